#pragma once
// ALVIO_WIDEST_VECTORS before a function built from plain loops the compiler vectorises: GCC
// then builds it twice, for AVX2 and for the baseline, and the library picks one when it loads
// (function multi-versioning). Only for integer work or float work without reductions: the
// AVX2 copy must give the same bits as the baseline one, and neither fuses multiplies and adds
// (AVX2 does not bring FMA with it).
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define ALVIO_WIDEST_VECTORS __attribute__((target_clones("avx2", "default")))
#else
#define ALVIO_WIDEST_VECTORS
#endif

// Hand-written AVX2 intrinsics go in functions marked ALVIO_AVX2, built where ALVIO_AVX2_CODE
// is 1 and called only when cpuHasAvx2(). Such a function is not inlined into code built for
// the baseline: sums it carries through a loop belong in its locals, not behind pointers.
#if defined(__GNUC__) && defined(__x86_64__)
#define ALVIO_AVX2_CODE 1
#define ALVIO_AVX2 __attribute__((target("avx2")))
#else
#define ALVIO_AVX2_CODE 0
#define ALVIO_AVX2
#endif

namespace alvio {

/// Which of a function's hand-written vector paths to take: the widest the CPU has, or the
/// baseline's (SSE2 on x86-64). Both give the same bits; the choice is for tests and benchmarks.
enum class Vectors { kWidest, kBaseline };

inline bool cpuHasAvx2() {
#if ALVIO_AVX2_CODE
  static const bool has = __builtin_cpu_supports("avx2");
  return has;
#else
  return false;
#endif
}

}  // namespace alvio
