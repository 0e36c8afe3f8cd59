// `handcentric report` (and plain `handcentric`): the main report, and its first section: the
// audit summary of the built-ins (`handcentric audit` without witnesses), one compact table per
// representation, compared cell by cell with what App. A of the paper says
// (experiments/report_audit.hpp).
//
// `handcentric report --out DIR` writes the report as a page (experiments/report_page.hpp).
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "handcentric/experiments/cell.hpp"
#include "handcentric/experiments/methods.hpp"
#include "handcentric/experiments/report_audit.hpp"
#include "handcentric/experiments/report_page.hpp"
#include "handcentric/props/audit.hpp"

namespace handcentric::apps {

int run_audit_section(std::ostream& out, const ReportOptions& options) {
  const experiments::ReportAudit run = experiments::run_report_audit(options.cases, options.seed);
  out << "1. Audit of the built-in representations (handcentric audit; witnesses there)\n"
      << "   " << run.options.cases << " cases per pointwise cell, "
      << run.classifier.distribution.cases << " per in-distribution cell, seed " << run.options.seed
      << "; 'yes' = invariant, the number = largest error seen\n\n";
  props::print_audit(out, run.results, run.options, /*witnesses=*/false);
  if (run.mismatches.empty()) {
    out << "Every cell matches App. A of the paper" << experiments::kPaperPattern << "\n";
    return 0;
  }
  out << run.mismatches.size() << " cell(s) differ from the paper:\n";
  for (const auto& line : run.mismatches) out << "  " << line << "\n";
  return 1;
}

void add_report_command(CLI::App& app, int& exit_code) {
  auto options = std::make_shared<ReportOptions>();
  auto page = std::make_shared<experiments::ReportPageOptions>();
  page->conventions = HANDCENTRIC_CONVENTIONS_DIR;  // the source tree's, not the working folder's
  CLI::App* cmd = app.add_subcommand("report", "the main report (what plain `handcentric` runs)");
  cmd->add_option("--cases", options->cases, "cases per pointwise cell of the audit section")
      ->capture_default_str();
  cmd->add_option("--seed", options->seed, "seed of the audit section")->capture_default_str();
  cmd->add_option("--out", page->out,
                  "write the report as a page: DIR/index.html and index.md, with a quick Table 1 "
                  "and Table 2 and Figs. 3 and 5");
  cmd->add_flag("--full", page->full,
                "with --out: the paper's whole grid (" +
                    std::to_string(experiments::kPaperDemoCounts.size()) + " demo counts, " +
                    std::to_string(experiments::EvalSettings{}.trials) + " trials)");
  cmd->add_option("--demos", page->demos, "with --out: the quick Table 1's demo counts")
      ->capture_default_str();
  cmd->add_option("--trials", page->trials,
                  "with --out: rollouts per scene set of the quick tables")
      ->capture_default_str();
  cmd->add_option("--methods", page->methods, "with --out: Table 1's rows")->capture_default_str();
  cmd->add_option("--ablation-demos", page->ablation_demos, "with --out: Fig. 5's demo counts")
      ->capture_default_str();
  cmd->add_option("--table2-demos", page->table2_demos,
                  "with --out: Table 2's demos (3D insertion)")
      ->capture_default_str();
  cmd->add_option("--steps", page->steps,
                  "with --out: Adam steps per cell and Table 2 policy (0: the library's budget; "
                  "the quick Table 2: " +
                      std::to_string(experiments::kQuickTable2Steps) + ")")
      ->capture_default_str();
  cmd->add_option("--jobs", page->jobs, "with --out: trainings at once (0: one per core)")
      ->capture_default_str();
  cmd->add_option("--conventions", page->conventions,
                  "with --out: the folder of public-convention plug-ins (docs/CONVENTIONS.md)")
      ->capture_default_str();
  cmd->add_option("--python", page->python, "with --out: the interpreter of those plug-ins")
      ->capture_default_str();
  cmd->callback([options, page, &exit_code] {
    (void)props::checked_cases(options->cases);  // before any work: one line, exit 1
    if (page->out.empty()) {
      exit_code = run_main_report(std::cout, *options);
      return;
    }
    page->cases = options->cases;
    page->seed = options->seed;
    exit_code = experiments::write_report_page(*page);
  });
}

}  // namespace handcentric::apps
