#pragma once
// Four-lane helpers are always inlined into the kernel that calls them. The kernels are built
// three times, for the x86-64 baseline, AVX2 and AVX-512 ([[gnu::target]], picked at run time:
// lane_isa.hpp); a 32-byte vector argument or result travels in a ymm register in the AVX
// builds and in memory on the baseline (the x86-64 psABI; GCC's -Wpsabi note). A helper left
// out of line is compiled for the baseline, so a call to it from an AVX kernel would hand it
// a vector where it does not look: wrong forces, with no error. Whether GCC inlines a helper
// it is free not to inline depends on the size of the whole translation unit, so every
// function and lambda that takes or returns a four-lane vector carries one of these.
// tests/geometry/check_lane_abi.py fails when a built library holds such a function out of line.
#define FLOEDEM_LANES [[gnu::always_inline]] inline
/// After a lambda's parameter list: `[&](v4d x) FLOEDEM_LANES_LAMBDA { ... }`.
#define FLOEDEM_LANES_LAMBDA __attribute__((always_inline))
