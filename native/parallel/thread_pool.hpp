#pragma once
// A persistent pool of worker threads for the per-step loops (forcing, narrow phase, placing,
// integration). Work is split into blocks fixed by the loop's size and grain alone, and every
// index writes only its own outputs, so results do not depend on the thread count: a run with
// FLOEDEM_THREADS=1 and one with 16 are identical to the bit (tests/run/test_determinism.cpp).
// The calling thread takes blocks too; workers sleep on a condition variable between loops
// (no spinning: the report runs several processes on few cores). Waking them costs tens of
// microseconds, so each loop's grain is set for a block of some 50-150 us of work: a small
// scene runs inline on the caller.
#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstddef>
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
  /// spread over the threads; returns when all are done. Inline when one block covers it.
  template <class F>
  void for_blocks(std::size_t n, std::size_t grain, F&& fn) {
    grain = std::max<std::size_t>(grain, 1);
    const std::size_t blocks = (n + grain - 1) / grain;
    if (blocks <= 1 || workers_.empty()) {
      if (n > 0) fn(std::size_t{0}, n);
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

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  void* context_ = nullptr;
  BlockFn block_ = nullptr;
  std::size_t blocks_ = 0;
  std::atomic<std::size_t> next_{0};
  std::size_t busy_ = 0;          // workers inside the current job (under mutex_)
  std::uint64_t generation_ = 0;  // bumped for each job (under mutex_)
  bool stop_ = false;
};

/// The process's pool, with worker_threads() threads (FLOEDEM_THREADS), made on first use.
ThreadPool& thread_pool();

/// Replaces the process's pool by one of `threads` threads (tests compare thread counts).
/// Only while no loop runs on the pool.
void set_thread_pool_size(unsigned threads);

}  // namespace floedem
