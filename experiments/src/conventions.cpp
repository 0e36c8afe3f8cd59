#include "handcentric/experiments/conventions.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <regex>
#include <sstream>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/experiments/document_markdown.hpp"
#include "handcentric/experiments/shell_quote.hpp"
#include "handcentric/props/audit.hpp"
#include "handcentric/props/plugin_audit.hpp"

namespace handcentric::experiments {
namespace {

const props::View kConventionViews[] = {props::View::eye_in_hand, props::View::third_person};

// What each cell of the table shows, in order: the convention itself (its actions, pointwise),
// what a flow policy learns (the flow target's law), and what the policy is given.
struct ShownCell {
  props::Component component;
  props::Mode mode;
  const char* label;
};
const ShownCell kShownCells[] = {
    {props::Component::actions, props::Mode::pointwise, "actions"},
    {props::Component::flow_target, props::Mode::distribution, "target law"},
    {props::Component::observation, props::Mode::pointwise, "observation"},
};

std::string read_plugin_text(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InvalidArgument("cannot read the plug-in '" + path + "'");
  std::ostringstream out;
  out << file.rdbuf();
  return out.str();
}

// Three significant digits, and exact zeros for what is rounding noise at the scale of the
// audit (below 1e-9): the printed witness is then the same on any machine that gets the same
// doubles up to their last bits.
std::string rounded(double value) {
  return format_significant(std::abs(value) < 1e-9 ? 0.0 : value, 3);
}

std::string rounded_vector(const Eigen::Vector3d& v) {
  return "(" + rounded(v.x()) + ", " + rounded(v.y()) + ", " + rounded(v.z()) + ")";
}

std::string witness_anchor(const std::string& name, const props::Verdict& v) {
  return "conventions-" + name + "-" + props::to_string(v.component) + "-" +
         props::to_string(v.group) + "-" + props::to_string(v.mode) + "-" +
         props::to_string(v.view);
}

std::string view_words(props::View view) {
  return view == props::View::eye_in_hand ? "eye-in-hand" : "third-person";
}

// One line on a failing check: how large the difference was, for which g, on which scene, and
// the first coordinate that differs (rounded: the full witness is in `audit --json`).
Text witness_summary(const props::Verdict& v) {
  Text out;
  if (!v.witness) {
    out.push_back(plain("no witness (the check could not run)"));
    return out;
  }
  const props::Witness& w = *v.witness;
  const Eigen::Vector3d rotation = w.g.rotation().log();
  const double angle = rotation.norm();
  std::string g = "g: ";
  if (angle > 1e-9) {
    g += "rotation " + rounded(angle) + " rad about " + rounded_vector(rotation / angle);
  } else {
    g += "no rotation";
  }
  g += ", translation " + rounded_vector(w.g.translation()) + " m";
  std::string scene = "scene: H = " + std::to_string(w.scene.history_length()) +
                      ", K = " + std::to_string(w.scene.chunk_length()) + ", " +
                      std::to_string(w.scene.world_points.size()) + " world points, p_0 = " +
                      rounded_vector(w.scene.world_T_hand0().translation()) + " m";
  std::string where;
  if (w.before.size() == w.after.size() && w.before.size() > 0) {
    Eigen::Index i = 0;
    (w.after - w.before).cwiseAbs().maxCoeff(&i);
    where = "; largest difference at coordinate " + std::to_string(i) + ": " +
            rounded(w.before[i]) + " -> " + rounded(w.after[i]);
  }
  out.push_back(plain("error " + rounded(w.error) + " (tolerance " + rounded(w.tolerance) + "); " +
                      g + "; " + scene + where));
  return out;
}

// A cell of the table: the three shown verdicts of (group, view), each yes or NO, a NO linking
// to its witness's row.
TableCell group_cell(const ConventionAudit& c, props::Group group, props::View view) {
  TableCell cell;
  for (const ShownCell& shown : kShownCells) {
    if (!cell.text.empty()) cell.text.push_back(plain(" · "));
    const props::Verdict* v =
        props::find_verdict(c.result, shown.component, shown.mode, group, view);
    if (v == nullptr) {
      cell.text.push_back(plain("-"));
    } else if (v->invariant) {
      cell.text.push_back(plain("yes"));
    } else {
      cell.text.push_back(plain("NO", "#" + witness_anchor(c.name, *v)));
    }
  }
  return cell;
}

TableCell injectivity_cell(const ConventionAudit& c) {
  const std::string link = "#conventions-" + c.name + "-injectivity";
  if (!c.result.injectivity) return text_cell("-");
  const props::Injectivity& inj = *c.result.injectivity;
  if (!inj.injective.has_value()) return text_cell("no loss found");
  if (*inj.injective) return text_cell("yes");
  TableCell cell;
  std::string shown = "NO";
  if (inj.resolution) {
    shown += ", below " + props::format_resolution(*inj.resolution, inj.resolution_unit);
  }
  cell.text.push_back(plain(shown, link));
  return cell;
}

// The commits a row was read at, each once, in the order its Source cites them:
// `owner/repo@1234567` (the section above the table gives the 40 digits).
TableCell commit_cell(const ConventionAudit& c) {
  TableCell cell;
  std::vector<std::string> shown;
  for (const ConventionCitation& citation : c.citations) {
    const std::string short_form = citation.repo + "@" + citation.commit.substr(0, 7);
    if (std::find(shown.begin(), shown.end(), short_form) != shown.end()) continue;
    if (!cell.text.empty()) cell.text.push_back(plain(", "));
    cell.text.push_back(code(short_form));
    shown.push_back(short_form);
  }
  if (cell.text.empty()) cell.text.push_back(plain("-"));
  return cell;
}

Table summary_table(const std::vector<ConventionAudit>& conventions, props::View view,
                    const ConventionsOptions& options) {
  Table table;
  table.id = "conventions-" + props::to_string(view);
  table.kind = "conventions";
  table.caption = "The " + view_words(view) +
                  " view: each cell is actions (pointwise) · target law (in distribution) · "
                  "observation (pointwise)";
  table.columns = {"convention"};
  for (props::Group group : props::all_groups()) table.columns.push_back(props::to_string(group));
  table.columns.push_back("injective");
  // The Expect lines speak of the eye-in-hand view (Theorem 1's setting); that table also says
  // where each row comes from.
  if (view == props::View::eye_in_hand) {
    for (const char* column : {"as expected", "used by", "commit", "plug-in"})
      table.columns.push_back(column);
  }
  for (const ConventionAudit& c : conventions) {
    std::vector<TableCell> row;
    TableCell name;
    name.text.push_back(plain(c.name, "#conventions-" + c.name));
    row.push_back(std::move(name));
    for (props::Group group : props::all_groups()) row.push_back(group_cell(c, group, view));
    row.push_back(injectivity_cell(c));
    if (view == props::View::eye_in_hand) {
      // Whether the eye-in-hand cells are what the docstring's Expect line (the theory) says.
      row.push_back(c.mismatches.empty()
                        ? verdict_cell(true, "", "", "")
                        : verdict_cell(false, std::to_string(c.mismatches.size()) + " differ", "",
                                       "#conventions-" + c.name));
      row.push_back(text_cell(c.used_by.empty() ? "-" : c.used_by));
      row.push_back(commit_cell(c));
      TableCell plugin;
      plugin.text.push_back(plain(c.name + ".py", options.plugin_links + c.name + ".py"));
      row.push_back(std::move(plugin));
    }
    table.rows.push_back(std::move(row));
  }
  return table;
}

// A docstring's parts: its opening paragraph, then one item per paragraph that starts with a
// word at the margin (Source, Config, Formula, Assumed, Theory, Expect), each item that word and
// its lines joined by spaces (but for a citation broken after a colon: ends_inside_citation).
struct DocstringParts {
  std::string opening;
  std::vector<std::pair<std::string, std::string>> items;  // (keyword, body)
};

// Whether `text` ends inside a citation broken after one of its colons: its last word holds
// "@COMMIT:" and ends with ':'. A citation longer than a line goes on over the next ones, joined
// without a space ("owner/repo@COMMIT:" then "path:function").
bool ends_inside_citation(const std::string& text) {
  static const std::regex kCommit("@[0-9a-f]{40}:");
  const std::size_t space = text.find_last_of(' ');
  const std::string word = space == std::string::npos ? text : text.substr(space + 1);
  return !word.empty() && word.back() == ':' && std::regex_search(word, kCommit);
}

DocstringParts split_docstring(const std::string& docstring) {
  static const char* const kKeywords[] = {"Source",  "Config", "Formula",
                                          "Assumed", "Theory", "Expect"};
  DocstringParts out;
  std::istringstream lines(docstring);
  std::string line;
  auto add = [](std::string& to, const std::string& text) {
    const std::size_t start = text.find_first_not_of(' ');
    if (start == std::string::npos) return;
    if (!to.empty() && !ends_inside_citation(to)) to += ' ';
    to += text.substr(start);
  };
  while (std::getline(lines, line)) {
    if (!line.empty() && line.front() != ' ') {
      const std::size_t space = line.find(' ');
      const std::string word = line.substr(0, space);
      if (std::find(std::begin(kKeywords), std::end(kKeywords), word) != std::end(kKeywords)) {
        out.items.emplace_back(word, "");
        add(out.items.back().second, space == std::string::npos ? "" : line.substr(space));
        continue;
      }
    }
    add(out.items.empty() ? out.opening : out.items.back().second, line);
  }
  return out;
}

// The body of a docstring's paragraph `keyword` (empty when it has none).
std::string docstring_paragraph(const std::string& docstring, const std::string& keyword) {
  for (const auto& [word, body] : split_docstring(docstring).items) {
    if (word == keyword) return body;
  }
  return "";
}

// A docstring as the page shows it: its opening paragraph, then its keyword paragraphs as a
// list, each keyword in bold. Not verbatim (<pre>): the page keeps <pre> for commands.
void docstring_blocks(const std::string& docstring, std::vector<Block>& blocks) {
  const DocstringParts parts = split_docstring(docstring);
  List items;
  for (const auto& [word, body] : parts.items)
    items.items.push_back({bold(word), plain(" " + body)});
  blocks.push_back(Paragraph{{plain(parts.opening)}});
  blocks.push_back(std::move(items));
}

// A convention's own section: what it is (its docstring), whether it keeps the chunk's
// information, and each NO of the table with its witness, one anchored row each.
Section convention_section(const ConventionAudit& c) {
  Section out;
  out.id = "conventions-" + c.name;
  out.title = c.name + ": " + c.title;
  out.level = 3;
  docstring_blocks(c.description, out.blocks);
  Text injectivity = {bold("Injectivity:"), plain(" ")};
  if (c.result.injectivity) {
    const props::Injectivity& inj = *c.result.injectivity;
    injectivity.push_back(plain(!inj.injective.has_value() ? "no loss found"
                                : *inj.injective           ? "yes"
                                                           : "NO"));
    injectivity.push_back(plain(" (" + inj.how + ")."));
  }
  out.blocks.push_back(Paragraph{injectivity});
  List theory;
  for (const std::string& m : c.mismatches) theory.items.push_back({plain(m)});
  out.blocks.push_back(
      Paragraph{{bold("Against its Expect line:"),
                 plain(c.mismatches.empty()
                           ? " every eye-in-hand cell as expected."
                           : " " + std::to_string(c.mismatches.size()) + " cell(s) differ:")}});
  if (!theory.items.empty()) out.blocks.push_back(std::move(theory));
  Table failing;
  failing.id = "conventions-" + c.name + "-witnesses";
  failing.kind = "witnesses";
  failing.columns = {"check", "method", "witness"};
  for (props::View view : kConventionViews) {
    for (const ShownCell& shown : kShownCells) {
      for (props::Group group : props::all_groups()) {
        const props::Verdict* v =
            props::find_verdict(c.result, shown.component, shown.mode, group, view);
        if (v == nullptr || v->invariant) continue;
        TableCell what;
        what.text.push_back(plain(std::string(shown.label) + ", " + props::to_string(group) + ", " +
                                  view_words(view)));
        TableCell method = text_cell(v->mode == props::Mode::pointwise
                                         ? "pointwise"
                                         : "in distribution, " + props::to_string(v->method));
        TableCell witness;
        witness.text = witness_summary(*v);
        failing.rows.push_back({std::move(what), std::move(method), std::move(witness)});
        failing.row_ids.push_back(witness_anchor(c.name, *v));
      }
    }
  }
  // The injectivity row, so that its NO links somewhere on the page.
  failing.rows.push_back(
      {text_cell("injectivity"), text_cell("chunk pairs and resolution scan"),
       text_cell(c.result.injectivity ? c.result.injectivity->how : "not checked")});
  failing.row_ids.push_back("conventions-" + c.name + "-injectivity");
  out.blocks.push_back(Paragraph{{plain("The NO cells of the tables, each with its witness:")}});
  out.blocks.push_back(std::move(failing));
  return out;
}

Text how_made(const ConventionsOptions& options) {
  const props::ClassifierOptions used = props::classifier_options([&] {
    props::AuditOptions audit;
    audit.cases = options.cases;
    audit.seed = options.seed;
    return audit;
  }());
  return {plain("Each row is a plug-in of "),
          code("conventions/"),
          plain(" (this project's own code; each file's docstring, shown below, cites the "
                "codebase, file and formula it follows) audited through the "),
          code("--exec"),
          plain(" pipe: " + std::to_string(options.cases) + " cases per pointwise cell, " +
                std::to_string(used.distribution.cases) + " per in-distribution cell, " +
                std::to_string(used.injectivity_cases) +
                " chunk pairs and a resolution scan for injectivity, seed " +
                std::to_string(options.seed) + ". Regenerate with "),
          code("handcentric conventions --out docs/CONVENTIONS.md"),
          plain("; a test fails when this file is out of date. What a verdict means and what it "
                "could miss: docs/AUDIT.md.")};
}

}  // namespace

std::string convention_title(const std::string& docstring) {
  std::string first = docstring.substr(0, docstring.find("\n\n"));
  std::replace(first.begin(), first.end(), '\n', ' ');
  return first.substr(0, first.find(": "));
}

std::vector<ConventionCitation> convention_citations(const std::string& path,
                                                     const std::string& docstring) {
  // owner/repo@COMMIT:path:function, the commit in full; a path holds no ':' or space.
  static const std::regex kCitation(
      R"(([A-Za-z0-9][A-Za-z0-9_.-]*/[A-Za-z0-9][A-Za-z0-9_.-]*)@([0-9a-f]{40}):([^:\s`]+):)"
      R"(([A-Za-z_][A-Za-z0-9_.]*))");
  const std::string source = docstring_paragraph(docstring, "Source");
  std::vector<ConventionCitation> out;
  for (auto it = std::sregex_iterator(source.begin(), source.end(), kCitation);
       it != std::sregex_iterator(); ++it) {
    std::string function = (*it)[4].str();
    while (!function.empty() && function.back() == '.') function.pop_back();  // a full stop
    out.push_back({(*it)[1].str(), (*it)[2].str(), (*it)[3].str(), function});
  }
  if (out.empty()) {
    throw InvalidArgument("the plug-in '" + path +
                          "' cites no code in its Source paragraph; write each place read as "
                          "owner/repo@COMMIT:path:function (a line may end after one of its "
                          "colons), COMMIT the 40 hex digits of the version read "
                          "(conventions/README.md)");
  }
  return out;
}

std::string convention_used_by(const std::string& path, const std::string& docstring) {
  const std::string body = docstring_paragraph(docstring, "Config");
  if (body.empty()) {
    throw InvalidArgument("the plug-in '" + path +
                          "' has no Config paragraph; name the shipped configurations that "
                          "select its pipeline, or write 'no shipped config' "
                          "(conventions/README.md)");
  }
  return body;
}

std::vector<std::string> convention_plugins(const std::string& folder) {
  namespace fs = std::filesystem;
  std::error_code error;
  if (!fs::is_directory(folder, error)) {
    throw InvalidArgument("no folder of convention plug-ins at '" + folder +
                          "'; pass --plugins DIR (the source tree's conventions/)");
  }
  std::vector<std::string> out;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
    const std::string file = entry.path().filename().string();
    if (entry.is_regular_file() && entry.path().extension() == ".py" && file.front() != '_')
      out.push_back(entry.path().string());
  }
  std::sort(out.begin(), out.end());
  if (out.empty()) {
    throw InvalidArgument("the folder '" + folder +
                          "' holds no convention plug-in (*.py not starting with '_')");
  }
  return out;
}

