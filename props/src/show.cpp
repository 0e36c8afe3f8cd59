#include "handcentric/props/show.hpp"

#include "handcentric/core/format.hpp"

namespace handcentric {
namespace {

template <typename Item, typename Print>
void show_list(std::ostream& os, const char* label, const std::vector<Item>& items, Print print) {
  os << "  " << label << " (" << items.size() << "):\n";
  for (const Item& item : items) {
    os << "    ";
    print(item);
    os << "\n";
  }
}

}  // namespace

// Counterexamples print as the witnesses do (verdict.cpp): 6 digits, rounding noise as 0 (the
// seed replays the exact values); a rotation's angle in full, since SO(3) code breaks within
// 1e-9 of pi and 0.
void showValue(const Rotation& rotation, std::ostream& os) {
  os << "Rotation{r = " << format_readable(rotation.log())
     << ", angle = " << format_number(rotation.angle()) << "}";
}

void showValue(const RigidTransform& transform, std::ostream& os) {
  os << "RigidTransform{r = " << format_readable(transform.rotation().log())
     << ", p = " << format_readable(transform.translation()) << "}";
}

void showValue(const Scene& scene, std::ostream& os) {
  os << "Scene{H = " << scene.history_length() << ", K = " << scene.chunk_length() << "\n";
  auto pose = [&](const RigidTransform& T) { showValue(T, os); };
  auto point = [&](const Eigen::Vector3d& x) { os << format_readable(x); };
  show_list(os, "world_T_hand_history [T_0, T_-1, ...]", scene.world_T_hand_history, pose);
  show_list(os, "world_T_hand_chunk [T_1, ...]", scene.world_T_hand_chunk, pose);
  show_list(os, "hand_points (frame hand0)", scene.hand_points, point);
  show_list(os, "world_points (frame world)", scene.world_points, point);
  os << "}";
}

}  // namespace handcentric
