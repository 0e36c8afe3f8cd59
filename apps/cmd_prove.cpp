// `handcentric prove [--json] [--markdown FILE]`: every claim of the paper as an exact
// certificate (proofs/), with its verdict and, for a counterexample, its exact witness.
// Exit status 1 when any certificate fails. --markdown writes the claims report (docs/CLAIMS.md
// is that report) atomically. Also the main report's section 20: "N/N certificates verified".
#include <iostream>
#include <memory>
#include <string>

#include "commands.hpp"
#include "handcentric/core/atomic_file.hpp"
#include "handcentric/proofs/claims.hpp"
#include "handcentric/proofs/report.hpp"

namespace handcentric::apps {
namespace {

struct ProveOptions {
  bool json = false;
  std::string markdown_path;
};

int run_prove(const ProveOptions& options) {
  const std::vector<proofs::ClaimOutcome> outcomes = proofs::certify_all(proofs::paper_claims());
  if (!options.markdown_path.empty()) {
    write_file_atomically(options.markdown_path, proofs::report_markdown(outcomes));
  }
  std::cout << (options.json ? proofs::report_json(outcomes) : proofs::report_text(outcomes));
  if (!options.json && !options.markdown_path.empty()) {
    std::cout << "claims report written to " << options.markdown_path << "\n";
  }
  return proofs::count_verified(outcomes) == static_cast<int>(outcomes.size()) ? 0 : 1;
}

}  // namespace

void add_prove_command(CLI::App& app, int& exit_code) {
  auto options = std::make_shared<ProveOptions>();
  CLI::App* cmd = app.add_subcommand(
      "prove",
      "check every claim of the paper as an exact certificate (identity or counterexample)");
  cmd->add_flag(
      "--json", options->json,
      "print {\"claims\": [{\"id\", \"statement\", \"kind\", \"verified\", \"witness\", ...}]}");
  cmd->add_option("--markdown", options->markdown_path,
                  "also write the claims report to FILE (docs/CLAIMS.md is this report)");
  cmd->callback([options, &exit_code] { exit_code = run_prove(*options); });
}

int run_proofs_section(std::ostream& out, const ReportOptions&) {
  const std::vector<proofs::ClaimOutcome> outcomes = proofs::certify_all(proofs::paper_claims());
  out << "handcentric prove: the paper's claims as exact certificates (details: `handcentric "
         "prove`, docs/CLAIMS.md)\n"
      << proofs::summary_text(outcomes);
  return proofs::count_verified(outcomes) == static_cast<int>(outcomes.size()) ? 0 : 1;
}

}  // namespace handcentric::apps
