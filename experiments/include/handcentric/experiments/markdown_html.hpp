#pragma once
// The report's HTML page from its Markdown (one source, two views): the subset of Markdown the
// report writes, turned into a standalone HTML page with its own small stylesheet.
//
// Supported, line based: "# ", "## ", "### " headings; pipe tables (a header row, a |---| row,
// body rows); "- " bullet lists; ``` fenced blocks (shown verbatim); ![alt](src) on a line of its
// own (an image); other lines form paragraphs, with `code` spans. Every character of the
// Markdown's text is HTML-escaped, so a report can never inject markup into its page.
#include <string>

namespace handcentric::experiments {

/// A whole HTML5 document titled `title` holding `markdown` rendered as above.
std::string markdown_to_html(const std::string& markdown, const std::string& title);

/// `text` with &, <, >, " and ' escaped.
std::string html_escape(const std::string& text);

}  // namespace handcentric::experiments
