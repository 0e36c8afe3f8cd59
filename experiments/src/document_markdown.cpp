#include "handcentric/experiments/document_markdown.hpp"

#include <sstream>

namespace handcentric::experiments {
namespace {

// A code span that survives backticks in its text: a fence one longer than any run inside.
std::string code_span(const std::string& text) {
  std::size_t longest = 0, run = 0;
  for (char c : text) {
    run = c == '`' ? run + 1 : 0;
    if (run > longest) longest = run;
  }
  const std::string fence(longest + 1, '`');
  std::string inner;
  for (char c : text) inner += c == '|' ? std::string("\\|") : std::string(1, c);
  const bool pad = !inner.empty() && (inner.front() == '`' || inner.back() == '`');
  return fence + (pad ? " " : "") + inner + (pad ? " " : "") + fence;
}

// A link target that cannot end the link early or open an attribute: the few characters that
// would are percent-encoded.
std::string target(const std::string& link) {
  return substitute(
      link, {{' ', "%20"}, {'"', "%22"}, {'<', "%3C"}, {'>', "%3E"}, {'(', "%28"}, {')', "%29"}});
}

std::string markdown_text(const Text& text) {
  std::string out;
  for (const Span& span : text) {
    std::string inner =
        span.style == Span::Style::code ? code_span(span.text) : markdown_escape(span.text);
    if (span.style == Span::Style::bold) inner = "**" + inner + "**";
    if (!span.link.empty()) inner = "[" + inner + "](" + target(span.link) + ")";
    out += inner;
  }
  return out;
}

std::string cell_markdown(const TableCell& cell) {
  std::string content;
  if (cell.mark == Mark::yes) content += "✓ yes ";
  if (cell.mark == Mark::no) content += "**✗ NO** ";
  content += markdown_text(cell.text);
  if (!cell.detail.empty()) content += " (" + markdown_escape(cell.detail) + ")";
  if (!cell.link.empty()) content = "[" + content + "](" + target(cell.link) + ")";
  return content.empty() ? " " : content;
}

void block_markdown(std::ostream& out, const Block& block) {
  if (const auto* paragraph = std::get_if<Paragraph>(&block)) {
    out << markdown_text(paragraph->text) << "\n\n";
  } else if (const auto* list = std::get_if<List>(&block)) {
    for (const Text& item : list->items) out << "- " << markdown_text(item) << "\n";
    out << "\n";
  } else if (const auto* pre = std::get_if<Preformatted>(&block)) {
    // A fence longer than any backtick run of the text.
    std::size_t longest = 0, run = 0;
    for (char c : pre->text) {
      run = c == '`' ? run + 1 : 0;
      if (run > longest) longest = run;
    }
    const std::string fence(longest < 3 ? 3 : longest + 1, '`');
    out << fence << "\n"
        << pre->text << (pre->text.empty() || pre->text.back() == '\n' ? "" : "\n") << fence
        << "\n\n";
  } else if (const auto* figure = std::get_if<Figure>(&block)) {
    out << "![" << markdown_escape(figure->alt) << "](" << target(figure->src) << ")\n\n";
    if (!figure->caption.empty()) out << "*" << markdown_text(figure->caption) << "*\n\n";
  } else if (const auto* table = std::get_if<Table>(&block)) {
    out << "<a id=\"" << table->id << "\"></a>\n\n";
    if (!table->caption.empty()) out << "**" << markdown_escape(table->caption) << "**\n\n";
    out << "|";
    for (const std::string& column : table->columns) out << " " << markdown_escape(column) << " |";
    out << "\n|";
    for (std::size_t c = 0; c < table->columns.size(); ++c) out << "---|";
    out << "\n";
    for (std::size_t r = 0; r < table->rows.size(); ++r) {
      out << "|";
      // A row's anchor opens its first cell, so that "#id" links reach the row here too.
      if (!table->row_ids.empty()) out << " <a id=\"" << table->row_ids[r] << "\"></a>";
      for (const TableCell& cell : table->rows[r]) out << " " << cell_markdown(cell) << " |";
      out << "\n";
    }
    out << "\n";
  }
}

}  // namespace

std::string markdown_escape(const std::string& text) {
  return substitute(text, {{'&', "&amp;"},
                           {'<', "&lt;"},
                           {'>', "&gt;"},
                           {'\n', " "},
                           {'\r', " "},
                           {'\\', "\\\\"},
                           {'`', "\\`"},
                           {'*', "\\*"},
                           {'_', "\\_"},
                           {'[', "\\["},
                           {']', "\\]"},
                           {'|', "\\|"},
                           {'#', "\\#"}});
}

std::string to_markdown(const Document& document) {
  check(document);
  std::ostringstream out;
  out << "# " << markdown_escape(document.title) << "\n\n";
  for (const Block& block : document.intro) block_markdown(out, block);
  if (!document.sections.empty()) out << "**Contents**\n\n";
  for (const Section& section : document.sections) {
    if (section.level > 3) continue;
    out << (section.level == 3 ? "  - " : "- ") << "[" << markdown_escape(section.title) << "](#"
        << section.id << ")\n";
  }
  out << "\n";
  for (const Section& section : document.sections) {
    out << "<a id=\"" << section.id << "\"></a>\n\n"
        << std::string(static_cast<std::size_t>(section.level), '#') << " "
        << markdown_escape(section.title) << "\n\n";
    for (const Block& block : section.blocks) block_markdown(out, block);
  }
  return out.str();
}

}  // namespace handcentric::experiments
