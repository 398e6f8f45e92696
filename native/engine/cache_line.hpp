#pragma once
// The cache line of the x86-64 processors floedem is measured on (AMD Zen, Intel): the unit a
// prefetch asks for (prefetch.hpp), the alignment of the lists whose records are whole lines
// (line_vector.hpp) and of the coloured sweeps' bundles.
#include <cstddef>

namespace floedem {

inline constexpr std::size_t kCacheLine = 64;

}  // namespace floedem
