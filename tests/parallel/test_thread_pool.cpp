// The pool that runs the per-step loops: every index of a loop is visited exactly once, by
// blocks that are the loop's own (fixed by its size and grain), on any number of threads, over
// many loops in a row (jobs open and close faster than a worker wakes), and across sleeps.
#include <catch2/catch.hpp>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "parallel/thread_pool.hpp"

namespace floedem {

namespace {

/// Runs `loops` loops of sizes cycling through a few shapes (one block, a short tail, many
/// blocks); each index counts its visits and each block checks its bounds.
void check_every_index_once(ThreadPool& pool, int loops) {
  const std::size_t sizes[] = {1, 7, 64, 65, 1000, 4096, 12345};
  const std::size_t grains[] = {1, 3, 64, 512};
  std::vector<std::atomic<int>> visits(12345);
  std::atomic<int> bad_blocks{0};
  for (int loop = 0; loop < loops; ++loop) {
    const std::size_t n = sizes[loop % 7], grain = grains[(loop / 7) % 4];
    for (std::size_t i = 0; i < n; ++i) visits[i].store(0, std::memory_order_relaxed);
    pool.for_blocks(n, grain, [&](std::size_t begin, std::size_t end) {
      // A block is [k grain, min(n, (k + 1) grain)), on one thread as on several.
      if (begin % grain != 0 || end != std::min(n, begin + grain)) bad_blocks.fetch_add(1);
      for (std::size_t i = begin; i < end; ++i) visits[i].fetch_add(1, std::memory_order_relaxed);
    });
    // for_blocks has returned: every block's writes are visible here.
    std::size_t wrong = 0;
    for (std::size_t i = 0; i < n; ++i) wrong += visits[i].load(std::memory_order_relaxed) != 1;
    INFO("loop " << loop << ": n " << n << ", grain " << grain);
    REQUIRE(wrong == 0);
  }
  CHECK(bad_blocks.load() == 0);
}

}  // namespace

TEST_CASE("thread pool visits every index once on 1 to 4 threads", "[parallel]") {
  for (unsigned threads = 1; threads <= 4; ++threads) {
    INFO("threads " << threads);
    ThreadPool pool(threads);
    CHECK(pool.size() == threads);
    check_every_index_once(pool, 2000);
  }
}

TEST_CASE("thread pool resumes after its workers have gone to sleep", "[parallel]") {
  ThreadPool pool(3);
  check_every_index_once(pool, 50);
  // Longer than a worker watches for the next job (0.2 ms): the next loops wake sleepers.
  for (int pause = 0; pause < 5; ++pause) {
    std::this_thread::sleep_for(std::chrono::milliseconds(3));
    check_every_index_once(pool, 30);
  }
}

TEST_CASE("thread pool runs blocks on its workers and not only on the caller", "[parallel]") {
  // Blocks that wait for each other can only finish if two threads take them at once: with
  // two blocks and two threads, each block waits (bounded) until the other has started.
  ThreadPool pool(2);
  int met = 0;
  for (int attempt = 0; attempt < 20; ++attempt) {
    std::atomic<int> started{0};
    std::atomic<bool> both{false};
    pool.for_blocks(2, 1, [&](std::size_t, std::size_t) {
      started.fetch_add(1);
      const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(200);
      while (started.load() < 2 && std::chrono::steady_clock::now() < until) std::this_thread::yield();
      if (started.load() == 2) both.store(true);
    });
    met += both.load() ? 1 : 0;
  }
  CHECK(met > 0);
}

}  // namespace floedem
