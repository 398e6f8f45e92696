#pragma once
// Four doubles in one vector (GCC and Clang vector extensions): two SSE2 registers on the
// x86-64 baseline, one AVX register where a function is built for AVX2 or AVX-512. The SIMD
// loops of the coloured sweeps (solver/coloured_sweeps.cpp) and of drag (forcing/drag.cpp)
// compute with these, lane by lane, each lane the scalar rule's IEEE operations in its order
// (-ffp-contract=off), so a lane holds the scalar result to the bit. Masks are 64-bit lanes
// of all ones (true) or zeros, as a comparison of two v4d gives them.
#include <cstdint>
#include <cstring>
#include <limits>
#if defined(__SSE2__)
#include <emmintrin.h>
#else
#include <cmath>
#endif

#include "geometry/lane_inline.hpp"

namespace floedem::lanes4 {

using v4d = double __attribute__((vector_size(32)));
using v4m = std::int64_t __attribute__((vector_size(32)));

FLOEDEM_LANES v4d load(const double* p) {
  v4d v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
FLOEDEM_LANES void store(double* p, v4d v) { std::memcpy(p, &v, sizeof v); }
FLOEDEM_LANES v4d splat(double x) { return v4d{} + x; }
// Four lanes from four places, as two pairs joined: built as v4d{a, b, c, d}, GCC 12 loads
// each lane into the register that held the previous vector (vmovlpd merges), a false
// dependence that chains each vector to the one before it. (Four scalar stores read back as
// one vector instead wait for all four: the store cannot be forwarded.)
using v2d = double __attribute__((vector_size(16)));
FLOEDEM_LANES v4d lanes(double a, double b, double c, double d) {
  const v2d low{a, b}, high{c, d};
  return __builtin_shufflevector(low, high, 0, 1, 2, 3);
}
// Per lane: a where the mask holds, else b.
FLOEDEM_LANES v4d select(v4m m, v4d a, v4d b) { return (v4d)((m & (v4m)a) | (~m & (v4m)b)); }
FLOEDEM_LANES v4d abs(v4d x) {
  constexpr std::int64_t magnitude = std::numeric_limits<std::int64_t>::max();
  return (v4d)((v4m)x & magnitude);
}
// std::max(a, b) per lane: (a < b) ? b : a.
FLOEDEM_LANES v4d max(v4d a, v4d b) { return select((v4m)(a < b), b, a); }
// Correctly rounded per lane, as std::sqrt: two SSE2 square roots, split and joined in
// registers (through memory, the 32-byte load of two 16-byte stores waits for both).
FLOEDEM_LANES v4d sqrt4(v4d x) {
#if defined(__SSE2__)
  const v2d lo = _mm_sqrt_pd(__builtin_shufflevector(x, x, 0, 1)), hi = _mm_sqrt_pd(__builtin_shufflevector(x, x, 2, 3));
  return __builtin_shufflevector(lo, hi, 0, 1, 2, 3);
#else
  return v4d{std::sqrt(x[0]), std::sqrt(x[1]), std::sqrt(x[2]), std::sqrt(x[3])};
#endif
}

// The operations solver/local_law.hpp asks of a lane type (its ScalarOps on four lanes).
struct Ops {
  using value = v4d;
  using mask = v4m;
  static constexpr bool lanes = true;
  FLOEDEM_LANES static v4d select(v4m m, v4d a, v4d b) { return lanes4::select(m, a, b); }
  FLOEDEM_LANES static v4m both(v4m a, v4m b) { return a & b; }
  FLOEDEM_LANES static v4d absolute(v4d x) { return lanes4::abs(x); }
  FLOEDEM_LANES static v4d splat(double x) { return lanes4::splat(x); }
  FLOEDEM_LANES static v4m less(v4d a, v4d b) { return (v4m)(a < b); }
  FLOEDEM_LANES static v4m less_equal(v4d a, v4d b) { return (v4m)(a <= b); }
};

}  // namespace floedem::lanes4
