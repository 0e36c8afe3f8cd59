#pragma once
// The sampler of heads c8ddpm_avg and c8flow_avg: the C8 stand-ins for Equivariant Diffusion
// Policy [7] that are C8-equivariant by construction, not only as far as their network learned
// it (c8ddpm, c8flow_planar). What follows says DDIM step; for c8flow_avg read Euler step
// x + f(x, t, o) / N, whose average is the averaged velocity field itself.
//
// Its network is c8ddpm's (c8_planar.hpp: DDPM with epsilon prediction on planar poses
// (x, y, z, cos, sin), trained on the C8 orbit of its data about config.c8_centre_*; eye-in-hand
// points untouched, as [7]'s eye-in-hand features are invariant). What changes is the sampler:
// each DDIM step phi(x, o), as a map of raw planar coordinates (normalization, network, clip and
// update included), is replaced by its group average
//
//   Phi(x, o) = 1/8 sum_{k=0..7} g_k^-1 phi(g_k x, g_k o),                g_k = C8's element k,
//
// which is the flow-field average v(x) = 1/8 sum_g rho(g)^-1 v(rho(g) x) of the step's
// displacement v = phi - x. Phi(g x, g o) = g Phi(x, o) for every g in C8 (reindex the sum; g acts
// affinely, and an affine map commutes with the mean), whatever the weights. The start x_T is
// the DDPM's noise, turned by the element k*(o) nearest to the hand's current heading (45 deg
// sectors centred on the elements), so that x_T(g o) = g x_T(o) for the same noise: the whole
// sampler is pointwise equivariant, a(g o, n) = g a(o, n) (eq. 4 for g in C8), at any noise
// scale, except on the sector edges (headings 22.5 deg + k 45 deg), a set of measure zero where
// the start jumps: no choice of k* can be continuous on the circle and equivariant. With
// noise_scale 0, the default, the start is the prior mode moved onto C8's fixed points and
// there is no jump at all.
//
// The field is averaged, not the sampled chunks: averaging the 8 chunks g_k^-1 s(g_k o) of a
// multimodal policy (the peg passing left or right of an obstacle) returns a chunk between the
// modes, which no demo has and which the 0.1 cm clearance does not forgive. Averaging each step
// keeps the ODE's modes: the averaged dynamics still carry each start to one mode, and the
// group only moves which start goes where. And the chunks averaged after sampling with a
// different noise per element are not even equivariant pointwise (the noises pair with other
// elements for g o), which the tests plant.
#include <Eigen/Core>
#include <random>
#include <vector>

#include "handcentric/policy/head.hpp"

namespace handcentric::policy::c8 {

/// The elements 0..7 of C8 (all of them: the equivariant average).
const std::vector<int>& all_elements();

/// c8ddpm_avg's (c8flow_avg's) sampler on raw absolute observation columns (in double: they are
/// moved by the group before they are rounded to float32), averaging each DDIM (Euler) step over
/// `elements` (all_elements(): what the head does; fewer elements are not a group and break
/// equivariance, a planted fault for tests). Returns raw absolute chunks, one per column, in
/// double (rounded to float32 they would no longer move exactly with g).
/// Throws InvalidArgument if `head` is not a planar C8 head (c8_planar.hpp), or for an element
/// list that is empty or names an element outside 0..7.
Eigen::MatrixXd averaged_sample(const Head& head, const Eigen::MatrixXd& observations,
                                std::mt19937_64& rng,
                                const std::vector<int>& elements = all_elements());

/// k*(o): the C8 element nearest to the heading theta of the hand now (pose block 0 of a
/// planar observation), round(theta / 45 deg) mod 8.
int heading_sector(const Eigen::VectorXd& planar_observation);

}  // namespace handcentric::policy::c8
