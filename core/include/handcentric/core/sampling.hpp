#pragma once
// Seeded sampling of rotations and transforms outside RapidCheck (reports, benchmarks, sweeps).
// Same seed, same bits: std::mt19937_64 and our own transforms of its raw 64-bit output (no
// std::*_distribution, whose algorithms differ between standard libraries).
#include <cstdint>
#include <random>

#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/core/rotation.hpp"
#include "handcentric/core/scene.hpp"

namespace handcentric {

/// A uniform double in [0, 1) from the top 53 bits of one draw.
double uniform01(std::mt19937_64& rng);

/// A standard normal (Box-Muller on two uniform01 draws).
double standard_normal(std::mt19937_64& rng);

/// Shoemake's map from three uniforms in [0, 1) to a unit quaternion: Haar-uniform rotations
/// when the inputs are uniform. Deterministic.
Rotation shoemake_rotation(double u1, double u2, double u3);

/// The inverse of the CDF F(t) = (t - sin t) / pi of a Haar rotation's angle (density
/// (1 - cos t) / pi on [0, pi]), to double precision: a uniform u in [0, 1) gives a Haar angle;
/// haar_angle(0) = 0 and the angle grows with u (so a rotation drawn as a uniform axis and this
/// angle shrinks toward the identity as u does). Deterministic; u outside (0, 1) clamps.
double haar_angle(double u);

/// The map from two uniforms in [0, 1) to a uniformly distributed unit vector.
Eigen::Vector3d sphere_point(double u1, double u2);

/// A Haar-uniform rotation (Shoemake's method).
Rotation random_rotation(std::mt19937_64& rng);

/// A rotation by exactly `angle` about a uniformly random axis.
Rotation random_rotation_with_angle(std::mt19937_64& rng, double angle);

/// A Haar rotation and a translation with coordinates uniform in [-max_abs, max_abs].
RigidTransform random_transform(std::mt19937_64& rng, double max_abs);

/// A scene with H past poses, K actions (a constant random body twist per step, translations up
/// to 0.1 and angles up to 0.3 rad per step), `hand_points` eye-in-hand points within 1 of the
/// hand and `world_points` world points; the hand starts at random_transform(rng, max_abs).
Scene random_scene(std::mt19937_64& rng, int H, int K, int hand_points, int world_points,
                   double max_abs);

}  // namespace handcentric
