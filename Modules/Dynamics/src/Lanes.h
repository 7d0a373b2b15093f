#pragma once
// Four doubles in one value for the Dynamics module's hand-vectorized
// kernels (PairedProduct.cpp), private to it.
//
// Each kernel is inlined into two entry points: one compiled for AVX2 and
// FMA, chosen at run time where the processor has them (hasAvx2Fma()), and
// one for the baseline x86-64 (SSE2), where a Lanes value is two registers.
// The AVX2 one is about twice as fast; the two round differently (fused
// multiply-adds), and each gives the same results from run to run.
#include <cstring>

namespace dynsub {

#define DYNSUB_KERNEL inline __attribute__((always_inline))
#define DYNSUB_AVX2 __attribute__((target("avx2,fma")))

typedef double Lanes __attribute__((vector_size(32)));
constexpr int kLanes = 4;

// By reference, not by value: a 32-byte vector passed by value has a
// different ABI with and without AVX (GCC warns), though these are always inlined.
// Unaligned: a std::vector of doubles is aligned to 16 bytes only.
DYNSUB_KERNEL void load(Lanes& v, const double* p) { std::memcpy(&v, p, sizeof v); }
DYNSUB_KERNEL void store(double* p, const Lanes& v) { std::memcpy(p, &v, sizeof v); }

// The lanes' sum in a fixed order: kernels that sum lane by lane and add the
// lanes at the end vectorize without -ffast-math and still sum in one order.
DYNSUB_KERNEL double sum(const Lanes& v) { return (v[0] + v[1]) + (v[2] + v[3]); }

inline bool hasAvx2Fma() {
  static const bool has = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return has;
}

}  // namespace dynsub
