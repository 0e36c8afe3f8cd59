#include "handcentric/experiments/report_page.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "handcentric/core/atomic_file.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/experiments/audit_page.hpp"
#include "handcentric/experiments/claims_page.hpp"
#include "handcentric/experiments/document_html.hpp"
#include "handcentric/experiments/document_markdown.hpp"
#include "handcentric/experiments/flow_figure.hpp"
#include "handcentric/experiments/locate_page.hpp"
#include "handcentric/experiments/methods.hpp"
#include "handcentric/experiments/model_profile.hpp"
#include "handcentric/experiments/profile_plot.hpp"
#include "handcentric/experiments/report_audit.hpp"
#include "handcentric/experiments/results_page.hpp"
#include "handcentric/experiments/table1.hpp"
#include "handcentric/experiments/table2.hpp"
#include "handcentric/proofs/claims.hpp"
#include "handcentric/sim/expert_check.hpp"
#include "handcentric/sim/scenes.hpp"

namespace handcentric::experiments {
namespace {

// Runs a Table 1 grid into `dir` (resuming what is there), writes its table1.md/.png, and
// returns its rows, read back from the result files.
std::vector<Row> table_into(const std::string& dir, const std::vector<int>& demo_counts, int trials,
                            const std::vector<Method>& methods,
                            const std::vector<std::string>& heads, const ReportPageOptions& page,
                            std::vector<Cell>* cells = nullptr) {
  Table1Options table;
  table.demo_counts = demo_counts;
  table.eval.trials = trials;
  table.methods = methods;
  table.heads = heads;
  table.steps = page.steps;
  table.jobs = page.jobs;
  table.out = dir;
  table.resume = true;
  table.quiet = true;
  table.validate();
  const Table1Grid grid = prepare_table1(table);
  run_table1(table, grid);
  (void)collect_table1(grid.dir);
  std::vector<Row> rows;
  for (const Cell& cell : grid.cells) rows.push_back(collect_row(cell, table.eval, grid.dir));
  if (cells != nullptr) *cells = grid.cells;
  return rows;
}

// What a Table 1 figure (experiments/plot.hpp) shows, up to its PNG link.
std::string table1_figure_caption(std::size_t demo_counts) {
  return std::string(demo_counts == 1
                         ? "Success per method and head at one demo count: train scenes and "
                           "independent OOD scenes, the paper's number as a black tick"
                         : "Success against demos: train scenes solid, independent OOD scenes "
                           "dashed") +
         "; Wilson 95% bars (SVG; ";
}

Section section(std::string id, std::string title) {
  Section out;
  out.id = std::move(id);
  out.title = std::move(title);
  return out;
}

// The audit: the built-ins' grids, how to read them, and whether they match App. A; their
// witnesses go to `witnesses`, an appendix of the page.
std::vector<Section> audit_sections(const ReportPageOptions& page, std::vector<PageFile>& files,
                                    std::vector<Section>& witnesses, bool& matches) {
  std::fprintf(stderr, "report: audit\n");
  const ReportAudit run = run_report_audit(page.cases, page.seed);
  const props::AuditOptions& audit = run.options;
  const std::vector<std::string>& mismatches = run.mismatches;
  matches = mismatches.empty();
  Section top = section("audit",
                        "Audit: which global transforms each representation is "
                        "invariant under");
  top.blocks.push_back(Paragraph{
      {plain("Each built-in representation (and ActionFlow's target) checked under each group "
             "of global transforms g: " +
             std::to_string(audit.cases) + " cases per pointwise cell, " +
             std::to_string(run.classifier.distribution.cases) +
             " per in-distribution cell, seed " + std::to_string(audit.seed) + " ("),
       code("handcentric audit --cases " + std::to_string(audit.cases) + " --seed " +
            std::to_string(audit.seed)),
       plain(" prints the same on a terminal; docs/AUDIT.md says what each verdict means).")}});
  top.blocks.push_back(List{{
      {bold("✓ yes"), plain(": f(g·s) = f(s) on every case (in distribution: the laws agree).")},
      {bold("✗ NO"),
       plain(": a case where it does not; the cell links to that witness (the appendix).")},
      {bold("m/1"), plain(": the largest error seen, in the component's units: metres for "
                          "positions, no unit for rotation-matrix entries (one max-norm over "
                          "both). In distribution: the largest difference of the laws' moments "
                          "(exact), or the energy distance (test).")},
      {bold("exact / test"),
       plain(": how an in-distribution cell was decided: the laws compared exactly as "
             "Gaussians, or by the energy, mean and scale tests (a 'yes' then means no difference "
             "was found).")},
  }});
  if (matches) {
    top.blocks.push_back(
        Paragraph{{bold("Every cell matches App. A of the paper"), plain(kPaperPattern)}});
  } else {
    List differ;
    for (const std::string& line : mismatches) differ.items.push_back({plain(line)});
    top.blocks.push_back(
        Paragraph{{bold(std::to_string(mismatches.size()) + " cell(s) differ from the paper:")}});
    top.blocks.push_back(std::move(differ));
  }
  std::vector<Section> out = {std::move(top)};
  AuditPart part = audit_part(run.results, audit);
  for (Section& s : part.grids) out.push_back(std::move(s));
  if (!part.witnesses.empty()) {
    Section appendix = section("witnesses", "Appendix: the witnesses of the audit's NO cells");
    appendix.blocks.push_back(Paragraph{
        {plain("Each NO cell of the grids links here: the scene s (its sizes and T_0), the "
               "global transform g, the two outputs coordinate by coordinate and, projected on two "
               "world axes, "
               "the hand's path in s and in g s.")}});
    witnesses.push_back(std::move(appendix));
    for (Section& s : part.witnesses) witnesses.push_back(std::move(s));
  }
  for (PageFile& f : part.files) files.push_back(std::move(f));
  return out;
}

Section certificates_section(std::vector<PageFile>& files, bool& all_verified) {
  std::fprintf(stderr, "report: certificates\n");
  const auto outcomes = proofs::certify_all(proofs::paper_claims());
  ClaimsPart claims = claims_part(outcomes);
  all_verified = claims.verified == static_cast<int>(outcomes.size());
  Section out = section("certificates", "Certificates: the paper's claims, exactly");
  out.blocks.push_back(Paragraph{
      {plain(std::to_string(claims.verified) + "/" + std::to_string(outcomes.size()) +
             " certificates verified. An identity is proved symbolically for generic inputs; a "
             "counterexample is one exact input where the two sides differ ("),
       code("handcentric prove"), plain("; each row links to its entry in "),
       plain("docs/CLAIMS.md", "claims.html"), plain(").")}});
  out.blocks.push_back(std::move(claims.table));
  for (PageFile& f : claims.files) files.push_back(std::move(f));
  return out;
}

Section sim_section(bool& passes) {
  std::fprintf(stderr, "report: the sim's bar\n");
  Section out = section("sim", "The 2D peg-in-hole task: the expert's bar");
  out.blocks.push_back(Paragraph{
      {plain("Sec. 4.2's task: expert demos on " + std::to_string(sim::kExpertBarScenes) +
             " scenes and closed-loop expert rollouts on " +
             std::to_string(sim::kExpertBarRollouts) + " scenes per distribution, seed " +
             std::to_string(sim::kExpertBarSeed) +
             ". The bar: at least 99% solved and 99% inserted in closed loop (docs/SIM.md; "),
       code("handcentric demos"), plain(" and "), code("handcentric eval --policy expert"),
       plain(" reproduce these).")}});
  Table table;
  table.id = "sim-bar";
  table.kind = "results";
  table.caption = "The expert on the train and OOD scenes";
  table.columns = {"distribution", "expert solved", "discard rate", "closed loop", "bar (99%)"};
  passes = true;
  for (const auto& distribution :
       {sim::SceneDistribution::train(), sim::SceneDistribution::ood()}) {
    const sim::ExpertCheck check = sim::check_expert(distribution, sim::kExpertBarScenes,
                                                     sim::kExpertBarRollouts, sim::kExpertBarSeed);
    passes = passes && check.passes();
    table.rows.push_back(
        {text_cell(distribution.name), text_cell(format_fixed(100.0 * check.solved_rate, 1) + "%"),
         text_cell(format_fixed(check.discard_rate, 3)),
         text_cell(std::to_string(check.rollout_success) + "/" + std::to_string(check.rollouts)),
         verdict_cell(check.passes(), check.passes() ? "met" : "below the bar", "",
                      check.passes() ? "" : "#sim")});
  }
  out.blocks.push_back(std::move(table));
  return out;
}

// The table of public conventions, audited afresh from their plug-ins as docs/CONVENTIONS.md is
// (experiments/conventions.hpp), at its cases and seed; a note instead when there is no folder.
std::vector<Section> conventions_page_sections(const ReportPageOptions& page) {
  ConventionsOptions options;
  options.folder = page.conventions;
  options.python = page.python;
  // The plug-in column links each file from where the page is written.
  std::filesystem::path folder = std::filesystem::absolute(options.folder).lexically_normal();
  if (folder.filename().empty()) folder = folder.parent_path();  // "conventions/"
  const std::filesystem::path out = std::filesystem::absolute(page.out).lexically_normal();
  options.plugin_links = folder.lexically_relative(out).generic_string() + "/";
  if (!std::filesystem::is_directory(options.folder)) {
    Section note = section("conventions", "Public pose conventions, audited");
    note.blocks.push_back(
        Paragraph{{plain("Not run: no folder of convention plug-ins at " + options.folder + " ("),
                   code("--conventions DIR"), plain(": the source tree's conventions/).")}});
    return {std::move(note)};
  }
  options.progress = [](const std::string& name, int index, int count) {
    std::fprintf(stderr, "report: convention %s (%d/%d)\n", name.c_str(), index, count);
  };
  try {
    return conventions_sections(audit_conventions(options), options);
  } catch (const Error& error) {
    // The rest of the page stands without this table; say why it is missing, there and here.
    std::fprintf(stderr, "report: the conventions' table is left out: %s\n", error.what());
    Section note = section("conventions", "Public pose conventions, audited");
    note.blocks.push_back(Paragraph{{plain("Not run: " + std::string(error.what()) + " ("),
                                     code("--conventions DIR --python PYTHON"), plain(").")}});
    return {std::move(note)};
  }
}

// How far from equivariant each Table 1 row's model is (props/profile.hpp), under the groups
// that keep the 2D task's plane: one figure per group, the model of each method at the largest
// demo count and the first training seed. Figures go to DIR/profiles/<group>.png.
Section profiles_section(const std::filesystem::path& dir, const std::vector<Cell>& cells) {
  Section out = section("profiles", "How far from equivariant: Table 1's models");
  int demos = 0;
  for (const Cell& cell : cells) demos = std::max(demos, cell.demos);
  std::vector<const Cell*> models;  // one per method, in Table 1's order
  for (const Cell& cell : cells) {
    if (cell.demos != demos) continue;
    bool seen = false;
    for (const Cell*& m : models) {
      if (m->method != cell.method) continue;
      seen = true;
      if (cell.train_seed < m->train_seed) m = &cell;
    }
    if (!seen) models.push_back(&cell);
  }
  out.blocks.push_back(Paragraph{
      {plain("The normalized error of each model's chunk, |g a(o, n) - a(g o, n)| over the "
             "chunk's reach, against the size of g (median over 8 scenes of the task's own "
             "planar kind; in distribution too where the head is affine in its noise), as "),
       code("handcentric audit --model M --profile GROUP"),
       plain(" draws it; the models are Table 1's at " + std::to_string(demos) +
             " demos. Theorem 1 makes the hand-centric model flat at rounding; an absolute model "
             "grows with any g; a model made C8-equivariant by construction (c8_averaged, "
             "with --methods) is zero at the multiples of 45 degrees about its centre only, "
             "and the C8 stand-ins trained with rotated copies only as far as they learned it. "
             "How a profile is made: docs/AUDIT.md, \"Profiles\".")}});
  std::filesystem::create_directories(dir / "profiles");
  for (const props::Group group :
       {props::Group::translation, props::Group::se2, props::Group::c8}) {
    props::ProfileOptions options;
    options.scenes = 8;
    std::vector<props::Profile> profiles;
    for (const Cell* cell : models) {
      props::Profile p =
          profile_model((dir / "table1" / cell->model_path()).string(), group, options);
      p.name = cell->method;
      profiles.push_back(std::move(p));
    }
    if (profiles.empty()) continue;
    const std::string name = props::to_string(group);
    write_profiles_png((dir / "profiles" / (name + ".png")).string(), profiles);
    out.blocks.push_back(Figure{"profiles/" + name + ".png",
                                "profiles of Table 1's models under " + name,
                                {plain("Under " + name + " (" + props::profile_unit(group) +
                                       "): filled dots the pointwise median, open circles its "
                                       "maximum, hollow squares the in-distribution median.")},
                                0});
  }
  return out;
}

// Table 1's hand-centric model (the largest demo count, the first training seed) and the same
// model with a world-frame bias in its second layer, located under se2 (locate_page.hpp).
std::vector<Section> locate_table1_sections(const std::filesystem::path& dir,
                                            const std::vector<Cell>& cells, std::uint64_t seed) {
  const Cell* model = nullptr;
  for (const Cell& cell : cells) {
    if (cell.method != "hand_centric") continue;
    if (!model || cell.demos > model->demos ||
        (cell.demos == model->demos && cell.train_seed < model->train_seed))
      model = &cell;
  }
  if (!model) {
    Section out = section("locate", "Where the symmetry breaks: a planted fault located");
    out.blocks.push_back(Paragraph{
        {plain("Table 1 ran no hand_centric row (--methods), so no model is located here; "),
         code("handcentric audit --model M --locate"), plain(" locates any model file.")}});
    return {std::move(out)};
  }
  return locate_sections(
      (dir / "table1" / model->model_path()).string(),
      "Table 1's hand-centric model at " + std::to_string(model->demos) + " demos",
      props::Group::se2, kReportLocateCases, seed);
}

}  // namespace

int write_report_page(const ReportPageOptions& page) {
  const auto start = std::chrono::steady_clock::now();
  (void)report_audit_options(page.cases, page.seed);  // --cases, before any work
  if (page.table2_demos < 1 || page.table2_demos > 1000) {
    throw InvalidArgument("--table2-demos " + std::to_string(page.table2_demos) +
                          " is out of range: use 1..1000");
  }
  const std::filesystem::path dir = std::filesystem::absolute(page.out);
  std::filesystem::create_directories(dir);
  std::vector<PageFile> files;
  Document doc;
  doc.title = "handcentric report";
  bool audit_matches = false, verified = false, sim_passes = false;
  std::vector<Section> witnesses;
  std::vector<Section> sections = audit_sections(page, files, witnesses, audit_matches);
  sections.push_back(certificates_section(files, verified));
  sections.push_back(sim_section(sim_passes));
  for (Section& s : conventions_page_sections(page)) sections.push_back(std::move(s));

  std::fprintf(stderr, "report: Fig. 3\n");
  write_flow_figure_png((dir / "fig3.png").string(), compute_flow_figure());
  Section fig3 = section("fig3", "Fig. 3: the flow of the first action under a global transform");
  fig3.blocks.push_back(Figure{
      "fig3.png",
      "Fig. 3",
      {plain("Rows: a demonstrated chunk and the same chunk after a global transform g; columns: "
             "absolute, relative and hand-centric actions ("),
       code("handcentric figure flow"), plain(").")},
      0});
  sections.push_back(std::move(fig3));

  const std::vector<int> demo_counts =
      page.full ? std::vector<int>(kPaperDemoCounts.begin(), kPaperDemoCounts.end())
                : parse_int_list(page.demos, "--demos");
  const int trials = page.full ? EvalSettings{}.trials : page.trials;
  std::fprintf(stderr, "report: Table 1 (%zu demo counts, %d trials per scene set)\n",
               demo_counts.size(), trials);
  std::vector<Cell> table1_cells;
  const auto table1 = table_into((dir / "table1").string(), demo_counts, trials,
                                 parse_methods(page.methods), {"flow"}, page, &table1_cells);
  Section t1 = section("table1", std::string("Table 1") + (page.full ? "" : " (quick)") +
                                     ": success on the 2D task against the paper's");
  t1.blocks.push_back(Paragraph{
      {plain(page.full
                 ? "The paper's grid: 5 to 100 demos, 100 rollouts per scene set. "
                 : "A quick run: demo counts " + page.demos + " only, " + std::to_string(trials) +
                       " rollouts per scene set (the paper: 5 to 100 demos, 100 trials; "
                       "--full runs its grid). "),
       plain("Success rates with their Wilson 95% intervals; OOD (independent) scenes are new "
             "scenes out of the training distribution, OOD (paired) the in-distribution scenes "
             "under a global transform. Models and result files: "),
       plain("table1/", "table1/table1.json"), plain(".")}});
  t1.blocks.push_back(table1_table(table1, "table1-rows", "Table 1: ours beside the paper"));
  t1.blocks.push_back(Figure{"table1/table1.svg",
                             "Table 1 plotted",
                             {plain(table1_figure_caption(demo_counts.size())),
                              plain("PNG", "table1/table1.png"), plain(").")},
                             0});
  sections.push_back(std::move(t1));
  std::fprintf(stderr, "report: the profiles of Table 1's models\n");
  sections.push_back(profiles_section(dir, table1_cells));
  std::fprintf(stderr, "report: where the symmetry breaks\n");
  for (Section& s : locate_table1_sections(dir, table1_cells, page.seed))
    sections.push_back(std::move(s));

  Table2Options t2options;
  t2options.demos = page.table2_demos;
  t2options.trials = trials;
  t2options.steps = page.steps > 0 ? page.steps : (page.full ? 0 : kQuickTable2Steps);
  t2options.jobs = page.jobs;
  t2options.out = (dir / "table2").string();
  t2options.quiet = true;
  t2options.validate();
  std::fprintf(stderr, "report: Table 2 (%d demos, %d trials per scene set)\n", t2options.demos,
               trials);
  const std::vector<Table2Row> table2 = run_table2(t2options);
  Section t2 = section("table2", std::string("Table 2") + (page.full ? "" : " (quick)") +
                                     ": the 3D blade insertion against the paper's");
  t2.blocks.push_back(Paragraph{
      {plain("The analogue of the paper's real-robot Table 2 on the simulated 3D insertion: flow "
             "policies trained on " +
             std::to_string(t2options.demos) + " expert demos of train scenes, each evaluated on " +
             std::to_string(trials) +
             " closed-loop rollouts per set; ood and random-se3 scene i is a global transform of "
             "train scene i. The paper's row is a real robot's (not rerunnable here). Files: "),
       plain("table2/", "table2/table2.json"), plain(".")}});
  t2.blocks.push_back(table2_table(table2, "table2-rows"));
  t2.blocks.push_back(Figure{"table2/table2.svg",
                             "Table 2 plotted",
                             {plain("Success per method and scene set, Wilson 95% bars, the "
                                    "paper's hand-centric numbers as black ticks (SVG; "),
                              plain("PNG", "table2/table2.png"), plain(").")},
                             0});
  sections.push_back(std::move(t2));

  const std::vector<int> ablation_counts =
      page.full ? std::vector<int>{10, 40, 100}
                : parse_int_list(page.ablation_demos, "--ablation-demos");
  std::fprintf(stderr, "report: Fig. 5 (heads flow, ddpm, cvae)\n");
  const auto ablation =
      table_into((dir / "fig5").string(), ablation_counts, trials,
                 parse_methods("hand_centric,absolute"), {"flow", "ddpm", "cvae"}, page);
  Section fig5 =
      section("fig5", "Fig. 5: the learning algorithm against the representation (App. B)");
  fig5.blocks.push_back(Paragraph{
      {plain("Hand-centric and absolute actions, each with a flow, a DDPM and a CVAE head, at demo "
             "counts " +
             (page.full ? std::string("10, 40, 100") : page.ablation_demos) + ", " +
             std::to_string(trials) +
             " rollouts per scene set. The paper's finding: the representation, not the learning "
             "algorithm, decides success.")}});
  fig5.blocks.push_back(table1_table(ablation, "fig5-rows", "Fig. 5's grid"));
  fig5.blocks.push_back(Figure{"fig5/table1.svg",
                               "Fig. 5",
                               {plain(table1_figure_caption(ablation_counts.size())),
                                plain("PNG", "fig5/table1.png"), plain(").")},
                               0});
  sections.push_back(std::move(fig5));
  for (Section& s : witnesses) sections.push_back(std::move(s));

  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::string took = "made in " + format_fixed(seconds, 0) + " s of wall time";
  doc.intro.push_back(Paragraph{
      {plain("What this library checks of \"Guaranteed SE(3)-Equivariant Control via "
             "Hand-Centric Behavior Cloning\", run on this machine (" +
             took + "). Regenerate with "),
       code(std::string("handcentric report --out DIR") + (page.full ? " --full" : "")),
       plain("; the same content as Markdown: "), plain("index.md", "index.md"), plain(".")}});
  doc.intro.push_back(List{{
      {bold(audit_matches ? "✓ audit" : "✗ audit"),
       plain(audit_matches ? ": every cell matches App. A" : ": cells differ from App. A"),
       plain(" (", ""), plain("grids", "#audit"), plain(")")},
      {bold(verified ? "✓ certificates" : "✗ certificates"),
       plain(verified ? ": all verified" : ": some not verified"), plain(" ("),
       plain("table", "#certificates"), plain(")")},
      {bold(sim_passes ? "✓ sim" : "✗ sim"),
       plain(sim_passes ? ": the expert meets its 99% bar" : ": the expert is below its bar"),
       plain(" ("), plain("numbers", "#sim"), plain(")")},
  }});
  doc.sections = std::move(sections);
  const int status = audit_matches && verified && sim_passes ? 0 : 1;

  // Everything is built and checked before the first file is written.
  const std::string html = to_html(doc);
  const std::string markdown = to_markdown(doc);
  for (const PageFile& file : files) {
    const std::filesystem::path path = dir / file.path;
    std::filesystem::create_directories(path.parent_path());
    write_file_atomically(path.string(), file.bytes);
  }
  write_file_atomically((dir / "index.md").string(), markdown);
  write_file_atomically((dir / "index.html").string(), html);
  std::cout << "wrote " << (dir / "index.html").string() << " and index.md (" << took << ")"
            << (status == 0 ? "" : "; a section FAILS its bar") << "\n";
  return status;
}

}  // namespace handcentric::experiments
