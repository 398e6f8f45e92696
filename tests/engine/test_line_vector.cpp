// LineVector (native/engine/line_vector.hpp): storage on a 64-byte cache line, through every way
// the solver grows and swaps its lists, and the elements kept.
#include <catch2/catch.hpp>

#include <cstdint>

#include "engine/line_vector.hpp"
#include "solver/contact_types.hpp"
#include "solver/headroom.hpp"

using namespace floedem;

namespace {

template <class T>
bool on_a_line(const LineVector<T>& v) {
  return reinterpret_cast<std::uintptr_t>(v.data()) % kCacheLine == 0;
}

template <class T>
void check_growth() {
  LineVector<T> v;
  for (std::size_t n = 1; n < 5000; n += n / 2 + 1) {  // reallocates many times over
    resize_with_headroom(v, n);
    REQUIRE(on_a_line(v));
  }
  LineVector<T> grown;
  for (int i = 0; i < 1000; ++i) {
    grown.push_back(T{});
    REQUIRE(on_a_line(grown));
  }
  LineVector<T> copy = grown;
  REQUIRE(on_a_line(copy));
  std::swap(copy, v);
  REQUIRE(on_a_line(copy));
  REQUIRE(on_a_line(v));
  v.shrink_to_fit();
  REQUIRE(on_a_line(v));
}

}  // namespace

TEST_CASE("line vector: storage starts on a cache line however the list grows", "[engine][memory]") {
  check_growth<Vec2>();           // 16 bytes: a part's vertex
  check_growth<Aabb>();           // 32 bytes: a part's bounds
  check_growth<NarrowManifold>(); // 192 bytes: the narrow phase's slot
  check_growth<Manifold>();       // 384 bytes: a contact
}

TEST_CASE("line vector: growth keeps the elements, to the bit", "[engine][memory]") {
  LineVector<double> v;
  for (int i = 0; i < 3000; ++i) v.push_back(0.1 * i + 1e-17 * i);
  resize_with_headroom(v, 10000);
  for (int i = 0; i < 3000; ++i) REQUIRE(v[static_cast<std::size_t>(i)] == 0.1 * i + 1e-17 * i);
  for (std::size_t i = 3000; i < v.size(); ++i) REQUIRE(v[i] == 0.0);
}
