#pragma once
// Which float32 kernels the policy networks run on. Mlp<float> multiplies its matrices with
// kernels written once on Google Highway and compiled for several instruction sets; the one for
// the CPU it runs on is chosen at run time, so one portable build (no -march) trains at AVX-512
// speed where the CPU has AVX-512:
//
//   generic  the best below AVX2: SSE4 on most x86 CPUs, else the portable code; every CPU
//   avx2     AVX2 + FMA (Haswell and later, Zen)
//   avx512   AVX-512 F, BW, DQ, VL (Skylake-SP and later, Zen 4)
//
// The default is the best the CPU supports; the environment variable HANDCENTRIC_KERNELS
// (generic | avx2 | avx512) or set_kernel_isa() picks another. Results are bit-for-bit
// deterministic for one kernel set on one thread; different kernel sets sum in different
// orders, so their results differ in the last bits (tests/policy/test_kernels.cpp bounds it).
#include <string>

namespace handcentric::policy {

enum class KernelIsa { generic, avx2, avx512 };

/// "generic", "avx2", "avx512".
std::string to_string(KernelIsa isa);
/// Throws InvalidArgument naming the value and the valid names.
KernelIsa parse_kernel_isa(const std::string& name);

/// Whether this CPU (and this build) can run `isa`.
bool kernel_isa_supported(KernelIsa isa);
/// The best supported set.
KernelIsa best_kernel_isa();
/// The set in use: HANDCENTRIC_KERNELS when set (read once, at first use), else best_kernel_isa().
/// An unknown or unsupported HANDCENTRIC_KERNELS throws InvalidArgument at first use.
KernelIsa kernel_isa();
/// Use `isa` from now on, for the whole process. Throws InvalidArgument when the CPU lacks it.
/// Switch between computations, not during one: a training step or a sample that is running on
/// another thread may see both sets.
void set_kernel_isa(KernelIsa isa);

}  // namespace handcentric::policy
