#include "handcentric/experiments/markdown_html.hpp"

#include <sstream>
#include <vector>

namespace handcentric::experiments {
namespace {

bool starts_with(const std::string& s, const std::string& prefix) {
  return s.compare(0, prefix.size(), prefix) == 0;
}

// Escapes `text` and turns `code` spans into <code> elements.
std::string inline_html(const std::string& text) {
  std::string out;
  bool in_code = false;
  std::string piece;
  for (char c : text) {
    if (c == '`') {
      out += in_code ? "<code>" + html_escape(piece) + "</code>" : html_escape(piece);
      piece.clear();
      in_code = !in_code;
    } else {
      piece += c;
    }
  }
  // An unmatched backtick is text.
  out += in_code ? html_escape("`" + piece) : html_escape(piece);
  return out;
}

std::vector<std::string> table_cells(const std::string& line) {
  std::vector<std::string> cells;
  std::string s = line;
  if (!s.empty() && s.front() == '|') s.erase(0, 1);
  if (!s.empty() && s.back() == '|') s.pop_back();
  std::stringstream stream(s);
  std::string cell;
  while (std::getline(stream, cell, '|')) {
    const auto first = cell.find_first_not_of(' ');
    const auto last = cell.find_last_not_of(' ');
    cells.push_back(first == std::string::npos ? "" : cell.substr(first, last - first + 1));
  }
  return cells;
}

bool is_image(const std::string& line) {
  return starts_with(line, "![") && line.back() == ')' && line.find("](") != std::string::npos;
}

const char* kStyle =
    "body{font-family:system-ui,sans-serif;max-width:1400px;margin:2em auto;padding:0 1em;"
    "color:#222}"
    "pre{background:#f6f6f6;padding:.8em;white-space:pre-wrap;font-size:13px;line-height:1.35}"
    "table{border-collapse:collapse;margin:1em 0}"
    "td,th{border:1px solid #ccc;padding:.25em .6em;text-align:left}"
    "th{background:#f0f0f0}"
    "img{max-width:100%;border:1px solid #ddd}"
    "code{background:#f3f3f3;padding:0 .2em}";

}  // namespace

std::string html_escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string markdown_to_html(const std::string& markdown, const std::string& title) {
  std::vector<std::string> lines;
  {
    std::stringstream stream(markdown);
    std::string line;
    while (std::getline(stream, line)) lines.push_back(line);
  }
  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>"
       << html_escape(title) << "</title>\n<style>" << kStyle << "</style>\n</head>\n<body>\n";
  std::string paragraph;
  const auto flush_paragraph = [&] {
    if (!paragraph.empty()) html << "<p>" << inline_html(paragraph) << "</p>\n";
    paragraph.clear();
  };
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string& line = lines[i];
    if (starts_with(line, "```")) {
      flush_paragraph();
      html << "<pre>";
      for (++i; i < lines.size() && !starts_with(lines[i], "```"); ++i)
        html << html_escape(lines[i]) << "\n";
      html << "</pre>\n";
    } else if (starts_with(line, "### ") || starts_with(line, "## ") || starts_with(line, "# ")) {
      flush_paragraph();
      const std::size_t level = line.find(' ');
      html << "<h" << level << ">" << inline_html(line.substr(level + 1)) << "</h" << level
           << ">\n";
    } else if (starts_with(line, "|") && i + 1 < lines.size() &&
               starts_with(lines[i + 1], "|---")) {
      flush_paragraph();
      html << "<table>\n<tr>";
      for (const auto& cell : table_cells(line)) html << "<th>" << inline_html(cell) << "</th>";
      html << "</tr>\n";
      for (i += 2; i < lines.size() && starts_with(lines[i], "|"); ++i) {
        html << "<tr>";
        for (const auto& cell : table_cells(lines[i]))
          html << "<td>" << inline_html(cell) << "</td>";
        html << "</tr>\n";
      }
      --i;
      html << "</table>\n";
    } else if (starts_with(line, "- ")) {
      flush_paragraph();
      html << "<ul>\n";
      for (; i < lines.size() && starts_with(lines[i], "- "); ++i)
        html << "<li>" << inline_html(lines[i].substr(2)) << "</li>\n";
      --i;
      html << "</ul>\n";
    } else if (!line.empty() && is_image(line)) {
      flush_paragraph();
      const std::size_t middle = line.find("](");
      const std::string alt = line.substr(2, middle - 2);
      const std::string src = line.substr(middle + 2, line.size() - middle - 3);
      html << "<p><img src=\"" << html_escape(src) << "\" alt=\"" << html_escape(alt)
           << "\"></p>\n";
    } else if (line.find_first_not_of(' ') == std::string::npos) {
      flush_paragraph();
    } else {
      if (!paragraph.empty()) paragraph += ' ';
      paragraph += line;
    }
  }
  flush_paragraph();
  html << "</body>\n</html>\n";
  return html.str();
}

}  // namespace handcentric::experiments
