#pragma once
// Text quoted for /bin/sh, for the command lines the experiments write or run: Table 1's plan
// (jobs.txt) and the conventions' plug-in commands.
#include <string>

namespace handcentric::experiments {

/// `text` as one single-quoted /bin/sh word that the shell reads back as exactly `text`: each
/// ' written as '\'' (a quote cannot appear inside single quotes, so it closes them, is escaped
/// and reopens them). Nothing else is special inside single quotes.
std::string shell_quote(const std::string& text);

}  // namespace handcentric::experiments
