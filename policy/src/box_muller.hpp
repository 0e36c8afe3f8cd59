#pragma once
// Private: the transform behind fill_standard_normal (gaussian.hpp), one 64-bit draw per pair of
// standard normals. With the top 24 bits of each 32-bit half, u1 = (hi + 1) 2^-24 in (0, 1] and
// u2 = lo 2^-24 in [0, 1), both exact in float; r = sqrt(-2 ln u1) (at most sqrt(48 ln 2) =
// 5.77: the tails beyond 5.77 sigma, probability 8e-9, are cut), and the pair is
// (r cos 2 pi u2, r sin 2 pi u2), in float with libm's logf, cosf and sinf.
//
// Every trained model depends on these bits, so the vector kernels (kernels/box_muller-inl.h)
// transcribe glibc's logf, sinf and cosf (its FMA variants, which glibc picks on a CPU with FMA
// and AVX2, the CPUs of those kernels) and are used only while they give libm's bits on probe
// inputs (box_muller_kernel_agrees_with_libm); u1 and u2 take 2^24 values each, so a test
// compares them with libm on all of them (tests/policy/test_gaussian.cpp).
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

/// The constants of glibc 2.36's logf (sysdeps/ieee754/flt-32/e_logf_data.c) and sinf / cosf
/// (s_sincosf_data.c, the x86-64 build: no TOINT_INTRINSICS, so 2 / pi is scaled by 2^24), all
/// from ARM's optimized-routines. A parameter of the kernels rather than a constant inside them,
/// so a test can plant a fault (one coefficient off in its last bit) and see the checks catch it.
struct LibmFloatConstants {
  // logf: x = 2^k z, log x = log1p(z / c - 1) + log c + k ln 2, c from a 16-entry table.
  double log_invc[16], log_logc[16];
  double log_ln2;
  double log_poly[3];
  // sinf / cosf: n = round(x 2 / pi), r = x - n pi / 2, then sin r = r + r^3 (s1 + r^2 s2 ...),
  // cos r = c0 + r^2 c1 + ...
  double sincos_hpi_inv, sincos_hpi;
  double cos_poly[5], sin_poly[3];
};

inline constexpr LibmFloatConstants kGlibcFloatConstants{
    {0x1.661ec79f8f3bep+0, 0x1.571ed4aaf883dp+0, 0x1.49539f0f010bp+0, 0x1.3c995b0b80385p+0,
     0x1.30d190c8864a5p+0, 0x1.25e227b0b8eap+0, 0x1.1bb4a4a1a343fp+0, 0x1.12358f08ae5bap+0,
     0x1.0953f419900a7p+0, 0x1p+0, 0x1.e608cfd9a47acp-1, 0x1.ca4b31f026aap-1, 0x1.b2036576afce6p-1,
     0x1.9c2d163a1aa2dp-1, 0x1.886e6037841edp-1, 0x1.767dcf5534862p-1},
    {-0x1.57bf7808caadep-2, -0x1.2bef0a7c06ddbp-2, -0x1.01eae7f513a67p-2, -0x1.b31d8a68224e9p-3,
     -0x1.6574f0ac07758p-3, -0x1.1aa2bc79c81p-3, -0x1.a4e76ce8c0e5ep-4, -0x1.1973c5a611cccp-4,
     -0x1.252f438e10c1ep-5, 0x0p+0, 0x1.aa5aa5df25984p-5, 0x1.c5e53aa362eb4p-4,
     0x1.526e57720db08p-3, 0x1.bc2860d22477p-3, 0x1.1058bc8a07ee1p-2, 0x1.4043057b6ee09p-2},
    0x1.62e42fefa39efp-1,
    {-0x1.00ea348b88334p-2, 0x1.5575b0be00b6ap-2, -0x1.ffffef20a4123p-2},
    0x1.45F306DC9C883p+23,
    0x1.921FB54442D18p0,
    {0x1p0, -0x1.ffffffd0c621cp-2, 0x1.55553e1068f19p-5, -0x1.6c087e89a359dp-10,
     0x1.99343027bf8c3p-16},
    {-0x1.555545995a603p-3, 0x1.1107605230bc4p-7, -0x1.994eb3774cf24p-13}};

/// out[2 i], out[2 i + 1] = the pair of bits[i], i < pairs: the active kernel set's vector
/// transform when it agrees with libm on the probes, else box_muller_pairs_libm.
void box_muller_pairs(std::ptrdiff_t pairs, const std::uint64_t* bits, float* out);

/// The same in scalar float with libm (the reference every trained bit comes from).
void box_muller_pairs_libm(std::ptrdiff_t pairs, const std::uint64_t* bits, float* out);

/// The parts of each pair with libm: radius[i] = sqrtf(-2 logf(u1)), cosine[i] = cosf(2 pi u2),
/// sine[i] = sinf(2 pi u2) (the scalar targets' KernelSet::box_muller_parts). `constants` is
/// ignored: libm has its own.
void box_muller_parts_libm(std::ptrdiff_t pairs, const std::uint64_t* bits, float* radius,
                           float* cosine, float* sine, const LibmFloatConstants& constants);

namespace kernels {
struct KernelSet;
}

/// Whether `set`'s Box-Muller parts with `constants` equal libm's bit for bit on 2^14 seeded
/// probe inputs (every logf table entry and binade of u1, every quadrant and the small-angle
/// cases of u2): false on a libm other than the one the kernels transcribe.
bool box_muller_kernel_agrees_with_libm(const kernels::KernelSet& set,
                                        const LibmFloatConstants& constants);

}  // namespace handcentric::policy
