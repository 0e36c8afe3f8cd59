#pragma once
// Seeded standard normals for noise (flow, DDPM, CVAE): Box-Muller on core's uniform01, using
// both outputs of each pair. Same generator state, same bits (no std::normal_distribution).
#include <Eigen/Core>
#include <random>

namespace handcentric::policy {

/// Fills `out` with independent standard normals drawn from `rng`, column by column.
void fill_standard_normal(std::mt19937_64& rng, Eigen::Ref<Eigen::MatrixXf> out);

}  // namespace handcentric::policy
