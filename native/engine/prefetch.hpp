#pragma once
// Software prefetch of a record's cache lines, for the passes whose loads perf showed waiting on
// memory (the records come back from memory each step at 16k floes and more). A prefetch only
// warms the cache: no value computed changes.
#include <cstddef>
#include <cstdint>

namespace floedem {

/// Asks for every 64-byte line of the `bytes` bytes from `at`. `at` may lie past the end of the
/// caller's array (a prefetch of an address never faults): it is taken as an address, not
/// dereferenced. Always inline: called from loops built for several ISAs (gnu::target).
[[gnu::always_inline]] inline void prefetch_lines(const void* at, std::size_t bytes) {
  const auto first = reinterpret_cast<std::uintptr_t>(at);
  for (std::size_t line = 0; line < bytes; line += 64) __builtin_prefetch(reinterpret_cast<const void*>(first + line));
}

}  // namespace floedem
