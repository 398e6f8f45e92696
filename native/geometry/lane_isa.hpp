#pragma once
// The instruction sets a SIMD loop of floedem (geometry/lanes4.hpp) is built for, picked at
// run time: the coloured sweeps and the drag's four-floe lanes.
#include <vector>

namespace floedem {

/// The builds of such a loop: the x86-64 baseline (SSE2), AVX2, and AVX2 with AVX-512's 32
/// registers (for the same 4-lane vectors: fewer spills). The same results to the bit in each.
enum class LaneIsa { baseline, avx2, avx512 };

/// The builds this processor runs, slowest first (only the baseline off x86-64).
inline std::vector<LaneIsa> available_lane_isas() {
  std::vector<LaneIsa> isas{LaneIsa::baseline};
#if defined(__x86_64__)
  __builtin_cpu_init();  // may be called from a static initialiser
  if (__builtin_cpu_supports("avx2")) isas.push_back(LaneIsa::avx2);
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl"))
    isas.push_back(LaneIsa::avx512);
#endif
  return isas;
}

}  // namespace floedem
