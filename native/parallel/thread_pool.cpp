#include "parallel/thread_pool.hpp"

#include <memory>

#include "parallel/threads.hpp"

namespace floedem {

ThreadPool::ThreadPool(unsigned threads) {
  for (unsigned t = 1; t < std::max(threads, 1u); ++t) workers_.emplace_back([this] { work_loop(); });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (std::thread& t : workers_) t.join();
}

void ThreadPool::take_blocks() {
  for (std::size_t b; (b = next_.fetch_add(1, std::memory_order_relaxed)) < blocks_;) block_(context_, b);
}

void ThreadPool::run(std::size_t blocks, void* context, BlockFn block) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    context_ = context;
    block_ = block;
    blocks_ = blocks;
    next_.store(0, std::memory_order_relaxed);
    busy_ = workers_.size();
    ++generation_;
  }
  wake_.notify_all();
  take_blocks();
  // Every worker leaves the job before the next one is set up (the job's fields are reused).
  std::unique_lock<std::mutex> lock(mutex_);
  done_.wait(lock, [this] { return busy_ == 0; });
  context_ = nullptr;
  block_ = nullptr;
}

void ThreadPool::work_loop() {
  std::uint64_t seen = 0;
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
    }
    take_blocks();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (--busy_ == 0) done_.notify_one();
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
