#pragma once
// Software prefetch of a record's cache lines, for the passes whose loads perf showed waiting on
// memory (the records come back from memory each step at 16k floes and more). A prefetch only
// warms the cache: no value computed changes.
#include <cstddef>
#include <cstdint>

#include "engine/cache_line.hpp"

namespace floedem {

/// Asks for every cache line of the `bytes` bytes from `at`. `at` may lie past the end of the
/// caller's array (a prefetch of an address never faults): it is taken as an address, not
/// dereferenced. Always inline: called from loops built for several ISAs (gnu::target).
[[gnu::always_inline]] inline void prefetch_lines(const void* at, std::size_t bytes) {
  const auto first = reinterpret_cast<std::uintptr_t>(at);
  for (std::size_t line = 0; line < bytes; line += kCacheLine) __builtin_prefetch(reinterpret_cast<const void*>(first + line));
}

/// prefetch_lines for record `index` of the array at `first` (`bytes` from its start: one record
/// unless told), `index` taken as an offset, not a subscript: it may name a record past the
/// array's end (a loop asking a few records ahead, near its last), which is never formed as a
/// pointer.
template <class Record>
[[gnu::always_inline]] inline void prefetch_record(const Record* first, std::size_t index,
                                                   std::size_t bytes = sizeof(Record)) {
  prefetch_lines(reinterpret_cast<const void*>(reinterpret_cast<std::uintptr_t>(first) + index * sizeof(Record)), bytes);
}

}  // namespace floedem
