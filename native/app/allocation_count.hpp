#pragma once
// Heap allocations made by this process so far: the floedem executable replaces malloc and its
// kin, and the global operator new, with ones that count (allocation_count.cpp, one relaxed
// atomic increment per call), so that `floedem bench` can show that a step allocates nothing in
// the steady state. Under a sanitizer only operator new is counted.
#include <cstdint>

namespace floedem {

std::uint64_t allocations_so_far();

}  // namespace floedem
