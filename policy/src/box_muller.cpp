// The scalar reference with libm's logf, cosf and sinf, and the choice between it and the
// active kernel set's vector transform (box_muller.hpp). A training step of the flow policy
// draws 24 x 256 normals against 225 MFLOP of products; in scalar libm that was ~9% of the
// paper preset's CPU time (docs/BENCHMARKS.md, section "Policy").
#include "box_muller.hpp"

#include <array>
#include <cmath>
#include <cstring>
#include <numbers>
#include <random>
#include <vector>

#include "handcentric/policy/kernels.hpp"
#include "kernels/kernel_set.hpp"

namespace handcentric::policy {

namespace {

float u1_of(std::uint64_t bits) {
  return static_cast<float>(BoxMuller::high24(bits) + 1) * BoxMuller::kTwoPow24Inverse;
}

float angle_of(std::uint64_t bits) {
  const float u2 = static_cast<float>(BoxMuller::low24(bits)) * BoxMuller::kTwoPow24Inverse;
  return 2.0f * std::numbers::pi_v<float> * u2;
}

}  // namespace

void box_muller_pairs_libm(std::ptrdiff_t pairs, const std::uint64_t* bits, float* out) {
  for (std::ptrdiff_t i = 0; i < pairs; ++i) {
    const float radius = std::sqrt(-2.0f * std::log(u1_of(bits[i])));
    const float angle = angle_of(bits[i]);
    out[2 * i] = radius * std::cos(angle);
    out[2 * i + 1] = radius * std::sin(angle);
  }
}

void box_muller_parts_libm(std::ptrdiff_t pairs, const std::uint64_t* bits, float* radius,
                           float* cosine, float* sine, const LibmFloatConstants& /*constants*/) {
  for (std::ptrdiff_t i = 0; i < pairs; ++i) {
    radius[i] = std::sqrt(-2.0f * std::log(u1_of(bits[i])));
    cosine[i] = std::cos(angle_of(bits[i]));
    sine[i] = std::sin(angle_of(bits[i]));
  }
}

bool box_muller_kernel_agrees_with_libm(const kernels::KernelSet& set,
                                        const LibmFloatConstants& constants) {
  // 2^14 seeded draws (every logf table entry, binade and quadrant many times over; half a
  // millisecond of libm once per kernel set) and the edges: u1 = 2^-e for each binade, u2 at 0,
  // around the small-angle bound 2^-12 (lo 651..653) and at each quarter turn.
  std::vector<std::uint64_t> probes;
  std::mt19937_64 rng(2036);
  for (int i = 0; i < (1 << 14); ++i) probes.push_back(rng());
  for (std::uint64_t e = 0; e <= 24; ++e) probes.push_back(((std::uint64_t{1} << e) - 1) << 40);
  for (std::uint64_t lo : {0ull, 1ull, 651ull, 652ull, 653ull, 0x200000ull, 0x400000ull,
                           0x400001ull, 0x800000ull, 0xC00000ull, 0xFFFFFFull})
    probes.push_back((std::uint64_t{0x9E3779} << 40) | (lo << 8));
  const auto n = static_cast<std::ptrdiff_t>(probes.size());
  std::vector<float> vector_parts(3 * probes.size()), libm_parts(3 * probes.size());
  set.box_muller_parts(n, probes.data(), vector_parts.data(), vector_parts.data() + n,
                       vector_parts.data() + 2 * n, constants);
  box_muller_parts_libm(n, probes.data(), libm_parts.data(), libm_parts.data() + n,
                        libm_parts.data() + 2 * n, constants);
  return std::memcmp(vector_parts.data(), libm_parts.data(), vector_parts.size() * sizeof(float)) ==
         0;
}

void box_muller_pairs(std::ptrdiff_t pairs, const std::uint64_t* bits, float* out) {
  // Probed once per kernel set: a libm other than the one transcribed (another glibc, another
  // C library) keeps the scalar path, so the bits never silently differ from libm's.
  static const std::array<bool, 3> agrees = [] {
    std::array<bool, 3> each{};
    for (KernelIsa isa : {KernelIsa::generic, KernelIsa::avx2, KernelIsa::avx512}) {
      if (kernel_isa_supported(isa)) {
        each[static_cast<std::size_t>(isa)] =
            box_muller_kernel_agrees_with_libm(kernels::kernels_for(isa), kGlibcFloatConstants);
      }
    }
    return each;
  }();
  const KernelIsa isa = kernel_isa();
  if (agrees[static_cast<std::size_t>(isa)]) {
    kernels::kernels_for(isa).box_muller(pairs, bits, out, kGlibcFloatConstants);
  } else {
    box_muller_pairs_libm(pairs, bits, out);
  }
}

}  // namespace handcentric::policy
