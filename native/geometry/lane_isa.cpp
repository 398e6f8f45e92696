#include "geometry/lane_isa.hpp"

#include <algorithm>
#include <atomic>
#include <stdexcept>

namespace floedem {

std::vector<LaneIsa> available_lane_isas() {
  std::vector<LaneIsa> isas{LaneIsa::baseline};
#if defined(__x86_64__)
  __builtin_cpu_init();  // called from a static initialiser too
  if (__builtin_cpu_supports("avx2")) isas.push_back(LaneIsa::avx2);
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl"))
    isas.push_back(LaneIsa::avx512);
#endif
  return isas;
}

namespace {
std::atomic<LaneIsa>& chosen() {
  static std::atomic<LaneIsa> isa{available_lane_isas().back()};
  return isa;
}
}  // namespace

LaneIsa lane_isa() { return chosen().load(std::memory_order_relaxed); }

void use_lane_isa(LaneIsa isa) {
  const std::vector<LaneIsa> isas = available_lane_isas();
  if (std::find(isas.begin(), isas.end(), isa) == isas.end())
    throw std::invalid_argument("use_lane_isa: this processor does not run that build of the SIMD loops");
  chosen().store(isa);
}

void use_fastest_lane_isa() { chosen().store(available_lane_isas().back()); }

}  // namespace floedem
