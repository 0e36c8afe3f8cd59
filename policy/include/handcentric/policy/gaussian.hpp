#pragma once
// Seeded standard normals for noise (flow, DDPM, CVAE): Box-Muller from one 64-bit draw of the
// generator per pair (24-bit uniforms, so tails beyond 5.77 sigma, probability 8e-9, are cut),
// both outputs used. Same generator state, same bits on every kernel set (no
// std::normal_distribution).
#include <Eigen/Core>
#include <random>

namespace handcentric::policy {

/// Fills `out` with independent standard normals drawn from `rng`, column by column.
void fill_standard_normal(std::mt19937_64& rng, Eigen::Ref<Eigen::MatrixXf> out);

}  // namespace handcentric::policy
