#include "handcentric/experiments/document_html.hpp"

#include <sstream>

namespace handcentric::experiments {
namespace {

// The marks carry a symbol and a word; the colours only repeat them.
const char* kStyle =
    "body{font-family:system-ui,sans-serif;max-width:1200px;margin:2em auto;padding:0 1em;"
    "color:#222;line-height:1.45}"
    "h1{font-size:1.7em}h2{border-bottom:1px solid #ddd;padding-bottom:.2em;margin-top:2em}"
    "h4{margin-bottom:.3em}"
    "nav{background:#f7f7f7;border:1px solid #e3e3e3;padding:.4em 1.2em;display:inline-block}"
    "nav ol{margin:.3em 0;padding-left:1.4em}nav ol ol{font-size:.92em}"
    "table{border-collapse:collapse;margin:.6em 0 1.2em}"
    "caption{text-align:left;font-weight:600;padding:.2em 0}"
    "td,th{border:1px solid #ccc;padding:.2em .55em;text-align:left;vertical-align:top}"
    "thead th{background:#eee}tbody th{background:#fafafa;font-weight:normal;white-space:nowrap}"
    "td.yes{background:#eef7ee}td.no{background:#fbe9e9}"
    ".mark{font-weight:700;white-space:nowrap}td.no .mark{color:#a00}td.yes .mark{color:#060}"
    "td small{display:block;color:#555}"
    "td a{color:inherit}"
    "table.verdict-grid td{min-width:7.5em}"
    "figure{margin:.5em 0 1.2em}figcaption{color:#444;font-size:.92em}"
    "img{max-width:100%;border:1px solid #ddd}"
    "code{background:#f1f1f1;padding:0 .2em}"
    "pre{background:#f6f6f6;padding:.6em;white-space:pre-wrap;font-size:13px}"
    ":target{outline:3px solid #fc6}";

std::string html_text(const Text& text) {
  std::string out;
  for (const Span& span : text) {
    std::string inner = html_escape(span.text);
    if (span.style == Span::Style::code) inner = "<code>" + inner + "</code>";
    if (span.style == Span::Style::bold) inner = "<strong>" + inner + "</strong>";
    if (!span.link.empty()) inner = "<a href=\"" + html_escape(span.link) + "\">" + inner + "</a>";
    out += inner;
  }
  return out;
}

std::string cell_html(const TableCell& cell, const char* tag, bool row_header) {
  std::string content;
  if (cell.mark == Mark::yes) content += "<span class=\"mark\">&#10003; yes</span> ";
  if (cell.mark == Mark::no) content += "<span class=\"mark\">&#10007; NO</span> ";
  content += html_text(cell.text);
  if (!cell.detail.empty()) content += "<small>" + html_escape(cell.detail) + "</small>";
  if (!cell.link.empty())
    content = "<a href=\"" + html_escape(cell.link) + "\">" + content + "</a>";
  std::string open = std::string("<") + tag;
  if (row_header) open += " scope=\"row\"";
  if (cell.mark == Mark::yes) open += " class=\"yes\"";
  if (cell.mark == Mark::no) open += " class=\"no\"";
  if (!cell.tooltip.empty()) open += " title=\"" + html_escape(cell.tooltip) + "\"";
  return open + ">" + content + "</" + tag + ">";
}

void block_html(std::ostream& out, const Block& block) {
  if (const auto* paragraph = std::get_if<Paragraph>(&block)) {
    out << "<p>" << html_text(paragraph->text) << "</p>\n";
  } else if (const auto* list = std::get_if<List>(&block)) {
    out << "<ul>\n";
    for (const Text& item : list->items) out << "<li>" << html_text(item) << "</li>\n";
    out << "</ul>\n";
  } else if (const auto* pre = std::get_if<Preformatted>(&block)) {
    out << "<pre>" << html_escape(pre->text) << "</pre>\n";
  } else if (const auto* figure = std::get_if<Figure>(&block)) {
    out << "<figure><img src=\"" << html_escape(figure->src) << "\" alt=\""
        << html_escape(figure->alt) << "\"";
    if (figure->width > 0) out << " width=\"" << figure->width << "\"";
    out << ">";
    if (!figure->caption.empty())
      out << "<figcaption>" << html_text(figure->caption) << "</figcaption>";
    out << "</figure>\n";
  } else if (const auto* table = std::get_if<Table>(&block)) {
    out << "<table id=\"" << html_escape(table->id) << "\"";
    if (!table->kind.empty()) out << " class=\"" << html_escape(table->kind) << "\"";
    out << ">\n";
    if (!table->caption.empty())
      out << "<caption>" << html_escape(table->caption) << "</caption>\n";
    out << "<thead><tr>";
    for (const std::string& column : table->columns)
      out << "<th scope=\"col\">" << html_escape(column) << "</th>";
    out << "</tr></thead>\n<tbody>\n";
    for (std::size_t r = 0; r < table->rows.size(); ++r) {
      const auto& row = table->rows[r];
      if (table->row_ids.empty())
        out << "<tr>";
      else
        out << "<tr id=\"" << html_escape(table->row_ids[r]) << "\">";
      for (std::size_t c = 0; c < row.size(); ++c)
        out << cell_html(row[c], c == 0 ? "th" : "td", c == 0);
      out << "</tr>\n";
    }
    out << "</tbody>\n</table>\n";
  }
}

}  // namespace

std::string html_escape(const std::string& text) {
  return substitute(
      text, {{'&', "&amp;"}, {'<', "&lt;"}, {'>', "&gt;"}, {'"', "&quot;"}, {'\'', "&#39;"}});
}

std::string to_html(const Document& document) {
  check(document);
  std::ostringstream out;
  out << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      << "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>"
      << html_escape(document.title) << "</title>\n<style>" << kStyle
      << "</style>\n</head>\n<body>\n<h1>" << html_escape(document.title) << "</h1>\n";
  for (const Block& block : document.intro) block_html(out, block);
  // The contents: level-2 sections, their level-3 sections nested beneath.
  if (!document.sections.empty())
    out << "<nav aria-label=\"contents\"><strong>Contents</strong>\n<ol>\n";
  bool nested = false;
  for (const Section& section : document.sections) {
    if (section.level > 3) continue;
    const std::string item =
        "<li><a href=\"#" + html_escape(section.id) + "\">" + html_escape(section.title) + "</a>";
    if (section.level == 2) {
      if (nested)
        out << "</ol></li>\n";
      else if (&section != &document.sections.front())
        out << "</li>\n";
      nested = false;
      out << item;
    } else {
      if (!nested) out << "\n<ol>\n";
      nested = true;
      out << item << "</li>\n";
    }
  }
  if (!document.sections.empty()) out << (nested ? "</ol></li>\n" : "</li>\n") << "</ol>\n</nav>\n";
  for (const Section& section : document.sections) {
    out << "<h" << section.level << " id=\"" << html_escape(section.id) << "\">"
        << html_escape(section.title) << "</h" << section.level << ">\n";
    for (const Block& block : section.blocks) block_html(out, block);
  }
  out << "</body>\n</html>\n";
  return out.str();
}

}  // namespace handcentric::experiments
