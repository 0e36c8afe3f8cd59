#pragma once
// The report page as data: sections of paragraphs, tables and figures, built once and rendered
// twice, to HTML (document_html.hpp) and to Markdown (document_markdown.hpp). Keeping the page's
// content here, apart from either syntax, is what makes index.html and index.md say the same
// thing: neither is converted from the other.
//
// A verdict cell carries its mark (yes / NO), and a NO cell a link to its witness; check() holds
// every document to that and to its internal links, before anything is written.
#include <initializer_list>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace handcentric::experiments {

/// A verdict's mark. Rendered with a symbol and a word, so it reads without colour.
enum class Mark { none, yes, no };

/// A run of text: plain, `code` or bold, optionally a link ("#id" on the page, or a path
/// relative to the page's folder).
struct Span {
  enum class Style { plain, code, bold };
  std::string text;
  Style style = Style::plain;
  std::string link;
};

/// Spans shown in sequence.
using Text = std::vector<Span>;

/// Helpers for the common spans.
Span plain(std::string text, std::string link = "");
Span code(std::string text);
Span bold(std::string text);

struct TableCell {
  Text text;
  Mark mark = Mark::none;
  std::string link;     ///< the whole cell links here (a NO verdict: its witness, "#id")
  std::string detail;   ///< a second, smaller line (e.g. "exact", "test")
  std::string tooltip;  ///< HTML title; not in the Markdown
};

/// Cell helpers: a text cell, and a verdict cell (mark, what it showed, detail, link).
TableCell text_cell(std::string text);
TableCell verdict_cell(bool holds, std::string shown, std::string detail, std::string link);

/// One table. `kind` names what it holds (e.g. "verdict-grid"): a CSS class in the HTML, and the
/// check script's handle on the page. The first column is the rows' header.
struct Table {
  std::string id;
  std::string caption;
  std::string kind;
  std::vector<std::string> columns;
  std::vector<std::vector<TableCell>> rows;
  std::vector<std::string> row_ids;  ///< empty, or one anchor per row (a line of a file)
};

/// An image file beside the page (SVG or PNG), relative to the page's folder.
struct Figure {
  std::string src;
  std::string alt;
  Text caption;
  int width = 0;  ///< display width in pixels in the HTML; 0: the page's width
};

struct Paragraph {
  Text text;
};

/// A bullet list, one Text per item.
struct List {
  std::vector<Text> items;
};

/// Verbatim lines (a command, a seed): never a verdict grid, which is a Table.
struct Preformatted {
  std::string text;
};

using Block = std::variant<Paragraph, List, Table, Figure, Preformatted>;

/// A heading (level 2: in the table of contents; 3 and 4: beneath it), its anchor and its
/// blocks. Sections are listed flat, in page order.
struct Section {
  std::string id;
  std::string title;
  int level = 2;
  std::vector<Block> blocks;
};

struct Document {
  std::string title;
  std::vector<Block> intro;  ///< before the table of contents
  std::vector<Section> sections;
};

/// A file the page shows or links to (a witness's picture), written beside it: `path` is
/// relative to the page's folder.
struct PageFile {
  std::string path;
  std::string bytes;
};

/// Throws InvalidArgument naming the first fault, and where it is, when the document breaks a
/// rule of the page: an id empty, repeated or not made of [A-Za-z0-9_-]; a section level
/// outside 2..4; row ids not one per row; a table row not as wide as its columns; a NO cell without
/// a link; an "#id" link (in a cell or a span) to no id of the document; a figure without a source.
void check(const Document& document);

/// `text` with each character that `table` lists replaced by its text (the renderers' escaping).
std::string substitute(const std::string& text,
                       std::initializer_list<std::pair<char, const char*>> table);

/// An id made of [a-z0-9-] from `text` ("A.3 eq. (23)" -> "a-3-eq-23").
std::string slug(const std::string& text);

}  // namespace handcentric::experiments
