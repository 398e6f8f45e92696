#pragma once
// Heap allocations made by this process so far: the floedem executable replaces the global
// operator new with one that counts (allocation_count.cpp, one relaxed atomic increment per
// call), so that `floedem bench` can show that a step allocates nothing in the steady state.
#include <cstdint>

namespace floedem {

std::uint64_t allocations_so_far();

}  // namespace floedem
