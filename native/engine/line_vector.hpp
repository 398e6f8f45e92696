#pragma once
// std::vector whose storage starts on a 64-byte cache line, and whose large lists sit on 2 MiB
// pages where the kernel has them.
//
// Cache line: malloc gives 16-byte alignment (a large block: a page plus its 16-byte header),
// so a record of a whole number of lines (a 384-byte manifold, a box floe's four 16-byte
// vertices) straddled one line more than it fills: every pass over it read, and every prefetch
// of it had to ask for, an extra line.
//
// Huge pages: the coloured sweeps stream the packed field's bundles (768 bytes a bundle, about
// 31 MB at 10^5 floes) ten times a step and more, and read and write the bodies between them.
// On 4 KiB pages that is some 7 600 pages a sweep, more than a second-level TLB holds (2 048 to
// 4 096 entries on recent x86-64), so the page walks come back every sweep; on 2 MiB pages, 16.
// A list of 2 MiB or more is therefore placed on 2 MiB boundaries and marked for transparent
// huge pages (madvise(MADV_HUGEPAGE)): Linux's default policy, "madvise", backs only marked
// memory with huge pages. Where the policy is "never" or the call fails, the memory stays on
// small pages; where it is "always", the mark changes nothing.
//
// An allocation's address and page size change no value, so the results are the same to the bit.
#include <cstddef>
#include <new>
#include <vector>

#include "engine/cache_line.hpp"

namespace floedem {

/// The huge page of x86-64 and of 4 KiB-granule arm64 Linux.
inline constexpr std::size_t kHugePage = std::size_t{2} << 20;

/// Asks the kernel to back [p, p + bytes) with huge pages; a hint only (line_vector.cpp).
void advise_huge_pages(void* p, std::size_t bytes) noexcept;

template <class T>
struct LineAllocator {
  using value_type = T;
  LineAllocator() = default;
  template <class U>
  constexpr LineAllocator(const LineAllocator<U>&) noexcept {}
  /// One rule for both ends: a list of n elements is made, and freed, with this alignment.
  static constexpr std::size_t alignment(std::size_t n) noexcept {
    return n * sizeof(T) < kHugePage ? kCacheLine : kHugePage;
  }
  T* allocate(std::size_t n) {
    const std::size_t bytes = n * sizeof(T);
    if (alignment(n) == kCacheLine) return static_cast<T*>(::operator new(bytes, std::align_val_t{kCacheLine}));
    // Whole pages, so that no other allocation shares the last one.
    const std::size_t whole = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    void* p = ::operator new(whole, std::align_val_t{kHugePage});
    advise_huge_pages(p, whole);
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t n) noexcept { ::operator delete(p, std::align_val_t{alignment(n)}); }
  template <class U>
  bool operator==(const LineAllocator<U>&) const noexcept {
    return true;
  }
};

template <class T>
using LineVector = std::vector<T, LineAllocator<T>>;

}  // namespace floedem
