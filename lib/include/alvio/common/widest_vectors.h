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
