#pragma once
// AddressSanitizer checks the kernels' plain vector loads and stores (GCC's intrinsics for them
// are ordinary memory accesses), but not masked loads, masked stores and gathers: those are
// builtins it does not see, and they are exactly the tails where a mask one lane too long would
// read or write past a buffer. Under ASan the wrappers in lanes-inl.h check each
// enabled lane here first, so such a mask is reported like any overflow. Without ASan these
// functions are empty and the wrappers compile to the bare intrinsic.
#include <cstddef>
#include <cstdint>

#if defined(__SANITIZE_ADDRESS__) || defined(HANDCENTRIC_ASAN)
#include <sanitizer/asan_interface.h>
#endif

namespace handcentric::policy::kernels {

/// The first poisoned byte among the lanes that `mask` enables (bit i: lane i, `lane_bytes`
/// each, from `base`), or nullptr. Disabled lanes are not looked at: a shifted head mask
/// (gemm-inl.h's narrow products) starts before the buffer on purpose. Always nullptr without ASan.
inline const void* poisoned_lane(const void* base, std::uint64_t mask, std::size_t lane_bytes) {
#if defined(__SANITIZE_ADDRESS__) || defined(HANDCENTRIC_ASAN)
  for (int i = 0; mask != 0; ++i, mask >>= 1) {
    if ((mask & 1u) == 0) continue;
    void* lane = const_cast<char*>(static_cast<const char*>(base) +
                                   static_cast<std::ptrdiff_t>(i) * lane_bytes);
    if (void* bad = __asan_region_is_poisoned(lane, lane_bytes)) return bad;
  }
#else
  (void)base, (void)mask, (void)lane_bytes;
#endif
  return nullptr;
}

/// ASan's report (an abort with halt_on_error) when a lane `mask` enables is poisoned.
inline void check_lanes(const void* base, std::uint64_t mask, std::size_t lane_bytes,
                        bool is_write) {
#if defined(__SANITIZE_ADDRESS__) || defined(HANDCENTRIC_ASAN)
  if (const void* bad = poisoned_lane(base, mask, lane_bytes)) {
    __asan_report_error(__builtin_return_address(0), __builtin_frame_address(0),
                        __builtin_frame_address(0), const_cast<void*>(bad), is_write ? 1 : 0,
                        lane_bytes);
  }
#else
  (void)base, (void)mask, (void)lane_bytes, (void)is_write;
#endif
}

}  // namespace handcentric::policy::kernels
