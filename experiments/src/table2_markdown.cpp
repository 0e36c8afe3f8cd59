// table2.md (table2.hpp): what the run was, then Table 2 as results_page.hpp renders it, through
// the page's Markdown renderer (document_markdown.hpp).
#include <algorithm>

#include "handcentric/core/format.hpp"
#include "handcentric/experiments/document_markdown.hpp"
#include "handcentric/experiments/results_page.hpp"
#include "handcentric/experiments/table2.hpp"

namespace handcentric::experiments {

std::string table2_markdown(const std::vector<Table2Row>& rows) {
  Document page;
  page.title = "Table 2 (3D blade insertion), simulated";
  const auto note = [&](const std::string& text) {
    page.intro.push_back(Paragraph{{plain(text)}});
  };
  if (!rows.empty()) {
    const Table2Row& first = rows.front();
    note("Flow policies trained on " + std::to_string(first.demos) +
         " expert demos of train scenes (seed " + std::to_string(first.seed) +
         "), each evaluated on " + std::to_string(first.train.trials) +
         " closed-loop rollouts per scene set (scenes of seed " + std::to_string(first.seed + 1) +
         "; ood and random-se3 scene i is a global transform of train scene i). Each cell: "
         "successes/trials: success rate [Wilson 95%].");
  }
  // The noise injection of each kind of row, once per kind.
  for (const policy::ObservationKind kind :
       {policy::ObservationKind::key_points, policy::ObservationKind::image}) {
    const auto row = std::find_if(rows.begin(), rows.end(),
                                  [kind](const Table2Row& r) { return r.observation == kind; });
    if (row == rows.end()) continue;
    std::string text =
        std::string(kind == policy::ObservationKind::image ? "Image rows" : "Key-point rows") +
        " train on the demos' scenes";
    if (row->perturbation.copies > 0) {
      text += " and " + std::to_string(row->perturbation.copies) +
              " noise-injected copies of each (the hand moved by up to " +
              format_significant(row->perturbation.max_cm, 6) + " cm and turned by up to " +
              format_significant(row->perturbation.max_deg, 6) + " deg per axis, in its own frame)";
    }
    note(text + ".");
  }
  const auto image = std::find_if(rows.begin(), rows.end(), [](const Table2Row& r) {
    return r.observation == policy::ObservationKind::image;
  });
  if (image != rows.end()) {
    note("Rows marked (image) see no key points: " +
         std::string(image->image.find("2 cameras") != std::string::npos
                         ? "the images of two cameras on the hand ("
                         : "the hand camera's image (") +
         image->image +
         ") through a small CNN trained end to end with the flow head "
         "(experiments/insert3d_image.hpp).");
  }
  note(
      "The last row is the paper's Table 2 (a real robot, blade insertion, 35 trials; not "
      "rerunnable here).");
  page.intro.push_back(table2_table(rows, "table2"));
  return to_markdown(page);
}

}  // namespace handcentric::experiments
