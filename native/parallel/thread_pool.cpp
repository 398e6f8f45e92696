#include "parallel/thread_pool.hpp"

#include <chrono>
#include <memory>

#include "parallel/threads.hpp"

namespace floedem {

namespace {

// How long a thread watches for news before it sleeps: a worker for the next job, the caller
// for the workers still inside a job. Longer than most serial stretches between two loops of
// a step (broad phase, island grouping), far shorter than a step of a field worth two threads
// (docs/performance.md gives both).
constexpr auto kSpin = std::chrono::microseconds(200);

/// True as soon as ready() is, false if it is not within kSpin.
template <class Ready>
bool watch(Ready ready) {
  const auto until = std::chrono::steady_clock::now() + kSpin;
  for (;;) {
    for (int k = 0; k < 64; ++k) {
      if (ready()) return true;
      cpu_relax();
    }
    if (std::chrono::steady_clock::now() >= until) return ready();
  }
}

}  // namespace

ThreadPool::ThreadPool(unsigned threads) {
  for (unsigned t = 1; t < std::max(threads, 1u); ++t) workers_.emplace_back([this] { work_loop(); });
}

ThreadPool::~ThreadPool() {
  stop_.store(true);
  { std::lock_guard<std::mutex> lock(mutex_); }  // a worker between its test and its wait is waiting now
  wake_.notify_all();
  for (std::thread& t : workers_) t.join();
}

void ThreadPool::take_blocks() {
  for (std::size_t b; (b = next_.fetch_add(1, std::memory_order_relaxed)) < blocks_;) block_(context_, b);
}

void ThreadPool::run(std::size_t blocks, void* context, BlockFn block) {
  // No worker is inside a job here (the last run waited for them), so the fields are ours.
  context_ = context;
  block_ = block;
  blocks_ = blocks;
  next_.store(0, std::memory_order_relaxed);
  ++job_;
  // Open (sequentially consistent, as the sleepers' count below: a worker that counted itself
  // after this load sees the new job in its own test, see work_loop).
  state_.store(static_cast<std::uint64_t>(job_) << 32);
  if (sleepers_.load() > 0) {
    { std::lock_guard<std::mutex> lock(mutex_); }
    wake_.notify_all();
  }
  take_blocks();
  // Every block is claimed: close the job, then wait for the workers inside to finish theirs.
  const std::uint64_t closed = state_.fetch_or(kClosed) | kClosed;
  if (inside(closed) == 0) return;
  auto all_out = [this] { return inside(state_.load(std::memory_order_acquire)) == 0; };
  if (watch(all_out)) return;
  caller_asleep_.store(true);
  std::unique_lock<std::mutex> lock(mutex_);
  finished_.wait(lock, [this] { return inside(state_.load()) == 0; });
  caller_asleep_.store(false, std::memory_order_relaxed);
}

void ThreadPool::work_loop() {
  std::uint32_t seen = 0;  // the last job this worker looked at
  auto news = [&] { return stop_.load(std::memory_order_relaxed) || job_of(state_.load(std::memory_order_relaxed)) != seen; };
  for (;;) {
    if (!watch(news)) {
      std::unique_lock<std::mutex> lock(mutex_);
      sleepers_.fetch_add(1);
      wake_.wait(lock, [this, &seen] { return stop_.load() || job_of(state_.load()) != seen; });
      sleepers_.fetch_sub(1);
    }
    if (stop_.load()) return;
    std::uint64_t s = state_.load(std::memory_order_acquire);
    seen = job_of(s);
    // Enter while the job is open; a closed one was done without this worker.
    bool entered = false;
    while (!(s & kClosed) && job_of(s) == seen)
      if (state_.compare_exchange_weak(s, s + kEntered, std::memory_order_acquire, std::memory_order_relaxed)) {
        entered = true;
        break;
      }
    if (!entered) continue;
    take_blocks();
    // Leave (release: the caller reads this worker's blocks' outputs after it sees the count
    // fall); the last one out of a closed job wakes the caller if it sleeps.
    const std::uint64_t left = state_.fetch_sub(kEntered) - kEntered;
    if ((left & kClosed) && inside(left) == 0 && caller_asleep_.load()) {
      { std::lock_guard<std::mutex> lock(mutex_); }
      finished_.notify_one();
    }
  }
}

namespace {
std::unique_ptr<ThreadPool>& the_pool() {
  static std::unique_ptr<ThreadPool> pool;
  return pool;
}
}  // namespace

ThreadPool& thread_pool() {
  std::unique_ptr<ThreadPool>& pool = the_pool();
  if (!pool) pool = std::make_unique<ThreadPool>(worker_threads());
  return *pool;
}

void set_thread_pool_size(unsigned threads) {
  the_pool().reset();
  the_pool() = std::make_unique<ThreadPool>(threads);
}

}  // namespace floedem
