// Private, per target: the named lane masks and tail accesses every kernel uses. A vector may
// cover lanes that lie outside a buffer (a tail of n mod Lanes values; a head that starts before
// a column to keep loads inside cache lines); those lanes are masked, and a masked lane is
// neither read nor written. The masked accesses are instructions AddressSanitizer does not see,
// so under ASan each one first checks its enabled lanes (asan_lanes.hpp).

#include <cstddef>
#include <cstdint>

#include <hwy/highway.h>

#include "kernels/asan_lanes.hpp"

HWY_BEFORE_NAMESPACE();
namespace handcentric::policy::kernels::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

/// Whether masked loads are instructions on this target (cheap enough for every k of a product).
constexpr bool kMaskedLoadInstructions =
    HWY_TARGET == HWY_AVX2 || HWY_TARGET == HWY_AVX3 || HWY_TARGET == HWY_AVX3_DL;

/// Lanes [begin, end) of one vector of D: the mask, and the same lanes as bits for the ASan check.
template <class D>
struct LaneSpan {
  hn::Mask<D> mask;
  std::uint64_t bits;
};

/// The lanes [begin, end) of a vector, 0 <= begin <= end <= Lanes(d) (begin > 0: a head that
/// starts before the data; end < Lanes(d): a tail).
template <class D>
HWY_INLINE LaneSpan<D> LanesBetween(D d, std::size_t begin, std::size_t end) {
  const std::uint64_t below_end = end >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << end) - 1;
  return {hn::AndNot(hn::FirstN(d, begin), hn::FirstN(d, end)),
          below_end & ~((std::uint64_t{1} << begin) - 1)};
}

/// The first `count` lanes (a tail); count >= Lanes(d) gives every lane.
template <class D>
HWY_INLINE LaneSpan<D> FirstLanes(D d, std::size_t count) {
  return LanesBetween(d, 0, count < hn::Lanes(d) ? count : hn::Lanes(d));
}

/// p[i] for the lanes of `lanes`, 0 elsewhere; nothing outside them is read. Highway's
/// MaskedLoad is a masked instruction on AVX2 and AVX-512 only: on the other targets it loads the
/// whole vector and then clears lanes, so there a partial vector is copied through a buffer.
template <class D, typename T = hn::TFromD<D>>
HWY_INLINE hn::Vec<D> LoadLanes(D d, const LaneSpan<D>& lanes, const T* p) {
  check_lanes(p, lanes.bits, sizeof(T), false);
// The condition of kMaskedLoadInstructions.
#if HWY_TARGET == HWY_AVX2 || HWY_TARGET == HWY_AVX3 || HWY_TARGET == HWY_AVX3_DL
  return hn::MaskedLoad(lanes.mask, d, p);
#else
  constexpr std::size_t kLanes = hn::MaxLanes(D());
  if (lanes.bits == (kLanes >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << kLanes) - 1))
    return hn::LoadU(d, p);
  alignas(64) T buffer[kLanes] = {};
  for (std::size_t i = 0; i < kLanes; ++i) {
    if ((lanes.bits >> i) & 1) buffer[i] = p[i];
  }
  return hn::Load(d, buffer);
#endif
}

/// p[i] = v[i] for the lanes of `lanes`; nothing outside them is written.
template <class D, typename T = hn::TFromD<D>>
HWY_INLINE void StoreLanes(D d, const LaneSpan<D>& lanes, hn::Vec<D> v, T* p) {
  check_lanes(p, lanes.bits, sizeof(T), true);
  hn::BlendedStore(v, lanes.mask, d, p);
}

/// The first `count` values at p (a whole vector when count is Lanes(d)), zero past them.
template <class D, typename T = hn::TFromD<D>>
HWY_INLINE hn::Vec<D> LoadPart(D d, const T* p, std::size_t count) {
  return count == hn::Lanes(d) ? hn::LoadU(d, p) : LoadLanes(d, FirstLanes(d, count), p);
}

/// Stores the first `count` lanes of v at p (the whole vector when count is Lanes(d)).
template <class D, typename T = hn::TFromD<D>>
HWY_INLINE void StorePart(D d, hn::Vec<D> v, T* p, std::size_t count) {
  if (count == hn::Lanes(d)) {
    hn::StoreU(v, d, p);
  } else {
    StoreLanes(d, FirstLanes(d, count), v, p);
  }
}

/// body(i, count) over [0, n) a vector at a time: count = Lanes(d), then the tail (n mod Lanes).
template <class D, class Body>
HWY_INLINE void ForEachVector(D d, std::ptrdiff_t n, Body&& body) {
  constexpr std::ptrdiff_t kLanes = static_cast<std::ptrdiff_t>(hn::MaxLanes(D()));
  std::ptrdiff_t i = 0;
  for (; i + kLanes <= n; i += kLanes) body(i, static_cast<std::size_t>(kLanes));
  if (i < n) body(i, static_cast<std::size_t>(n - i));
  (void)d;
}

/// Lane i = rows[i * ld] for i < count, 0 for the lanes past them: a column of `count` rows of a
/// row-major block (stride ld). The lanes past `count` gather the first row again (always
/// inside the block) and are then cleared, so no address outside the rows is read.
template <class D>
HWY_INLINE hn::Vec<D> GatherRows(D d, const float* rows, hn::Vec<hn::RebindToSigned<D>> row_offsets,
                                 const LaneSpan<D>& lanes) {
  const hn::RebindToSigned<D> di;
  const auto offsets = hn::IfThenElseZero(hn::RebindMask(di, lanes.mask), row_offsets);
#if defined(__SANITIZE_ADDRESS__) || defined(HANDCENTRIC_ASAN)
  alignas(64) std::int32_t each[hn::MaxLanes(D())];
  hn::Store(offsets, di, each);
  for (std::size_t i = 0; i < hn::Lanes(d); ++i)
    check_lanes(rows + each[i], 1, sizeof(float), false);
#endif
  return hn::IfThenElseZero(lanes.mask, hn::GatherIndex(d, rows, offsets));
}

}  // namespace handcentric::policy::kernels::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();
