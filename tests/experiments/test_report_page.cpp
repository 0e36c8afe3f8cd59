// The report page (experiments/document*.hpp, audit_page, claims_page, results_page): one
// document rendered to HTML and Markdown, its rules (a NO cell links to its witness, every
// "#id" link lands), no way for a name to become markup, and the audit, certificate and table
// builders. Each rule has a planted fault that must be caught.
#include <catch2/catch.hpp>

#include <regex>

#include "handcentric/core/errors.hpp"
#include "handcentric/experiments/audit_page.hpp"
#include "handcentric/experiments/claims_page.hpp"
#include "handcentric/experiments/document_html.hpp"
#include "handcentric/experiments/document_markdown.hpp"
#include "handcentric/experiments/results_page.hpp"
#include "handcentric/experiments/witness_figure.hpp"
#include "handcentric/proofs/report.hpp"

using namespace handcentric;
using namespace handcentric::experiments;
using Catch::Matchers::Contains;

namespace {

// A page with a verdict grid: one yes cell, one NO cell linking to its witness section.
Document small_page() {
  Document doc;
  doc.title = "page";
  Table grid;
  grid.id = "grid";
  grid.kind = "verdict-grid";
  grid.columns = {"component", "se3", "c8"};
  grid.rows.push_back({text_cell("actions"), verdict_cell(true, "1.0e-15 m/1", "", ""),
                       verdict_cell(false, "2.0e+00 m/1", "exact", "#witness")});
  Section audit{"audit", "Audit", 2, {grid}};
  Section witness{"witness", "Witness", 4, {Paragraph{{plain("g = ...")}}}};
  doc.sections = {audit, witness};
  return doc;
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// Markup a renderer must never let through from text: the detector the escaping tests rely on.
bool has_raw_markup(const std::string& html) {
  return html.find("<script") != std::string::npos || html.find("<b>") != std::string::npos ||
         html.find("\" onerror") != std::string::npos;
}

props::Verdict verdict(props::Group group, bool invariant) {
  props::Verdict v;
  v.component = props::Component::actions;
  v.group = group;
  v.invariant = invariant;
  v.max_error = invariant ? 1e-15 : 2.0;
  v.cases = 10;
  v.seed = 7;
  return v;
}

}  // namespace

TEST_CASE("report_page_html_and_markdown_show_the_same_grid_with_marks_and_links", "[unit]") {
  const Document doc = small_page();
  const std::string html = to_html(doc);
  const std::string md = to_markdown(doc);
  CHECK_THAT(html, Contains("<table id=\"grid\" class=\"verdict-grid\">"));
  CHECK_THAT(html, Contains("<td class=\"yes\"><span class=\"mark\">&#10003; yes</span>"));
  CHECK_THAT(html, Contains("<td class=\"no\"><a href=\"#witness\"><span class=\"mark\">&#10007; "
                            "NO</span> 2.0e+00 m/1<small>exact</small></a></td>"));
  CHECK_THAT(html, Contains("<h4 id=\"witness\">Witness</h4>"));
  CHECK_THAT(html, Contains("<nav") && Contains("<a href=\"#audit\">Audit</a>"));
  CHECK(count(html, "<pre") == 0);
  CHECK_THAT(
      md, Contains("| actions | ✓ yes 1.0e-15 m/1 | [**✗ NO** 2.0e+00 m/1 (exact)](#witness) |"));
  CHECK_THAT(md, Contains("<a id=\"witness\"></a>\n\n#### Witness"));
  CHECK_THAT(md, Contains("- [Audit](#audit)"));
}

TEST_CASE("report_page_check_refuses_a_no_cell_without_a_witness_link", "[unit]") {
  Document doc = small_page();
  REQUIRE_NOTHROW(check(doc));
  // Planted fault: the NO cell loses its link.
  std::get<Table>(doc.sections[0].blocks[0]).rows[0][2].link.clear();
  CHECK_THROWS_WITH(check(doc), Contains("NO cell") && Contains("column 'c8'") &&
                                    Contains("links to no witness"));
  CHECK_THROWS_AS(to_html(doc), InvalidArgument);
  CHECK_THROWS_AS(to_markdown(doc), InvalidArgument);
}

TEST_CASE("report_page_check_refuses_a_link_to_no_anchor_and_a_repeated_id", "[unit]") {
  Document doc = small_page();
  std::get<Table>(doc.sections[0].blocks[0]).rows[0][2].link = "#witnes";  // planted typo
  CHECK_THROWS_WITH(check(doc), Contains("'#witnes'") && Contains("points to no section"));
  Document twice = small_page();
  twice.sections[1].id = "grid";  // planted: a section with the table's id
  CHECK_THROWS_WITH(check(twice), Contains("the id 'grid' is used twice"));
  Document bad_id = small_page();
  bad_id.sections[0].id = "a b";
  CHECK_THROWS_WITH(check(bad_id), Contains("'a b'"));
  Document narrow = small_page();
  std::get<Table>(narrow.sections[0].blocks[0]).rows[0].pop_back();
  CHECK_THROWS_WITH(check(narrow), Contains("2 cells for 3 columns"));
}

TEST_CASE("report_page_escapes_names_with_markup_characters_in_both_renderings", "[unit]") {
  // The detector itself catches a page that lets markup through (its planted fault).
  REQUIRE(has_raw_markup("<p><script>alert(1)</script></p>"));
  REQUIRE(has_raw_markup("<img src=\"x\" onerror=\"y\">"));
  Document doc;
  doc.title = "<script>t</script>";
  const std::string name = "my<repr> & \"quoted\" | <b>bold</b>";
  Table table;
  table.id = "t";
  table.caption = name;
  table.columns = {name, "<script>"};
  TableCell cell = text_cell(name);
  cell.tooltip = "\" onerror=\"alert(1)";
  cell.detail = "<b>";
  table.rows.push_back({cell, verdict_cell(true, name, "", "")});
  Section section{"s", name, 2, {table, Paragraph{{plain(name), code(name), bold(name)}}}};
  section.blocks.push_back(Figure{"x.svg\" onerror=\"alert(1)", name, {plain(name)}, 0});
  doc.sections = {section};
  const std::string html = to_html(doc);
  CHECK_FALSE(has_raw_markup(html));
  CHECK_THAT(html, Contains("my&lt;repr&gt; &amp; &quot;quoted&quot; | &lt;b&gt;bold&lt;/b&gt;"));
  CHECK_THAT(html, Contains("<title>&lt;script&gt;t&lt;/script&gt;</title>"));
  const std::string md = to_markdown(doc);
  // A code span shows its text literally (Markdown does not parse inside it); outside them, no
  // markup.
  CHECK_FALSE(has_raw_markup(std::regex_replace(md, std::regex("`[^`]*`"), "")));
  CHECK_THAT(md, Contains("`my<repr> & \"quoted\" \\| <b>bold</b>`"));
  CHECK_THAT(md, Contains("my&lt;repr&gt; &amp; \"quoted\" \\| &lt;b&gt;bold&lt;/b&gt;"));
  // The '|' in the name is escaped, so every table line keeps its 3 cells (4 unescaped pipes).
  for (const char* line : {"| my", "|---"}) {
    const auto at = md.find(line);
    REQUIRE(at != std::string::npos);
    const std::string row = md.substr(at, md.find('\n', at) - at);
    CHECK(count(std::regex_replace(row, std::regex(R"(\\\|)"), ""), "|") == 3);
  }
  CHECK(html_escape("a&b'\"<>") == "a&amp;b&#39;&quot;&lt;&gt;");
  CHECK(markdown_escape("a|b*c_[d]") == "a\\|b\\*c\\_\\[d\\]");
}

TEST_CASE("audit_part_links_every_no_cell_to_a_witness_with_a_table_and_a_picture", "[unit]") {
  props::Classification classification;
  classification.name = "toy<&>";
  props::Verdict no = verdict(props::Group::se3, false);
  props::Witness w;
  w.scene.world_T_hand_history = {RigidTransform::planar(0.3, 0.1, 0.2),
                                  RigidTransform::planar(0.2, 0.0, 0.1)};
  w.scene.world_T_hand_chunk = {RigidTransform::planar(0.4, 0.2, 0.3)};
  w.g = RigidTransform::planar(1.0, 0.5, -0.5);
  w.before = Eigen::VectorXd::Constant(3, 1.0);
  w.after = Eigen::VectorXd::Constant(3, 3.0);
  w.error = 2.0;
  no.witness = w;
  props::Verdict dist_yes = verdict(props::Group::rotation, true);
  dist_yes.mode = props::Mode::distribution;
  dist_yes.method = props::Method::exact_gaussian;
  props::Verdict no_without_witness = verdict(props::Group::translation, false);
  classification.verdicts = {no, dist_yes, no_without_witness};
  props::AuditOptions options;
  options.views = {props::View::eye_in_hand};
  options.groups = {props::Group::translation, props::Group::rotation, props::Group::se3};
  const AuditPart part = audit_part({classification}, options);
  REQUIRE(part.grids.size() == 1);
  REQUIRE(part.witnesses.size() == 3);  // the heading and two witnesses
  const Table& grid = std::get<Table>(part.grids[0].blocks[0]);
  CHECK(grid.kind == "verdict-grid");
  REQUIRE(grid.rows.size() == 2);  // actions, actions (in distribution)
  const TableCell& se3 = grid.rows[0][3];
  CHECK(se3.mark == Mark::no);
  CHECK(se3.link == "#" + part.witnesses[2].id);
  CHECK(grid.rows[0][1].link == "#" + part.witnesses[1].id);  // no witness: still linked
  CHECK(grid.rows[1][2].detail == "exact");
  CHECK(grid.rows[1][2].mark == Mark::yes);
  CHECK(grid.rows[1][3].text[0].text == "not checked");
  REQUIRE(part.files.size() == 1);
  CHECK(part.files[0].path == "witness/" + part.witnesses[2].id + ".svg");
  CHECK_THAT(part.files[0].bytes, Contains("<svg") && Contains("stroke-dasharray"));
  Document doc;
  doc.title = "audit";
  doc.sections = part.grids;
  doc.sections.insert(doc.sections.end(), part.witnesses.begin(), part.witnesses.end());
  const std::string html = to_html(doc);
  CHECK_THAT(html, Contains("toy&lt;&amp;&gt;"));
  CHECK_THAT(html, Contains("class=\"witness-outputs\""));
  // Planted fault: a grid whose NO cell lost its witness link is refused.
  std::get<Table>(doc.sections[0].blocks[0]).rows[0][3].link.clear();
  CHECK_THROWS_WITH(check(doc), Contains("links to no witness"));
}

TEST_CASE("witness_figure_draws_both_scenes_and_refuses_an_empty_one", "[unit]") {
  Scene scene;
  CHECK_FALSE(drawable(scene));
  CHECK_THROWS_AS(witness_svg(scene, RigidTransform()), InvalidArgument);
  scene.world_T_hand_history = {RigidTransform::planar(0.0, 0.0, 0.0)};
  scene.world_T_hand_chunk = {RigidTransform::planar(0.0, 1.0, 0.0)};
  scene.world_points = {Eigen::Vector3d(0.5, 0.5, 0.0)};
  const RigidTransform g = RigidTransform::planar(0.0, 3.0, 0.0);
  const WitnessPicture picture = witness_picture(scene, g);
  for (const WitnessMarks* marks : {&picture.s, &picture.g_s}) {
    CHECK(marks->chunk.size() == 1);  // the chunk's pose; T_0 and the world point beside it
    CHECK(marks->points.size() == 1);
    CHECK(marks->path.size() == 2);  // T_0, then the chunk
  }
  CHECK(picture.g_s.t0.x() > picture.s.t0.x());  // g moves the hand along +x
  CHECK(picture.across == 0);
  CHECK(picture.up == 1);
  CHECK_THAT(witness_svg(scene, g), Contains("<svg"));
  // A g along z would draw s and g s on top of each other from above: the side view shows it.
  const WitnessPicture side =
      witness_picture(scene, RigidTransform::from_translation(Eigen::Vector3d(0.0, 0.0, 5.0)));
  CHECK(side.across == 0);
  CHECK(side.up == 2);
}

TEST_CASE("claims_part_links_each_claim_to_its_line_of_the_claims_file", "[unit]") {
  CHECK(equation_of("A.4 eqs. (27)-(29), path on p") == "(27)-(29)");
  CHECK(equation_of("Sec. 3.1 Lemma 1, eq. (8)") == "(8)");
  CHECK(equation_of("Sec. 3.2 Lemma 2, third-person") == "Lemma 2");
  CHECK(equation_of("Sec. 5 vs A.4, rotations in distribution") == "-");
  proofs::ClaimOutcome verified{"A.3 eq. (23)",
                                "hand-centric is invariant",
                                proofs::ClaimKind::identity,
                                proofs::ClaimSection::identities,
                                "",
                                {true, "", "0"}};
  proofs::ClaimOutcome failed{"A.1 eq. (13)",
                              "absolute is not <invariant>",
                              proofs::ClaimKind::counterexample,
                              proofs::ClaimSection::counterexamples,
                              "",
                              {false, "", "nope"}};
  const ClaimsPart part = claims_part({verified, failed});
  CHECK(part.verified == 1);
  REQUIRE(part.table.rows.size() == 2);
  REQUIRE(part.files.size() == 2);
  const std::string& markdown = part.files[0].bytes;
  CHECK(markdown == proofs::report_markdown({verified, failed}));
  for (std::size_t r = 0; r < 2; ++r) {
    const std::string& link = part.table.rows[r][5].text[0].link;
    const int line = claim_line(markdown, part.table.rows[r][0].text[0].text);
    REQUIRE(line > 0);
    CHECK(link == "claims.html#L" + std::to_string(line));
    CHECK_THAT(part.files[1].bytes, Contains("<tr id=\"L" + std::to_string(line) + "\">"));
  }
  CHECK(part.table.rows[1][4].mark == Mark::no);
  CHECK_FALSE(part.table.rows[1][4].link.empty());
  // Planted fault: a claim the file does not have is not found (line 0), not linked to line 1.
  CHECK(claim_line(markdown, "A.9 eq. (99)") == 0);
}

TEST_CASE("results_tables_put_wilson_intervals_beside_the_papers_numbers", "[unit]") {
  Row row;
  row.method = "hand_centric";
  row.head = "flow";
  row.demos = 100;
  row.trials = 30;
  row.id_success = 29.0 / 30;
  row.id_ci = wilson_interval(29, 30);
  row.ood_success = 1.0;
  row.ood_ci = wilson_interval(30, 30);
  const Table t1 = table1_table({row}, "t1", "Table 1");
  REQUIRE(t1.rows.size() == 1);
  CHECK(t1.rows[0][3].text[0].text == "0.97 [0.83, 0.99]");
  CHECK(t1.rows[0][4].text[0].text == "0.98 (Hand-Centric-Flow)");
  CHECK(t1.rows[0][6].text[0].text == "0.96");
  CHECK(t1.rows[0][7].text[0].text == "-");
  Table2Row r2;
  r2.method = "hand_centric";
  r2.demos = 100;
  r2.train = {30, 30};
  r2.ood = {30, 29};
  r2.random_se3 = {30, 0};
  const Table t2 = table2_table({r2}, "t2");
  REQUIRE(t2.rows.size() == 2);
  CHECK(t2.rows[0][4].text[0].text == "29/30: 0.97 [0.83, 0.99]");
  CHECK(t2.rows[0][5].text[0].text == "0/30: 0.00 [0.00, 0.11]");
  CHECK(t2.rows[1][3].text[0].text == "26/30: 0.87 [0.70, 0.95]");
}
