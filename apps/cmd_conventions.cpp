// `handcentric conventions`: the table of public pose conventions (docs/CONVENTIONS.md), written
// by auditing each plug-in of conventions/ (experiments/conventions.hpp).
//
//   handcentric conventions --out docs/CONVENTIONS.md       regenerate the committed file
//   handcentric conventions --check docs/CONVENTIONS.md     exit 1 when it is out of date
//   handcentric conventions                                 the Markdown on stdout
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <memory>
#include <string>

#include "commands.hpp"
#include "handcentric/core/atomic_file.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/experiments/conventions.hpp"
#include "handcentric/props/audit.hpp"

namespace handcentric::apps {
namespace {

struct ConventionsCommandOptions {
  experiments::ConventionsOptions table;
  std::string out, check;
};

int run_conventions(ConventionsCommandOptions options) {
  std::string committed;
  if (!options.check.empty()) {
    // Read first: a missing file is named before minutes of auditing.
    std::ifstream file(options.check, std::ios::binary);
    if (!file) {
      throw InvalidArgument("cannot read '" + options.check +
                            "' to check; regenerate it with handcentric conventions --out " +
                            options.check);
    }
    committed.assign(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
  }
  if (!options.out.empty()) {
    // Named before minutes of auditing; the file itself is written atomically at the end.
    const std::filesystem::path parent = std::filesystem::absolute(options.out).parent_path();
    if (!std::filesystem::is_directory(parent)) {
      throw InvalidArgument("cannot write '" + options.out + "': the folder '" + parent.string() +
                            "' does not exist; create it or name another file");
    }
  }
  (void)props::checked_cases(options.table.cases);  // --cases 0: one line before any work
  options.table.progress = [](const std::string& name, int index, int count) {
    std::cerr << "conventions: " << name << " (" << index << "/" << count << ")\n";
  };
  const auto conventions = experiments::audit_conventions(options.table);
  const std::string markdown = experiments::conventions_markdown(conventions, options.table);
  if (!options.out.empty()) {
    write_file_atomically(options.out, markdown);
    std::cout << "wrote " << options.out << " (" << conventions.size() << " conventions)\n";
  }
  if (!options.check.empty()) {
    const experiments::FirstDifference d = experiments::first_difference(committed, markdown);
    if (d.line != 0) {
      std::cerr << "handcentric conventions: '" << options.check
                << "' is out of date: the audit of conventions/ gives another table (first "
                   "difference at line "
                << d.line << ")\n  file:  " << d.first << "\n  audit: " << d.second
                << "\nregenerate it with: handcentric conventions --out " << options.check << "\n";
      return 1;
    }
    std::cout << options.check << " is up to date (" << conventions.size() << " conventions)\n";
  }
  if (options.out.empty() && options.check.empty()) std::cout << markdown;
  // A verdict the theory does not predict is a finding to look at, or a bug: never silent.
  int differing = 0;
  for (const experiments::ConventionAudit& c : conventions) {
    for (const std::string& m : c.mismatches) {
      std::cerr << "handcentric conventions: " << c.name << ": " << m << "\n";
      ++differing;
    }
  }
  if (differing > 0) {
    std::cerr << "handcentric conventions: " << differing
              << " cell(s) differ from the plug-ins' Expect lines (the table says so too)\n";
    return 1;
  }
  return 0;
}

}  // namespace

void add_conventions_command(CLI::App& app, int& exit_code) {
  auto options = std::make_shared<ConventionsCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "conventions",
      "audit the public pose conventions (conventions/*.py) and write their table "
      "(docs/CONVENTIONS.md)");
  cmd->add_option("--plugins", options->table.folder,
                  "the folder of convention plug-ins (every *.py not starting with '_')")
      ->capture_default_str();
  cmd->add_option("--python", options->table.python, "the interpreter that runs them (NumPy)")
      ->capture_default_str();
  cmd->add_option("--cases", options->table.cases,
                  "cases per pointwise cell (the committed table's: the default)")
      ->capture_default_str();
  cmd->add_option("--seed", options->table.seed, "RapidCheck seed")->capture_default_str();
  cmd->add_option("--timeout", options->table.timeout,
                  "seconds to wait for each answer of a plug-in")
      ->capture_default_str();
  cmd->add_option("--out", options->out, "write the Markdown table to FILE (atomically)");
  cmd->add_option("--check", options->check,
                  "exit 1, naming the first differing line, unless FILE is what the audit gives");
  cmd->callback([options, &exit_code] { exit_code = run_conventions(*options); });
}

}  // namespace handcentric::apps
