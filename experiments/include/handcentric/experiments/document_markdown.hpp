#pragma once
// A Document (document.hpp) as GitHub-flavoured Markdown, for reading the report on a forge:
// the same sections, tables (pipe tables), figures and links as the HTML page. Anchors are
// written as <a id="..."></a> before each heading, so "#id" links work in both.
#include <string>

#include "handcentric/experiments/document.hpp"

namespace handcentric::experiments {

/// The Markdown page. Calls check(document) first (throws InvalidArgument on a fault).
std::string to_markdown(const Document& document);

/// `text` as Markdown text that shows as itself: Markdown punctuation backslash-escaped, '|'
/// too (so it is safe in a table cell), <, > and & as entities, line breaks as spaces.
std::string markdown_escape(const std::string& text);

}  // namespace handcentric::experiments
