#include <catch2/catch.hpp>

#include <cstring>

#include <random>

#include "app/sanitizer.hpp"
#include "parallel/thread_pool.hpp"
#include "parallel/threads.hpp"
#include "collision/broad_phase.hpp"
#include "collision/pair_cache.hpp"

using namespace floedem;

TEST_CASE("broad phase finds exactly the overlapping pairs, once each, sorted", "[broad]") {
  // Sizes spread over two decades and a few very large parts (an iceberg), against brute force,
  // on one thread and on three (blocks of cells and of parts, their lists merged: 20 000 parts
  // make several blocks of each).
  const unsigned threads = GENERATE(1u, 3u);
  set_thread_pool_size(threads);
  INFO("threads " << threads);
  for (const int n : {5, 30, 400, 3000, 20000}) {
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
  set_thread_pool_size(worker_threads());
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

TEST_CASE("pair cache: every step the same pairs as a fresh broad phase", "[broad]") {
  // Parts at rest, creeping, drifting fast and jumping (a teleport leaves its fat box at once),
  // a large iceberg-like part sweeping through, many steps: the coherent cache must hand out
  // exactly what a full rebuild finds, in the same order, at every step; on one thread and on
  // three (20 000 parts: several blocks of parts and of candidates).
  const unsigned threads = GENERATE(1u, 3u);
  set_thread_pool_size(threads);
  INFO("threads " << threads);
  for (const int n : {10, 300, 2000, 20000}) {
    std::mt19937_64 rng(static_cast<unsigned>(n) + 7);
    std::uniform_real_distribution<double> pos(-300.0, 300.0), u(0.0, 1.0), s(-1.0, 1.0);
    std::vector<Vec2> centre(n), velocity(n), half(n);
    std::vector<std::int32_t> body;
    std::vector<std::uint8_t> fixed;
    for (int i = 0; i < n; ++i) {
      centre[i] = {pos(rng), pos(rng)};
      const double size = i == 0 ? 150.0 : 2.0 * std::pow(10.0, 1.3 * u(rng));
      half[i] = {size / 2, size * 0.35};
      const int kind = i % 4;  // at rest, creeping, drifting, drifting fast
      const double speed = kind == 0 ? 0.0 : kind == 1 ? 0.01 : kind == 2 ? 0.3 : 3.0;
      velocity[i] = speed * Vec2{s(rng), s(rng)};
      body.push_back(i - (i % 5 == 4 ? 1 : 0));
      fixed.push_back(i % 13 == 12 ? 1 : 0);
      if (fixed.back()) velocity[i] = {};
    }
    velocity[0] = {2.0, 0.5};  // the iceberg
    // Under a sanitizer the 20 000 parts (most of the time) take 60 steps: every kind of part has
    // moved, jumped and been refreshed by then (the checks below); the fewer parts keep 150,
    // which the 10 need to meet at all.
    const int steps = kSanitizerAllocator && n >= 20000 ? 60 : 150;
    BroadPhase fresh;
    PairCache cache;
    // The same, told each step which parts' boxes may have changed (the native engine's parts
    // that are not settled sleepers): the rest are not looked at, and the pairs are the same.
    PairCache told;
    std::vector<Aabb> boxes(n), before(n);
    std::vector<double> margin(n);
    std::vector<PartPair> expected, got, got_told;
    std::vector<std::int32_t> changed;
    std::int64_t pairs_seen = 0, left_out = 0;
    for (int step = 0; step < steps; ++step) {
      changed.clear();
      for (int i = 0; i < n; ++i) {
        centre[i] += velocity[i];
        if (!fixed[i] && u(rng) < 0.002) centre[i] = {pos(rng), pos(rng)};  // a jump
        const double reach = length(velocity[i]);
        boxes[i] = {centre[i] - half[i] - Vec2{reach, reach}, centre[i] + half[i] + Vec2{reach, reach}};
        margin[i] = 4.0 * reach + 0.1 * half[i].x;
        if (step == 0 || std::memcmp(&boxes[i], &before[i], sizeof(Aabb)) != 0) changed.push_back(i);
      }
      before = boxes;
      left_out += n - static_cast<std::int64_t>(changed.size());
      fresh.find_pairs(boxes, body, fixed, expected);
      cache.find_pairs(boxes, margin, body, fixed, got);
      REQUIRE(got == expected);
      told.find_pairs(boxes, margin, body, fixed, got_told, changed);
      REQUIRE(got_told == expected);
      pairs_seen += static_cast<std::int64_t>(expected.size());
    }
    CHECK(left_out > 0);  // parts at rest were left out
    CHECK(pairs_seen > 0);
    if (n >= 300) {
      CHECK(cache.rebuilds() < steps);          // the cache did not just rebuild every step
      CHECK(cache.refreshed_parts() > steps);   // and it did refresh parts in between
    }
  }
  set_thread_pool_size(worker_threads());
}

TEST_CASE("broad phase and pair cache keep no pairs of an earlier call when the threads change", "[broad]") {
  // A call on three threads fills several blocks' lists; the next, on one thread, has other
  // data: no list may hand out the earlier call's pairs.
  auto field = [](int n, double shift, std::vector<Aabb>& boxes) {
    std::mt19937_64 rng(static_cast<unsigned>(n));
    std::uniform_real_distribution<double> pos(-600.0, 600.0), u(0.0, 1.0);
    boxes.clear();
    for (int i = 0; i < n; ++i) {
      const double size = 2.0 * std::pow(10.0, 1.2 * u(rng));
      const Vec2 c{pos(rng) + shift, pos(rng)};
      boxes.push_back({c - Vec2{size / 2, size / 2}, c + Vec2{size / 2, size / 2}});
    }
  };
  const int n = 20000;
  std::vector<std::int32_t> body(n);
  for (int i = 0; i < n; ++i) body[i] = i;
  const std::vector<std::uint8_t> fixed(n, 0);
  const std::vector<double> margin(n, 0.5);
  std::vector<Aabb> first, second;
  field(n, 0.0, first);
  field(n, 1.0, second);  // the same boxes moved: many pairs differ from the first call's
  BroadPhase bp, fresh;
  PairCache cache;
  std::vector<PartPair> got, cached, expected;
  set_thread_pool_size(3);
  bp.find_pairs(first, body, fixed, got);
  cache.find_pairs(first, margin, body, fixed, cached);
  set_thread_pool_size(1);
  bp.find_pairs(second, body, fixed, got);
  cache.find_pairs(second, margin, body, fixed, cached);
  set_thread_pool_size(worker_threads());
  fresh.find_pairs(second, body, fixed, expected);
  CHECK(!expected.empty());
  CHECK(got == expected);
  CHECK(cached == expected);
}
