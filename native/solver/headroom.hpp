#pragma once
// Growth of the step's work lists without an allocation per step.
#include <cstddef>
#include <vector>

namespace floedem {

/// Makes room for n elements, and half as many again, when v cannot hold n. vector::assign
/// allocates exactly what it is asked for: a list that grows by a few elements a step (the
/// pairs of a compacting field, the islands of a growing pile) would allocate at every step
/// that sets a new largest size.
template <class T>
void reserve_with_headroom(std::vector<T>& v, std::size_t n) {
  if (v.capacity() < n) v.reserve(n + n / 2);
}

}  // namespace floedem
