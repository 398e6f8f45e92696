#include <catch2/catch.hpp>

#include <random>

#include "solver/broad_phase.hpp"

using namespace floedem;

TEST_CASE("broad phase finds exactly the overlapping pairs, once each, sorted", "[broad]") {
  // Sizes spread over two decades and a few very large parts (an iceberg), against brute force.
  for (const int n : {5, 30, 400, 3000}) {
    std::mt19937_64 rng(static_cast<unsigned>(n));
    std::uniform_real_distribution<double> pos(-500.0, 500.0), u(0.0, 1.0);
    std::vector<Aabb> boxes;
    std::vector<std::int32_t> body;
    std::vector<std::uint8_t> fixed;
    for (int i = 0; i < n; ++i) {
      const double size = i % 97 == 0 ? 300.0 : 2.0 * std::pow(10.0, 2.0 * u(rng));
      const Vec2 c{pos(rng), pos(rng)};
      boxes.push_back({c - Vec2{size / 2, size * 0.3}, c + Vec2{size / 2, size * 0.3}});
      body.push_back(i - (i % 3 == 2 ? 1 : 0));  // every third part shares the previous part's body
      fixed.push_back(i % 11 == 0 ? 1 : 0);
    }
    std::vector<PartPair> expected;
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j)
        if (body[i] != body[j] && !(fixed[i] && fixed[j]) && boxes[i].overlaps(boxes[j])) expected.push_back({i, j});
    BroadPhase bp;
    std::vector<PartPair> got;
    bp.find_pairs(boxes, body, fixed, got);
    CHECK(got == expected);
    bp.find_pairs(boxes, body, fixed, got);  // reuse of the buffers
    CHECK(got == expected);
  }
}

TEST_CASE("a lone part builds no pairs", "[broad]") {
  BroadPhase bp;
  std::vector<PartPair> out{{0, 1}};
  const std::vector<Aabb> boxes{{{0, 0}, {1, 1}}};
  const std::vector<std::int32_t> body{0};
  const std::vector<std::uint8_t> fixed{0};
  bp.find_pairs(boxes, body, fixed, out);
  CHECK(out.empty());
}
