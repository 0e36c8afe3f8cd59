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

void showValue(const Rotation& rotation, std::ostream& os) {
  os << "Rotation{r = " << format_matrix(rotation.log())
     << ", angle = " << format_number(rotation.angle()) << "}";
}

void showValue(const RigidTransform& transform, std::ostream& os) {
  os << "RigidTransform{R = " << format_matrix(transform.rotation().matrix())
     << ", p = " << format_matrix(transform.translation()) << "}";
}

void showValue(const Scene& scene, std::ostream& os) {
  os << "Scene{H = " << scene.history_length() << ", K = " << scene.chunk_length() << "\n";
  auto pose = [&](const RigidTransform& T) { showValue(T, os); };
  auto point = [&](const Eigen::Vector3d& x) { os << format_matrix(x); };
  show_list(os, "world_T_hand_history [T_0, T_-1, ...]", scene.world_T_hand_history, pose);
  show_list(os, "world_T_hand_chunk [T_1, ...]", scene.world_T_hand_chunk, pose);
  show_list(os, "hand_points (frame hand0)", scene.hand_points, point);
  show_list(os, "world_points (frame world)", scene.world_points, point);
  os << "}";
}

}  // namespace handcentric
