#pragma once
// How `handcentric` subcommands and main-report sections plug in. Each cmd_*.cpp registers
// itself with a static registration object, so adding a command touches no shared file:
//
//   static const CommandRegistration reg("audit", add_audit_command);
//   static const ReportSection section(20, "audit", run_audit_section);
//
// A command's callback sets `exit_code`. Errors: handcentric::Error -> one line on stderr and
// exit 1 (main.cpp); usage errors -> exit 2 (CLI11).
#include <CLI/CLI.hpp>
#include <cstdint>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace handcentric::apps {

using AddCommand = void (*)(CLI::App& app, int& exit_code);

struct CommandRegistration {
  CommandRegistration(std::string name, AddCommand add);
};

struct RegisteredCommand {
  std::string name;
  AddCommand add;
};

/// All registered commands, sorted by name.
std::vector<RegisteredCommand> registered_commands();

/// What `handcentric report` lets a user set (plain `handcentric` uses the defaults).
struct ReportOptions {
  int cases = 1000;        ///< cases per pointwise cell of the audit section
  std::uint64_t seed = 1;  ///< seed of the audit section
};

/// One part of the main report (plain `handcentric` / `handcentric report`), printed in `order`.
/// `run` returns 0 when everything it checked matched the paper, 1 otherwise.
using RunSection = std::function<int(std::ostream& out, const ReportOptions& options)>;

struct ReportSection {
  ReportSection(int order, std::string name, RunSection run);
};

struct RegisteredSection {
  int order;
  std::string name;
  RunSection run;
};

/// All registered report sections, by order.
std::vector<RegisteredSection> report_sections();

/// Prints every section; returns 0 when all returned 0.
int run_main_report(std::ostream& out, const ReportOptions& options = {});

}  // namespace handcentric::apps
