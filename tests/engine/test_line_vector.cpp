// LineVector (native/engine/line_vector.hpp): storage on a 64-byte cache line, through every way
// the solver grows and swaps its lists; large lists on whole 2 MiB pages; the elements kept.
#include <catch2/catch.hpp>

#include <cstdint>

#include "engine/line_vector.hpp"
#include "collision/manifold.hpp"
#include "engine/headroom.hpp"

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

TEST_CASE("line vector: a list of 2 MiB or more starts on a huge page, and keeps its elements", "[engine][memory]") {
  const auto on_a_huge_page = [](const LineVector<double>& v) {
    return reinterpret_cast<std::uintptr_t>(v.data()) % kHugePage == 0;
  };
  const std::size_t small = kHugePage / sizeof(double) / 2, large = 3 * kHugePage / sizeof(double) + 7;
  LineVector<double> v(small);
  REQUIRE(on_a_line(v));
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = 0.1 * static_cast<double>(i);
  v.resize(large);  // across the threshold: the elements move onto huge pages
  REQUIRE(on_a_huge_page(v));
  for (std::size_t i = 0; i < small; ++i) REQUIRE(v[i] == 0.1 * static_cast<double>(i));
  for (std::size_t i = small; i < large; ++i) REQUIRE(v[i] == 0.0);
  v[large - 1] = 2.5;  // the last element, on the last page's partial end, is the list's own
  LineVector<double> copy = v;
  REQUIRE(on_a_huge_page(copy));
  REQUIRE(copy[large - 1] == 2.5);
  v.resize(small);
  v.shrink_to_fit();  // and back below it: a cache line again, freed with the alignment it was made with
  REQUIRE(on_a_line(v));
  REQUIRE(v[small - 1] == 0.1 * static_cast<double>(small - 1));
}
