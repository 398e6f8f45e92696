#pragma once
// Growth of the step's work lists without an allocation per step.
#include <cstddef>
#include <vector>

namespace floedem {

/// Makes room for n elements, and half as many again, when v cannot hold n. vector::assign
/// allocates exactly what it is asked for: a list that grows by a few elements a step (the
/// pairs of a compacting field, the islands of a growing pile) would allocate at every step
/// that sets a new largest size.
template <class T, class A>
void reserve_with_headroom(std::vector<T, A>& v, std::size_t n) {
  if (v.capacity() < n) v.reserve(n + n / 2);
}

/// Resizes v to n, with room for half as many again when it grows past what it holds.
/// vector::resize past the capacity allocates size + max(size, n - size): after a list has
/// shrunk (fewer contacts this step), that is barely more than n, so a size that goes down and
/// up around its largest would allocate each time it sets a new largest.
template <class T, class A>
void resize_with_headroom(std::vector<T, A>& v, std::size_t n) {
  reserve_with_headroom(v, n);
  v.resize(n);
}

}  // namespace floedem
