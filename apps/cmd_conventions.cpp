// `handcentric conventions`: the table of public pose conventions (docs/CONVENTIONS.md), written
// by auditing each plug-in of conventions/ (experiments/conventions.hpp).
//
//   handcentric conventions --out docs/CONVENTIONS.md       regenerate the committed file
//   handcentric conventions --check docs/CONVENTIONS.md     exit 1 when it is out of date
//   handcentric conventions                                 the Markdown on stdout
//   handcentric conventions --detect episodes.npz           which convention recorded data are in
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
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
#include "handcentric/experiments/shell_quote.hpp"
#include "handcentric/props/audit.hpp"
#include "handcentric/props/checks/classifier.hpp"
#include "handcentric/props/plugin_audit.hpp"

namespace handcentric::apps {
namespace {

struct ConventionsCommandOptions {
  experiments::ConventionsOptions table;
  std::string out, check;
  std::string detect, declared;  ///< --detect FILE, --declared LAYOUT
};

// Pointwise cases per cell of the audit of a best-fitting layout: a verdict row in seconds
// (the table's rows are audited with kConventionsCases).
constexpr int kDetectAuditCases = 50;

std::string read_whole_file(const std::string& path) {
  std::ifstream file(path);
  return std::string((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
}

std::string temporary_path() {
  char path[] = "/tmp/handcentric_detect_XXXXXX";
  const int fd = mkstemp(path);
  if (fd < 0) throw InvalidArgument("cannot create a temporary file in /tmp for the detector");
  close(fd);
  return path;
}

// The eye-in-hand verdict row of a layout audited through the plug-in pipe: per group, actions
// (pointwise) · target law (in distribution) · observation (pointwise), as the table's cells.
std::string verdict_row(const props::Classification& result) {
  std::string row;
  for (props::Group group : props::all_groups()) {
    row += (row.empty() ? "" : " | ") + props::to_string(group);
    const struct {
      props::Component component;
      props::Mode mode;
    } cells[] = {{props::Component::actions, props::Mode::pointwise},
                 {props::Component::flow_target, props::Mode::distribution},
                 {props::Component::observation, props::Mode::pointwise}};
    for (std::size_t i = 0; i < std::size(cells); ++i) {
      const props::Verdict* v = props::find_verdict(result, cells[i].component, cells[i].mode,
                                                    group, props::View::eye_in_hand);
      row += std::string(i == 0 ? " " : " · ") + (v == nullptr ? "-" : v->invariant ? "yes" : "NO");
    }
  }
  return row;
}

// The detector is NumPy code (python/handcentric/detect.py, handcentric.detect_convention), run
// through conventions/_detect.py by the interpreter that runs the plug-ins, so that the command
// and the Python function give one ranking. Its one-line error becomes this command's error.
// A best fit that is a layout (no row of the table) is then audited here, served as a plug-in
// by the same script.
int run_detect(const ConventionsCommandOptions& options) {
  if (!options.out.empty() || !options.check.empty()) {
    throw InvalidArgument(
        "--detect reads recorded episodes; it writes no table: drop --out and "
        "--check");
  }
  if (options.table.python.empty()) throw InvalidArgument("--python is empty; name an interpreter");
  const std::filesystem::path script = std::filesystem::path(options.table.folder) / "_detect.py";
  if (!std::filesystem::is_regular_file(script)) {
    throw InvalidArgument("no detector at '" + script.string() +
                          "': --plugins names the repository's conventions/ folder");
  }
  const std::string errors_path = temporary_path(), best_path = temporary_path();
  const std::string run = options.table.python + " " + experiments::shell_quote(script.string());
  std::string command = run + " " + experiments::shell_quote(options.detect) + " --plugins " +
                        experiments::shell_quote(options.table.folder) + " --best-out " +
                        experiments::shell_quote(best_path);
  if (!options.declared.empty())
    command += " --declared " + experiments::shell_quote(options.declared);
  std::cout.flush();
  const int status = std::system((command + " 2>" + experiments::shell_quote(errors_path)).c_str());
  std::string message = read_whole_file(errors_path), best = read_whole_file(best_path);
  std::remove(errors_path.c_str());
  std::remove(best_path.c_str());
  while (!message.empty() && message.back() == '\n') message.pop_back();
  if (status == -1 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    if (message.empty()) message = "the detector failed (" + command + ")";
    // The detector's last line is its one-line diagnosis (a traceback ends with the exception).
    throw InvalidArgument(message.substr(message.find_last_of('\n') + 1));
  }
  if (!message.empty()) std::cerr << message << "\n";
  while (!best.empty() && best.back() == '\n') best.pop_back();
  if (best.find(' ') == std::string::npos) return 0;  // a row: the table's verdict was printed
  props::AuditOptions audit;
  audit.cases = kDetectAuditCases;
  audit.seed = options.table.seed;
  audit.views = {props::View::eye_in_hand};
  props::PluginAuditSetup setup;
  setup.timeout = options.table.timeout;
  const props::Classification result = props::audit_representation_plugin(
      run + " " + experiments::shell_quote(best) + " --serve", audit, setup);
  std::cout << "audit of " << best << " (eye-in-hand, " << kDetectAuditCases
            << " cases per cell; actions · target law · observation): " << verdict_row(result)
            << "\n";
  return 0;
}

int run_conventions(ConventionsCommandOptions options) {
  if (!options.detect.empty()) return run_detect(options);
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
  cmd->add_option("--detect", options->detect,
                  "rank every convention and pose layout by how well it decodes recorded "
                  "episodes (FILE.npz or FILE.jsonl: state (N,4,4), action (N,d), episode (N,)); "
                  "print the ranking and the best fit's verdict row");
  cmd->add_option("--declared", options->declared,
                  "with --detect: the layout the data are believed in, flagged when they "
                  "contradict it (e.g. pos_euler_xyz)");
  cmd->callback([options, &exit_code] { exit_code = run_conventions(*options); });
}

}  // namespace handcentric::apps
