#include "handcentric/experiments/document.hpp"

#include <algorithm>
#include <set>
#include <utility>

#include "handcentric/core/errors.hpp"

namespace handcentric::experiments {
namespace {

bool valid_id(const std::string& id) {
  if (id.empty()) return false;
  for (char c : id) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '-' || c == '_';
    if (!ok) return false;
  }
  return true;
}

// Every id of the page, and every "#id" link with where it is, for check().
struct Anchors {
  std::set<std::string> ids;
  std::vector<std::pair<std::string, std::string>> links;  // (target, where)

  void add_id(const std::string& id, const std::string& where) {
    if (!valid_id(id)) {
      throw InvalidArgument("report page: " + where + " has the id '" + id +
                            "': use letters, digits, '-' and '_' only (slug() makes one)");
    }
    if (!ids.insert(id).second) {
      throw InvalidArgument("report page: the id '" + id + "' is used twice (again at " + where +
                            "): give each section and table its own");
    }
  }
  void add_link(const std::string& link, const std::string& where) {
    if (!link.empty() && link.front() == '#') links.emplace_back(link.substr(1), where);
  }
  void add_text(const Text& text, const std::string& where) {
    for (const Span& span : text) add_link(span.link, where);
  }
};

void collect(const Block& block, const std::string& where, Anchors& anchors) {
  if (const auto* paragraph = std::get_if<Paragraph>(&block)) {
    anchors.add_text(paragraph->text, where);
  } else if (const auto* list = std::get_if<List>(&block)) {
    for (const Text& item : list->items) anchors.add_text(item, where);
  } else if (const auto* figure = std::get_if<Figure>(&block)) {
    if (figure->src.empty()) {
      throw InvalidArgument("report page: a figure in " + where + " ('" + figure->alt +
                            "') has no source file");
    }
    anchors.add_text(figure->caption, where);
  } else if (const auto* table = std::get_if<Table>(&block)) {
    const std::string at = "table '" + table->id + "' in " + where;
    anchors.add_id(table->id, at);
    if (!table->row_ids.empty() && table->row_ids.size() != table->rows.size()) {
      throw InvalidArgument("report page: " + at + " has " + std::to_string(table->row_ids.size()) +
                            " row ids for " + std::to_string(table->rows.size()) +
                            " rows: give every row an id or none");
    }
    for (const std::string& id : table->row_ids) anchors.add_id(id, "a row of " + at);
    for (std::size_t r = 0; r < table->rows.size(); ++r) {
      const auto& row = table->rows[r];
      if (row.size() != table->columns.size()) {
        throw InvalidArgument("report page: row " + std::to_string(r + 1) + " of " + at + " has " +
                              std::to_string(row.size()) + " cells for " +
                              std::to_string(table->columns.size()) + " columns");
      }
      for (std::size_t c = 0; c < row.size(); ++c) {
        const TableCell& cell = row[c];
        const std::string cell_at =
            "row " + std::to_string(r + 1) + ", column '" + table->columns[c] + "' of " + at;
        if (cell.mark == Mark::no && cell.link.empty()) {
          throw InvalidArgument("report page: the NO cell at " + cell_at +
                                " links to no witness: a failed check needs its witness linked");
        }
        anchors.add_link(cell.link, cell_at);
        anchors.add_text(cell.text, cell_at);
      }
    }
  }
}

}  // namespace

Span plain(std::string text, std::string link) {
  return Span{std::move(text), Span::Style::plain, std::move(link)};
}

Span code(std::string text) {
  return Span{std::move(text), Span::Style::code, ""};
}

Span bold(std::string text) {
  return Span{std::move(text), Span::Style::bold, ""};
}

TableCell text_cell(std::string text) {
  TableCell cell;
  cell.text = {plain(std::move(text))};
  return cell;
}

TableCell verdict_cell(bool holds, std::string shown, std::string detail, std::string link) {
  TableCell cell;
  cell.mark = holds ? Mark::yes : Mark::no;
  cell.text = {plain(std::move(shown))};
  cell.detail = std::move(detail);
  cell.link = std::move(link);
  return cell;
}

std::string substitute(const std::string& text,
                       std::initializer_list<std::pair<char, const char*>> table) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    const auto* entry =
        std::find_if(table.begin(), table.end(), [c](const auto& pair) { return pair.first == c; });
    if (entry == table.end())
      out += c;
    else
      out += entry->second;
  }
  return out;
}

std::string slug(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    const bool keep = (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9');
    if (keep) {
      out += c;
    } else if (!out.empty() && out.back() != '-') {
      out += '-';
    }
  }
  while (!out.empty() && out.back() == '-') out.pop_back();
  return out.empty() ? "x" : out;
}

void check(const Document& document) {
  Anchors anchors;
  for (const Block& block : document.intro) collect(block, "the introduction", anchors);
  for (const Section& section : document.sections) {
    const std::string where = "section '" + section.title + "'";
    if (section.level < 2 || section.level > 4) {
      throw InvalidArgument("report page: " + where + " has level " +
                            std::to_string(section.level) + ": use 2 (in the contents), 3 or 4");
    }
    anchors.add_id(section.id, where);
    for (const Block& block : section.blocks) collect(block, where, anchors);
  }
  for (const auto& [target, where] : anchors.links) {
    if (anchors.ids.count(target) == 0) {
      throw InvalidArgument("report page: the link to '#" + target + "' at " + where +
                            " points to no section or table of the page");
    }
  }
}

}  // namespace handcentric::experiments
