#pragma once
// std::vector whose storage starts on a 64-byte cache line. malloc gives 16-byte alignment (a
// large block: a page plus its 16-byte header), so a record of a whole number of lines (a
// 384-byte manifold, a box floe's four 16-byte vertices) straddled one line more than it fills:
// every pass over it read, and every prefetch of it had to ask for, an extra line. An
// allocation's address changes no value, so the results are the same to the bit.
#include <cstddef>
#include <new>
#include <vector>

#include "engine/cache_line.hpp"

namespace floedem {

template <class T>
struct LineAllocator {
  using value_type = T;
  LineAllocator() = default;
  template <class U>
  constexpr LineAllocator(const LineAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) {
    return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t{kCacheLine}));
  }
  void deallocate(T* p, std::size_t) noexcept { ::operator delete(p, std::align_val_t{kCacheLine}); }
  template <class U>
  bool operator==(const LineAllocator<U>&) const noexcept {
    return true;
  }
};

template <class T>
using LineVector = std::vector<T, LineAllocator<T>>;

}  // namespace floedem
