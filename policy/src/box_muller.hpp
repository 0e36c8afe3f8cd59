#pragma once
// Private: the transform behind fill_standard_normal (gaussian.hpp), one 64-bit draw per pair of
// standard normals. With the top 24 bits of each 32-bit half, u1 = (hi + 1) 2^-24 in (0, 1] and
// u2 = lo 2^-24 in [0, 1), both exact in float; r = sqrt(-2 ln u1) (at most sqrt(48 ln 2) =
// 5.77: the tails beyond 5.77 sigma, probability 8e-9, are cut), and the pair is
// (r cos 2 pi u2, r sin 2 pi u2).
#include <cstddef>
#include <cstdint>

namespace handcentric::policy {

struct BoxMuller {
  static std::uint32_t high24(std::uint64_t bits) { return static_cast<std::uint32_t>(bits >> 40); }
  static std::uint32_t low24(std::uint64_t bits) {
    return static_cast<std::uint32_t>(bits >> 8) & 0xFFFFFFu;
  }
  static constexpr float kTwoPow24Inverse = 0x1.0p-24f;
};

/// out[2 i], out[2 i + 1] = the pair of bits[i], i < pairs.
void box_muller_pairs(std::ptrdiff_t pairs, const std::uint64_t* bits, float* out);

}  // namespace handcentric::policy
