#pragma once
// A Document (document.hpp) as one standalone HTML5 page: its own stylesheet, no script and no
// external asset, a table of contents of the level-2 sections, every table a <table>, every
// figure an <img>. All text is escaped, so no name or number can become markup.
#include <string>

#include "handcentric/experiments/document.hpp"

namespace handcentric::experiments {

/// The page. Calls check(document) first (throws InvalidArgument on a fault).
std::string to_html(const Document& document);

/// `text` with &, <, >, " and ' escaped.
std::string html_escape(const std::string& text);

}  // namespace handcentric::experiments
