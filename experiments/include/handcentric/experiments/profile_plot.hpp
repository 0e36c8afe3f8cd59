#pragma once
// How far from equivariant, drawn (props/profile.hpp): the normalized error against the
// transform's size, one colour per profile; the pointwise median as filled dots on a solid line,
// its maximum as small open circles, the in-distribution median as hollow squares on a dashed
// line. The y axis is logarithmic (decades from 1e-16 up); a value below its bottom (exactly 0,
// or rounding below 1e-16) is drawn on the bottom decade's line. The x axis is logarithmic in
// the size, except for c8, whose angles are drawn in degrees on a linear axis with the group's
// elements (multiples of 45 deg) marked. Every mark stays inside the axes' box.
#include <string>
#include <vector>

#include "handcentric/props/checks/profile.hpp"
#include "handcentric/sim/draw.hpp"

namespace handcentric::experiments {

/// The profiles of one group as an RGB image. Throws InvalidArgument for no profiles, profiles
/// of different groups, or a profile without points.
sim::Image draw_profiles(const std::vector<props::Profile>& profiles, int width = 960,
                         int height = 600);

/// draw_profiles, written atomically as a PNG.
void write_profiles_png(const std::string& path, const std::vector<props::Profile>& profiles);

}  // namespace handcentric::experiments