std::string convention_docstring(const std::string& path, const std::string& source) {
  const std::size_t open = source.find("\"\"\"");
  const std::size_t close = open == std::string::npos ? open : source.find("\"\"\"", open + 3);
  if (close == std::string::npos) {
    throw InvalidArgument("the plug-in '" + path +
                          "' has no docstring; open it with a \"\"\" docstring saying its Source "
                          "(codebase, file, function), Formula and Theory (conventions/README.md)");
  }
  std::string text = source.substr(open + 3, close - open - 3);
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  for (const char* needed : {"Source", "Theory"}) {
    if (text.find(needed) == std::string::npos) {
      throw InvalidArgument("the plug-in '" + path + "' has a docstring without a '" + needed +
                            "' paragraph; say where its formula comes from (Source) and what the "
                            "audit should find (Theory) (conventions/README.md)");
    }
  }
  return text;
}

std::vector<props::Group> expected_groups(const std::string& path, const std::string& docstring,
                                          props::Component component) {
  const std::string fix =
      "; write e.g. 'Expect   actions: translation; observation: none' "
      "(groups: translation, rotation, se2, se3, c8, all or none; "
      "conventions/README.md)";
  std::istringstream lines(docstring);
  std::string line;
  while (std::getline(lines, line) && line.rfind("Expect", 0) != 0) {
  }
  if (line.rfind("Expect", 0) != 0) {
    throw InvalidArgument("the plug-in '" + path + "' has no 'Expect' line in its docstring" + fix);
  }
  const std::string wanted = props::to_string(component);
  std::istringstream parts(line.substr(6));
  std::string part;
  while (std::getline(parts, part, ';')) {
    const std::size_t colon = part.find(':');
    std::string name = part.substr(0, colon);
    name.erase(0, name.find_first_not_of(' '));
    name.erase(name.find_last_not_of(' ') + 1);
    if (colon == std::string::npos || (name != "actions" && name != "observation")) {
      throw InvalidArgument("the plug-in '" + path + "' has an Expect line whose part '" + part +
                            "' is not 'actions: GROUPS' or 'observation: GROUPS'" + fix);
    }
    if (name != wanted) continue;
    std::vector<props::Group> out;
    std::istringstream groups(part.substr(colon + 1));
    std::string group;
    while (std::getline(groups, group, ',')) {
      group.erase(0, group.find_first_not_of(' '));
      group.erase(group.find_last_not_of(' ') + 1);
      if (group == "all") return props::all_groups();
      if (group == "none") return {};
      try {
        out.push_back(props::parse_group(group));
      } catch (const InvalidArgument&) {
        throw InvalidArgument("the plug-in '" + path + "' expects the unknown group '" + group +
                              "'" + fix);
      }
    }
    return out;
  }
  throw InvalidArgument("the plug-in '" + path + "' has an Expect line that says nothing of " +
                        wanted + fix);
}

