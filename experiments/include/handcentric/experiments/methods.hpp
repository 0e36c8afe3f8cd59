#pragma once
// The rows of Table 1: a method is a representation of the actions, and the paper's row it
// stands for. The three C8 rows bring their own head, stand-ins for Equivariant-DiffPo [7]:
// c8ddpm (policy/c8_planar.hpp: DDPM on planar poses trained on the C8 orbit of its data,
// equivariant only as far as the network learned it) with the symmetry centre at the workspace
// centre (c8_centre) or at a robot base off it (c8_base), and c8ddpm_avg (c8_averaged), the
// same network with each denoising step averaged over C8 about the workspace centre, exactly
// equivariant whatever it learned (policy/c8_averaged.hpp). c8_centre and c8_averaged train the
// same weights, so the two rows differ by the sampler alone: learned against constructed
// symmetry. c8flow_centre and c8flow_averaged are the same pair with the rectified flow inside
// (c8flow_planar, c8flow_avg), which the default grid leaves out (--methods adds them): they
// train 30000 steps where the DDPM rows stop at 10000. The others take the head from --heads.
#include <array>
#include <optional>
#include <string>
#include <vector>

namespace handcentric::experiments {

struct Method {
  std::string name;  ///< "hand_centric", "relative", "absolute", "c8_centre", "c8_base", ...
  std::string representation;  ///< core/representations.hpp name
  std::string fixed_head;      ///< the head it always uses ("c8ddpm", "c8ddpm_avg"), empty: --heads
  std::string label;           ///< the row label of our table
  std::array<double, 2> c8_centre = {0.0, 0.0};  ///< c8ddpm's symmetry centre (world x, y; cm)
};

/// The workspace centre and the robot base the C8 rows rotate about (cm). The hole's opening
/// is placed in [-50, 50]^2 (sim/scenes.hpp), so (0, 0) is the workspace's centre; the base
/// stands 10 cm in front of the workspace's near edge, as a table-mounted arm's would.
inline constexpr std::array<double, 2> kWorkspaceCentre = {0.0, 0.0};
inline constexpr std::array<double, 2> kRobotBase = {0.0, -60.0};

/// The methods of Table 1, in the paper's row order (the C8 rows last).
const std::vector<Method>& table1_methods();

/// `list` split at commas, empty items kept: the lists of --methods, --heads, --demos and
/// --train-seeds.
std::vector<std::string> split_list(const std::string& list);

/// A comma-separated list of method names, e.g. "hand_centric,absolute". Throws InvalidArgument
/// naming the unknown or repeated name and the valid names.
std::vector<Method> parse_methods(const std::string& list);

/// A comma-separated list of heads among flow, ddpm, cvae. Throws InvalidArgument naming the
/// value and the valid names.
std::vector<std::string> parse_heads(const std::string& list);

/// The demo counts of Table 1's columns.
inline constexpr std::array<int, 7> kPaperDemoCounts = {5, 10, 20, 40, 60, 80, 100};

/// The paper's Table 1 row for a method with the flow head (Equivariant-DiffPo for the C8 rows):
/// success at each of kPaperDemoCounts, and out of distribution at 100 demos.
struct PaperRow {
  std::string label;
  std::array<double, 7> success;
  double ood_at_100 = 0.0;
};
std::optional<PaperRow> paper_row(const std::string& method, const std::string& head);

}  // namespace handcentric::experiments
