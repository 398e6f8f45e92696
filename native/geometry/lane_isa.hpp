#pragma once
// The instruction sets floedem's SIMD loops are built for, one of them picked at run time for
// all: the coloured sweeps (solver/coloured_sweeps.cpp), the narrow phase's separating-axis
// search (collision/narrow_phase.cpp) and the drag's four-floe lanes (forcing/drag.cpp). Each
// build takes the same IEEE operations in the same order (no fused multiply-add:
// -ffp-contract=off), so results are the same to the bit whichever runs (tested per loop).
#include <vector>

namespace floedem {

/// The x86-64 baseline (SSE2), AVX2, and AVX2 with AVX-512's 32 registers (for the same
/// 4-lane vectors: fewer spills).
enum class LaneIsa { baseline, avx2, avx512 };

/// The builds this processor runs, slowest first (only the baseline off x86-64).
std::vector<LaneIsa> available_lane_isas();
/// The build every SIMD loop uses: the fastest available unless a test or benchmark set another.
LaneIsa lane_isa();
/// Sets it; throws std::invalid_argument for one this processor does not run.
void use_lane_isa(LaneIsa isa);
/// Back to the fastest.
void use_fastest_lane_isa();

}  // namespace floedem
