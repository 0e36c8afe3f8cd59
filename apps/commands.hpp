#pragma once
// The subcommands of `handcentric` and the sections of its main report. Each cmd_*.cpp defines
// its `add_<name>_command` (and at most one report section); commands.cpp lists them all, in one
// constant table each, which is the one place a new command is added.
//
// A command's callback sets `exit_code`. Errors: handcentric::Error -> one line on stderr and
// exit 1 (main.cpp); usage errors -> exit 2 (CLI11).
#include <CLI/CLI.hpp>
#include <cstdint>
#include <ostream>
#include <span>
#include <string_view>

#include "handcentric/props/audit.hpp"

namespace handcentric::apps {

/// What `handcentric report` lets a user set (plain `handcentric` uses the defaults).
struct ReportOptions {
  /// cases per pointwise cell of the audit section (1 to props::kMaxCases) and its seed
  long long cases = props::kDefaultCases;
  std::uint64_t seed = props::AuditOptions{}.seed;
};

using AddCommand = void (*)(CLI::App& app, int& exit_code);

struct Command {
  std::string_view name;
  AddCommand add;
};

/// Every subcommand, sorted by name.
std::span<const Command> commands();

/// One part of the main report (plain `handcentric` / `handcentric report`). `run` returns 0
/// when everything it checked matched the paper, 1 otherwise.
using RunSection = int (*)(std::ostream& out, const ReportOptions& options);

struct ReportSection {
  std::string_view name;
  std::string_view title;  ///< its heading on the report page (`handcentric report --out`)
  RunSection run;
};

/// The main report's sections, in the order they are printed.
std::span<const ReportSection> report_sections();

/// Prints every section; returns 0 when all returned 0.
int run_main_report(std::ostream& out, const ReportOptions& options = {});

// Defined in the cmd_*.cpp file of the same name.
void add_audit_command(CLI::App& app, int& exit_code);
void add_conventions_command(CLI::App& app, int& exit_code);
void add_demos_command(CLI::App& app, int& exit_code);
void add_eval_command(CLI::App& app, int& exit_code);
void add_figure_command(CLI::App& app, int& exit_code);
void add_prove_command(CLI::App& app, int& exit_code);
void add_render_command(CLI::App& app, int& exit_code);
void add_report_command(CLI::App& app, int& exit_code);
void add_table1_command(CLI::App& app, int& exit_code);
void add_table2_command(CLI::App& app, int& exit_code);
void add_train_command(CLI::App& app, int& exit_code);

// The report sections: the audit of the built-in representations (cmd_report.cpp), the exact
// certificates (cmd_prove.cpp) and the 2D sim's own bar (cmd_eval.cpp).
int run_audit_section(std::ostream& out, const ReportOptions& options);
int run_proofs_section(std::ostream& out, const ReportOptions& options);
int run_sim_section(std::ostream& out, const ReportOptions& options);

}  // namespace handcentric::apps
