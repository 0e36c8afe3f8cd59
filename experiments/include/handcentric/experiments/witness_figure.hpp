#pragma once
// A witness's scene as a picture: the hand's path projected on the two world axes along which
// it spreads most (from above, (x, y), unless z spreads more), for the scene s and for g * s, as
// a small standalone SVG. Before and after differ in line style and marker shape,
// not in colour alone.
#include <string>

#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/core/scene.hpp"

namespace handcentric::experiments {

/// True when the scene has something to draw at finite coordinates (a hand pose at least).
bool drawable(const Scene& scene);

/// The SVG document: past hand positions, T_0, the chunk's positions joined in order and the
/// world points of s (solid, circles) and of g * s (dashed, squares), scaled to fit together.
/// Throws InvalidArgument when the scene is not drawable.
std::string witness_svg(const Scene& scene, const RigidTransform& g, int width = 360,
                        int height = 260);

}  // namespace handcentric::experiments
