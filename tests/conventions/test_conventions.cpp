// The parts of the conventions table (experiments/conventions.hpp) in process: the docstring and
// its Expect line, the comparison with the theory (with a planted wrong expectation), the table
// and its links, the first difference that an out-of-date check names, and the plug-in folder.
#include <catch2/catch.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/representations.hpp"
#include "handcentric/experiments/conventions.hpp"
#include "handcentric/experiments/document_html.hpp"
#include "handcentric/props/audit.hpp"

using namespace handcentric;
using namespace handcentric::experiments;

namespace {

const char* const kRelativeDoc =
    "The built-in relative representation.\n\nSource   this library, "
    "owner/lib@0123456789abcdef0123456789abcdef01234567:core/relative.cpp:encode\nConfig   the "
    "default\nTheory   translation only.\nExpect   actions: translation; observation: none";

// The built-in `relative` (actions p_k - p_0 and r(R_0^T R_k): translation-invariant only),
// classified at a small size: what a plug-in's audit gives, without a process.
const props::Classification& relative_audit() {
  static const props::Classification result = [] {
    props::AuditOptions audit;
    audit.cases = 60;
    props::ClassifierOptions options = props::classifier_options(audit);
    props::Classification c = props::classify_representation(
        std::shared_ptr<const Representation>(make_representation("relative")), options);
    c.name = "relative";
    return c;
  }();
  return result;
}

ConventionAudit relative_convention(const std::string& doc) {
  ConventionAudit c;
  c.name = "relative";
  c.title = "The built-in relative representation.";
  c.description = doc;
  c.used_by = "the default";
  c.citations = {
      {"owner/lib", "0123456789abcdef0123456789abcdef01234567", "core/relative.cpp", "encode"}};
  c.result = relative_audit();
  c.mismatches = expectation_mismatches("relative.py", doc, c.result);
  return c;
}

}  // namespace

TEST_CASE("conventions_docstring_is_read_and_must_cite_its_source_and_theory", "[unit]") {
  CHECK(convention_docstring("a.py",
                             "#!/usr/bin/env python3\n\"\"\"Title.\n\nSource x\nTheory "
                             "y\n\"\"\"\nimport numpy\n") == "Title.\n\nSource x\nTheory y");
  CHECK_THROWS_WITH(convention_docstring("a.py", "import numpy\n"),
                    Catch::Contains("'a.py' has no docstring"));
  CHECK_THROWS_WITH(convention_docstring("a.py", "\"\"\"Title.\nTheory y\n\"\"\""),
                    Catch::Contains("without a 'Source' paragraph"));
}

TEST_CASE("conventions_source_cites_repo_commit_path_and_function", "[unit]") {
  const std::string commit = "0123456789abcdef0123456789abcdef01234567";
  const std::string doc = "T\n\nSource   a/b@" + commit + ":src/x.py:f: `x = 1`;\n         " +
                          "c-d/e.f@" + commit + ":p/q.py:Class.method.\nTheory   t";
  const std::vector<ConventionCitation> cited = convention_citations("a.py", doc);
  REQUIRE(cited.size() == 2);
  CHECK(cited[0].repo == "a/b");
  CHECK(cited[0].commit == commit);
  CHECK(cited[0].path == "src/x.py");
  CHECK(cited[0].function == "f");
  CHECK(cited[1].repo == "c-d/e.f");
  CHECK(cited[1].function == "Class.method");
  // A citation longer than a line breaks after its colons, and reads (and shows) unbroken.
  const std::string broken = "T\n\nSource   a/b@" + commit + ":\n         src/x.py:\n" +
                             "         f, read there\nTheory   t";
  const std::vector<ConventionCitation> joined = convention_citations("a.py", broken);
  REQUIRE(joined.size() == 1);
  CHECK(joined[0].path == "src/x.py");
  CHECK(joined[0].function == "f");
  // Planted faults: a short commit, or no function, is not a citation; nor is one outside the
  // Source paragraph.
  CHECK_THROWS_WITH(convention_citations("a.py", "T\nSource   a/b@0123456:src/x.py:f\n"),
                    Catch::Contains("'a.py' cites no code in its Source paragraph"));
  CHECK_THROWS_WITH(convention_citations("a.py", "T\nSource   a/b@" + commit + ":src/x.py\n"),
                    Catch::Contains("40 hex digits"));
  CHECK_THROWS(convention_citations(
      "a.py", "T\nSource   a paper\nTheory   a/b@" + commit + ":src/x.py:f\n"));
}