std::vector<std::string> expectation_mismatches(const std::string& path,
                                                const std::string& docstring,
                                                const props::Classification& result) {
  std::vector<std::string> out;
  const struct {
    props::Component expected_of, component;
    props::Mode mode;
  } cells[] = {
      {props::Component::actions, props::Component::actions, props::Mode::pointwise},
      {props::Component::actions, props::Component::flow_target, props::Mode::distribution},
      {props::Component::observation, props::Component::observation, props::Mode::pointwise},
  };
  for (const auto& cell : cells) {
    const std::vector<props::Group> expected = expected_groups(path, docstring, cell.expected_of);
    for (props::Group group : props::all_groups()) {
      const props::Verdict* v =
          props::find_verdict(result, cell.component, cell.mode, group, props::View::eye_in_hand);
      if (v == nullptr) continue;
      const bool expect = std::find(expected.begin(), expected.end(), group) != expected.end();
      if (v->invariant == expect) continue;
      out.push_back(props::to_string(cell.component) + " (" + props::to_string(cell.mode) +
                    ", eye-in-hand) under " + props::to_string(group) + ": the audit says " +
                    (v->invariant ? "invariant" : "NOT invariant") + ", the Expect line " +
                    (expect ? "invariant" : "not invariant"));
    }
  }
  return out;
}

