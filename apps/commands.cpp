#include "commands.hpp"

#include <cstddef>

namespace handcentric::apps {
namespace {

// Sorted by name: the order `handcentric --help` lists them in.
constexpr Command kCommands[] = {
    {"audit", add_audit_command},   {"conventions", add_conventions_command},
    {"demos", add_demos_command},   {"eval", add_eval_command},
    {"figure", add_figure_command}, {"prove", add_prove_command},
    {"render", add_render_command}, {"report", add_report_command},
    {"table1", add_table1_command}, {"table2", add_table2_command},
    {"train", add_train_command},
};

constexpr bool sorted_by_name(std::span<const Command> list) {
  for (std::size_t i = 1; i < list.size(); ++i) {
    if (!(list[i - 1].name < list[i].name)) return false;
  }
  return true;
}
static_assert(sorted_by_name(kCommands), "kCommands: keep one entry per name, sorted by name");

constexpr ReportSection kReportSections[] = {
    {"audit", "Audit: which global transforms each representation is invariant under",
     run_audit_section},
    {"proofs", "Certificates: the paper's claims, exactly", run_proofs_section},
    {"sim", "The 2D peg-in-hole task: the expert's bar", run_sim_section},
};

}  // namespace

std::span<const Command> commands() {
  return kCommands;
}

std::span<const ReportSection> report_sections() {
  return kReportSections;
}

int run_main_report(std::ostream& out, const ReportOptions& options) {
  int status = 0;
  for (const ReportSection& section : report_sections()) {
    if (section.run(out, options) != 0) status = 1;
    out << "\n";
  }
  return status;
}

}  // namespace handcentric::apps
