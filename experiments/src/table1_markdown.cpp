// table1.md (table1.hpp): what the run was, then Table 1 as results_page.hpp renders it, through
// the page's Markdown renderer (document_markdown.hpp).
#include <algorithm>

#include "handcentric/experiments/document_markdown.hpp"
#include "handcentric/experiments/results_page.hpp"
#include "handcentric/experiments/table1.hpp"

namespace handcentric::experiments {
namespace {

// `text` with each `...` run as code and the rest plain.
Text with_code(const std::string& text) {
  Text spans;
  bool in_code = false;
  for (std::size_t start = 0;;) {
    const std::size_t at = text.find('`', start);
    const std::string part =
        text.substr(start, at == std::string::npos ? std::string::npos : at - start);
    if (!part.empty()) spans.push_back(in_code ? code(part) : plain(part));
    if (at == std::string::npos) return spans;
    in_code = !in_code;
    start = at + 1;
  }
}

}  // namespace

std::string table1_markdown(const std::vector<Row>& rows, const EvalSettings& eval,
                            std::uint64_t demo_seed, const std::string& training,
                            const sim::Difficulty& difficulty) {
  Document page;
  page.title = "Table 1 on this library";
  const auto note = [&](const std::string& text) {
    page.intro.push_back(Paragraph{with_code(text)});
  };
  note("Success over " + std::to_string(eval.trials) +
       " closed-loop rollouts per cell, with Wilson 95% intervals. Scenes: `id` = train "
       "distribution, eval seed " +
       std::to_string(eval.eval_seed) + "; `ood` = bottom-up holes, their own seed " +
       std::to_string(eval.ood_seed) +
       "; `ood paired` = the global transforms of the id scenes (same seed, same noise: equal "
       "to id exactly when the policy is equivariant). Demos: the first N of `demos --n 100 "
       "--dist train --seed " +
       std::to_string(demo_seed) + "`.");
  if (!difficulty.is_default()) {
    note("Task: " + difficulty.describe() +
         " (the paper's task: workspace 100 cm, clearance 0.1 cm).");
  }
  if (!training.empty()) note("Training data of every cell: " + training + ".");
  const bool audited =
      std::any_of(rows.begin(), rows.end(), [](const Row& r) { return !r.symmetry.empty(); });
  if (audited) {
    note(
        "`audited symmetry`: each model's pointwise audit, eq. (4) with the same noise on both "
        "sides (`handcentric audit --model M --view eye_in_hand --pointwise`, " +
        std::to_string(eval.audit_cases) +
        " cases per group, planar scenes for the 2D task): per group yes when the model is "
        "equivariant, and its largest error (the task's units). A `no`'s number is the error "
        "of the first failing case, and the audit draws small g first: it shows the group is "
        "broken, not by how much (`handcentric audit --profile` measures that).");
  }
  page.intro.push_back(table1_table(rows, "table1", ""));
  return to_markdown(page);
}

}  // namespace handcentric::experiments