std::vector<ConventionAudit> audit_conventions(const ConventionsOptions& options) {
  props::AuditOptions audit;
  audit.cases = props::checked_cases(options.cases);
  audit.seed = options.seed;
  if (options.python.empty()) throw InvalidArgument("--python is empty; name an interpreter");
  const std::vector<std::string> plugins = convention_plugins(options.folder);
  std::vector<ConventionAudit> out;
  for (std::size_t i = 0; i < plugins.size(); ++i) {
    const std::filesystem::path path(plugins[i]);
    ConventionAudit c;
    c.name = path.stem().string();
    c.description = convention_docstring(plugins[i], read_plugin_text(plugins[i]));
    c.title = convention_title(c.description);
    // The citations, the Config paragraph and the Expect line are read before minutes of
    // auditing, so that a typo fails at once.
    c.citations = convention_citations(plugins[i], c.description);
    c.used_by = convention_used_by(plugins[i], c.description);
    (void)expected_groups(plugins[i], c.description, props::Component::actions);
    (void)expected_groups(plugins[i], c.description, props::Component::observation);
    if (options.progress)
      options.progress(c.name, static_cast<int>(i) + 1, static_cast<int>(plugins.size()));
    // As `handcentric audit --exec` runs it: batched, with prefetch passes.
    props::PluginAuditSetup setup;
    setup.timeout = options.timeout;
    c.result = props::audit_representation_plugin(options.python + " " + shell_quote(plugins[i]),
                                                  audit, setup);
    c.result.name = c.name;
    c.mismatches = expectation_mismatches(plugins[i], c.description, c.result);
    out.push_back(std::move(c));
  }
  return out;
}

