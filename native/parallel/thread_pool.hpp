#pragma once
// A persistent pool of worker threads for the per-step loops (forcing, broad and narrow phase,
// placing, islands, integration). Work is split into blocks fixed by the loop's size and grain
// alone, and every index writes only its own outputs, so results do not depend on the thread
// count or on which thread takes which block: a run with FLOEDEM_THREADS=1 and one with 16 are
// identical to the bit (tests/run/test_determinism.cpp).
//
// A step runs some fifteen short loops, with serial work between them, so what a
// loop costs beyond its blocks decides whether a second thread helps at all. Here:
//  - a worker joins a job only while it is open, and the caller closes it as soon as every
//    block is claimed: a worker still waking when the caller has done all the blocks alone
//    joins nothing and is not waited for. The caller waits only for the workers inside the
//    job (whose blocks it needs); before, it waited for every worker to pass through every
//    job, a wake-up round trip (tens of microseconds on a VM) on each loop of the step;
//  - a worker that has finished a job watches for the next for a short while (kSpin in
//    thread_pool.cpp) before it sleeps on a condition variable, so the next loop of the same
//    step finds it awake; the caller watches the last blocks likewise before it sleeps. The
//    bound is short enough that a pool on a shared machine gives its core back almost at once
//    (the report runs one process per core, each with one thread and so no workers).
#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

namespace floedem {

class ThreadPool {
 public:
  explicit ThreadPool(unsigned threads);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  /// Threads that take blocks, the caller's included.
  unsigned size() const { return static_cast<unsigned>(workers_.size()) + 1; }

  /// Calls fn(begin, end) for consecutive blocks of at most `grain` indices covering [0, n),
  /// spread over the threads; returns when all are done. The blocks are the same on one
  /// thread (the caller takes them in order), so state kept per block (begin / grain) is too.
  /// One loop at a time: fn must not call for_blocks.
  template <class F>
  void for_blocks(std::size_t n, std::size_t grain, F&& fn) {
    grain = std::max<std::size_t>(grain, 1);
    const std::size_t blocks = (n + grain - 1) / grain;
    if (blocks <= 1 || workers_.empty()) {
      for (std::size_t b = 0; b < blocks; ++b) fn(b * grain, std::min(n, (b + 1) * grain));
      return;
    }
    struct Job {
      F& fn;
      std::size_t n, grain;
    } job{fn, n, grain};
    // A plain function and a pointer, not a std::function: no allocation per loop.
    run(blocks, &job, [](void* p, std::size_t b) {
      Job& j = *static_cast<Job*>(p);
      j.fn(b * j.grain, std::min(j.n, (b + 1) * j.grain));
    });
  }

 private:
  using BlockFn = void (*)(void*, std::size_t);
  void run(std::size_t blocks, void* context, BlockFn block);
  void work_loop();
  void take_blocks();

  // state_: the job's number (high half), how many workers are inside it (bits 1-31) and
  // whether it is closed to more (bit 0). A worker enters an open job with a compare-exchange,
  // and only then reads the job's fields; the caller closes the job once every block is
  // claimed and writes the next job's fields only after the last worker inside has left.
  static constexpr std::uint64_t kClosed = 1, kEntered = 2;
  static std::uint32_t job_of(std::uint64_t s) { return static_cast<std::uint32_t>(s >> 32); }
  static std::uint64_t inside(std::uint64_t s) { return (s & 0xffffffffu) >> 1; }

  std::vector<std::thread> workers_;
  std::atomic<std::uint64_t> state_{0};
  void* context_ = nullptr;  // the job (read by a worker only while it is inside)
  BlockFn block_ = nullptr;
  std::size_t blocks_ = 0;
  std::atomic<std::size_t> next_{0};  // next block to claim
  std::uint32_t job_ = 0;             // jobs run so far (the caller's)
  // Sleeping, after kSpin without news: workers on wake_, the caller on finished_.
  std::mutex mutex_;
  std::condition_variable wake_, finished_;
  std::atomic<int> sleepers_{0};
  std::atomic<bool> caller_asleep_{false};
  std::atomic<bool> stop_{false};
};

/// The process's pool, with worker_threads() threads (FLOEDEM_THREADS), made on first use.
ThreadPool& thread_pool();

/// Replaces the process's pool by one of `threads` threads (tests compare thread counts).
/// Only while no loop runs on the pool.
void set_thread_pool_size(unsigned threads);

}  // namespace floedem
