// The kernels compiled once per Highway target: foreach_target.h includes this file again for
// each target of the build (AVX-512 = HWY_AVX3, AVX2, SSE4 and the portable target; the policy
// library's CMakeLists says which), each time inside that target's namespace and with its
// instruction set enabled for the functions there only. Each target contributes one KernelSet;
// HWY_EXPORT gathers them into a table indexed like Highway's run-time dispatch.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "kernels/kernels.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h

#include <hwy/highway.h>

#include "kernels/gemm.hpp"
#include "kernels/kernel_set.hpp"
// The per-target parts, each once per target and only from here (so they need no include
// guards), each after those it uses.
#include "kernels/lanes-inl.h"
#include "kernels/silu-inl.h"
#include "kernels/adam-inl.h"
#include "kernels/gemm-inl.h"
#include "kernels/conv-inl.h"
#include "kernels/box_muller-inl.h"

HWY_BEFORE_NAMESPACE();
namespace handcentric::policy::kernels::HWY_NAMESPACE {

// Box-Muller: the vector transform on the targets with FMA, libm itself on the others
// (box_muller-inl.h).
#if HWY_TARGET == HWY_AVX2 || HWY_TARGET == HWY_AVX3
constexpr auto* kBoxMullerPairs = &BoxMullerPairs;
constexpr auto* kBoxMullerParts = &BoxMullerParts;
#else
inline void LibmBoxMullerPairs(std::ptrdiff_t pairs, const std::uint64_t* bits, float* out,
                               const LibmFloatConstants&) {
  box_muller_pairs_libm(pairs, bits, out);
}
constexpr auto* kBoxMullerPairs = &LibmBoxMullerPairs;
constexpr auto* kBoxMullerParts = &box_muller_parts_libm;
#endif

const KernelSet* TargetKernels() {
  static constexpr KernelSet kSet{vector_gemm<GemmKernel, ShortGemmKernel, HalfGemmKernel>,
                                  vector_offset_gemm<GemmKernel, ShortGemmKernel, HalfGemmKernel>,
                                  PixelConvForward,
                                  PixelConvWeights,
                                  Deinterleave,
                                  SiluForward,
                                  SiluBackward,
                                  SiluInPlace,
                                  SquaredNorm,
                                  Adam,
                                  Col2im,
                                  Row2im,
                                  kBoxMullerPairs,
                                  kBoxMullerParts,
                                  HWY_TARGET};
  return &kSet;
}

}  // namespace handcentric::policy::kernels::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace handcentric::policy::kernels {

HWY_EXPORT(TargetKernels);

std::vector<std::int64_t> available_targets() {
  return hwy::SupportedAndGeneratedTargets();
}

std::string target_name(std::int64_t target) {
  return hwy::TargetName(target);
}

const KernelSet& best_kernels() {
  return *HWY_DYNAMIC_DISPATCH(TargetKernels)();
}

const KernelSet& kernels_of_target(std::int64_t target) {
#if (HWY_TARGETS & (HWY_TARGETS - 1)) == 0  // one target: HWY_EXPORT's table has one entry
  (void)target;
  return *HWY_DYNAMIC_DISPATCH(TargetKernels)();
#else
  // The entry Highway's dispatch would take on a CPU whose best target is `target`: a
  // ChosenTarget of our own, so the process-wide choice is left alone.
  hwy::ChosenTarget only;
  only.Update(target);
  return *HWY_DISPATCH_TABLE(TargetKernels)[only.GetIndex()]();
#endif
}

}  // namespace handcentric::policy::kernels
#endif  // HWY_ONCE