std::vector<Section> conventions_sections(const std::vector<ConventionAudit>& conventions,
                                          const ConventionsOptions& options) {
  Section top;
  top.id = "conventions";
  top.title = "Public pose conventions, audited";
  top.blocks.push_back(Paragraph{how_made(options)});
  top.blocks.push_back(List{{
      {bold("actions"), plain(": the convention itself, f(g s) = f(s) case by case.")},
      {bold("target law"),
       plain(": the law of the rectified flow's regression target a - eps, eps ~ N(0, I): what a "
             "flow policy learns (affine in eps, so decided exactly).")},
      {bold("observation"), plain(": the proprioception the codebase feeds its policy, and the "
                                  "eye-in-hand and world points as the plug-in passes them.")},
      {bold("injective"), plain(": whether two different chunks can give one action vector; "
                                "\"no loss found\" means no collision in the searches (the "
                                "plug-ins do not decode, so nothing proves the converse).")},
      {bold("used by"),
       plain(": the shipped configurations that train the row's pipeline (\"no shipped config\" "
             "when none does, \"not on main\" when the code is on another branch only); "
             "commit: the versions read, each cited in full in the row's Source as "
             "owner/repo@COMMIT:path:function; plug-in: the row's file in conventions/.")},
  }});
  for (props::View view : kConventionViews)
    top.blocks.push_back(summary_table(conventions, view, options));
  std::vector<Section> out = {std::move(top)};
  for (const ConventionAudit& c : conventions) out.push_back(convention_section(c));
  return out;
}

std::string conventions_markdown(const std::vector<ConventionAudit>& conventions,
                                 const ConventionsOptions& options) {
  Document document;
  document.title = "Public pose conventions, audited (generated)";
  document.sections = conventions_sections(conventions, options);
  return to_markdown(document);
}

FirstDifference first_difference(const std::string& a, const std::string& b) {
  std::istringstream first(a), second(b);
  FirstDifference out;
  for (int line = 1;; ++line) {
    std::string x, y;
    const bool more_a = static_cast<bool>(std::getline(first, x));
    const bool more_b = static_cast<bool>(std::getline(second, y));
    if (!more_a && !more_b) return FirstDifference{};
    if (x != y || more_a != more_b) return FirstDifference{line, x, y};
  }
}

}  // namespace handcentric::experiments