TEST_CASE("conventions_config_paragraph_is_the_used_by_column", "[unit]") {
  CHECK(convention_used_by("a.py",
                           "T\nSource s\nConfig   pi0_libero,\n         pi0_fast_libero"
                           "\nTheory t") == "pi0_libero, pi0_fast_libero");
  CHECK(convention_used_by("a.py", "T\nConfig   no shipped config\n") == "no shipped config");
  CHECK_THROWS_WITH(convention_used_by("a.py", "T\nSource s\nTheory t"),
                    Catch::Contains("'a.py' has no Config paragraph"));
  CHECK_THROWS_WITH(convention_used_by("a.py", "T\nConfig\nTheory t"),
                    Catch::Contains("'a.py' has no Config paragraph"));
}

TEST_CASE("conventions_expect_line_names_the_groups_or_says_what_is_wrong", "[unit]") {
  using props::Component;
  using props::Group;
  const std::string doc = "T\nExpect   actions: translation, se2; observation: none";
  CHECK(expected_groups("a.py", doc, Component::actions) ==
        std::vector<Group>{Group::translation, Group::se2});
  CHECK(expected_groups("a.py", doc, Component::observation).empty());
  CHECK(expected_groups("a.py", "T\nExpect   actions: all; observation: all",
                        Component::observation) == props::all_groups());
  CHECK_THROWS_WITH(expected_groups("a.py", "T\nTheory x", Component::actions),
                    Catch::Contains("'a.py' has no 'Expect' line"));
  CHECK_THROWS_WITH(
      expected_groups("a.py", "T\nExpect   actions: rotate; observation: none", Component::actions),
      Catch::Contains("unknown group 'rotate'"));
  CHECK_THROWS_WITH(expected_groups("a.py", "T\nExpect   actions: none", Component::observation),
                    Catch::Contains("says nothing of observation"));
}

TEST_CASE("conventions_verdicts_are_compared_with_the_expect_line", "[unit]") {
  // The audit of `relative` is what the theory says...
  CHECK(relative_convention(kRelativeDoc).mismatches.empty());
  // ...and a planted wrong theory (hand-centric's) is reported, cell by cell: actions and the
  // target law under the four groups with a rotation, the observation under all five.
  const std::string wrong = "T\nSource s\nTheory t\nExpect   actions: all; observation: all";
  const std::vector<std::string> mismatches = relative_convention(wrong).mismatches;
  CHECK(mismatches.size() == 4 + 4 + 5);
  CHECK_THAT(mismatches.front(),
             Catch::Contains("actions (pointwise, eye-in-hand) under rotation: the audit says NOT "
                             "invariant, the Expect line invariant"));
}

