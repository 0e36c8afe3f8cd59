#pragma once
// A witness's scene as a picture: the hand's path projected on the two world axes along which
// it spreads most (from above, (x, y), unless z spreads more), for the scene s and for g * s, as
// a small standalone SVG drawn with Cairo (sim/canvas.hpp). Before and after differ in line
// style and marker shape, not in colour alone.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/core/scene.hpp"

namespace handcentric::experiments {

/// True when the scene has something to draw at finite coordinates (a hand pose at least).
bool drawable(const Scene& scene);

/// What the SVG draws of one scene, in its pixels (y down).
struct WitnessMarks {
  std::vector<Eigen::Vector2d> path;    ///< the history from the oldest pose, then the chunk
  std::vector<Eigen::Vector2d> chunk;   ///< the chunk's positions (small hollow marks)
  Eigen::Vector2d t0;                   ///< T_0 (a big filled mark)
  std::vector<Eigen::Vector2d> points;  ///< the world points (filled marks)
};

/// The picture's layout: the two world axes drawn (0 x, 1 y, 2 z; across, then up) and the
/// marks of s and of g * s at one scale. Throws InvalidArgument when the scene is not drawable.
struct WitnessPicture {
  int across = 0, up = 1;
  WitnessMarks s, g_s;
};
WitnessPicture witness_picture(const Scene& scene, const RigidTransform& g, int width = 360,
                               int height = 260);

/// The SVG document: past hand positions, T_0, the chunk's positions joined in order and the
/// world points of s (solid, circles) and of g * s (dashed, squares), scaled to fit together.
/// Throws InvalidArgument when the scene is not drawable.
std::string witness_svg(const Scene& scene, const RigidTransform& g, int width = 360,
                        int height = 260);

}  // namespace handcentric::experiments
