#pragma once
// The rows of Table 1: a method is a representation of the actions, and the paper's row it
// stands for. c8flow brings its own head (the C8-symmetrized flow on absolute actions); the
// others take the head from --heads.
#include <array>
#include <optional>
#include <string>
#include <vector>

namespace handcentric::experiments {

struct Method {
  std::string name;            ///< "hand_centric", "relative", "absolute", "c8flow"
  std::string representation;  ///< core/representations.hpp name
  std::string fixed_head;      ///< the head it always uses ("c8flow"), empty: --heads
  std::string label;           ///< the row label of our table
};

/// The four methods of Table 1, in the paper's row order.
const std::vector<Method>& table1_methods();

/// A comma-separated list of method names, e.g. "hand_centric,absolute". Throws InvalidArgument
/// naming the unknown or repeated name and the valid names.
std::vector<Method> parse_methods(const std::string& list);

/// A comma-separated list of heads among flow, ddpm, cvae. Throws InvalidArgument naming the
/// value and the valid names.
std::vector<std::string> parse_heads(const std::string& list);

/// The demo counts of Table 1's columns.
inline constexpr std::array<int, 7> kPaperDemoCounts = {5, 10, 20, 40, 60, 80, 100};

/// The paper's Table 1 row for a method with the flow head (Equivariant-DiffPo for c8flow):
/// success at each of kPaperDemoCounts, and out of distribution at 100 demos.
struct PaperRow {
  std::string label;
  std::array<double, 7> success;
  double ood_at_100 = 0.0;
};
std::optional<PaperRow> paper_row(const std::string& method, const std::string& head);

}  // namespace handcentric::experiments