TEST_CASE("conventions_table_links_each_no_to_its_witness_row", "[unit]") {
  ConventionsOptions options;
  options.cases = 60;
  const std::string markdown = conventions_markdown({relative_convention(kRelativeDoc)}, options);
  // One row per view table, the convention's section with its docstring, and a witness row
  // anchored for the link of each NO (to_markdown checks that every "#id" link has its id).
  CHECK_THAT(markdown, Catch::Contains("| convention | translation | rotation | se2 | se3 | c8 | "
                                       "injective | as expected | used by | commit | plug-in |"));
  // Where the row comes from: its configurations, its commit, a link to its plug-in.
  CHECK_THAT(markdown, Catch::Contains("| the default | `owner/lib@0123456` | "
                                       "[relative.py](../conventions/relative.py) |"));
  CHECK_THAT(markdown,
             Catch::Contains("[NO](#conventions-relative-actions-rotation-pointwise-eye_in_hand)"));
  CHECK_THAT(
      markdown,
      Catch::Contains("| <a id=\"conventions-relative-actions-rotation-pointwise-eye_in_hand\">"
                      "</a> actions, rotation, eye-in-hand |"));
  CHECK_THAT(markdown, Catch::Contains("- **Expect** actions: translation; observation: none\n"));
  CHECK_THAT(markdown, Catch::Contains("- **Source** this library, owner/lib@"));
  CHECK_THAT(markdown, Catch::Contains("- **Config** the default\n"));
  // Deterministic: the same results give the same bytes.
  CHECK(markdown == conventions_markdown({relative_convention(kRelativeDoc)}, options));
  // A convention against its theory shows in the table.
  const std::string wrong = conventions_markdown(
      {relative_convention("T\nSource s\nTheory t\nExpect   actions: all; observation: all")},
      options);
  CHECK_THAT(wrong, Catch::Contains("13 differ"));
  CHECK_THAT(markdown, Catch::Contains("| ✓ yes "));
}

TEST_CASE("conventions_first_difference_names_the_line", "[unit]") {
  CHECK(first_difference("a\nb\nc\n", "a\nb\nc\n").line == 0);
  const FirstDifference d = first_difference("a\nb\nc\n", "a\nB\nc\n");
  CHECK(d.line == 2);
  CHECK(d.first == "b");
  CHECK(d.second == "B");
  CHECK(first_difference("a\n", "a\nb\n").line == 2);
}

TEST_CASE("conventions_plugins_are_the_python_files_not_starting_with_underscore", "[unit]") {
  const std::vector<std::string> plugins =
      convention_plugins(std::string(HANDCENTRIC_SOURCE_DIR) + "/conventions");
  REQUIRE(plugins.size() >= 10);
  for (const std::string& path : plugins) {
    const std::string file = std::filesystem::path(path).filename().string();
    CHECK(file.front() != '_');
    CHECK(std::filesystem::path(path).extension() == ".py");
    // Every committed plug-in cites its source and states its theory in a parsable line.
    std::ifstream in(path);
    const std::string source((std::istreambuf_iterator<char>(in)),
                             std::istreambuf_iterator<char>());
    const std::string doc = convention_docstring(path, source);
    CHECK_NOTHROW(expected_groups(path, doc, props::Component::actions));
    // ...cites each place read with its full commit, and names the configurations using it.
    CHECK_NOTHROW(convention_citations(path, doc));
    CHECK_NOTHROW(convention_used_by(path, doc));
  }
  CHECK(std::is_sorted(plugins.begin(), plugins.end()));
  CHECK_THROWS_WITH(convention_plugins("/nonexistent/conventions"),
                    Catch::Contains("no folder of convention plug-ins at '/nonexistent"));
  const std::filesystem::path empty = std::filesystem::temp_directory_path() / "hc_conv_empty";
  std::filesystem::create_directories(empty);
  CHECK_THROWS_WITH(convention_plugins(empty.string()), Catch::Contains("holds no convention"));
}

TEST_CASE("conventions_sections_render_on_the_report_page", "[unit]") {
  ConventionsOptions options;
  options.cases = 60;
  Document page;
  page.title = "report";
  page.sections = conventions_sections({relative_convention(kRelativeDoc)}, options);
  const std::string html = to_html(page);  // check(): every NO links to an id of the page
  CHECK_THAT(html,
             Catch::Contains("id=\"conventions-eye_in_hand\"") &&
                 Catch::Contains("id=\"conventions-third_person\"") &&
                 Catch::Contains(
                     "<tr id=\"conventions-relative-actions-rotation-pointwise-eye_in_hand\">"));
  // HANDCENTRIC_CONVENTIONS_PAGE=FILE keeps the page, to look at it in a browser.
  if (const char* keep = std::getenv("HANDCENTRIC_CONVENTIONS_PAGE")) {
    std::ofstream(keep) << html;
  }
}
