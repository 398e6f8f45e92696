#pragma once
// How many worker threads the parallel parts of floedem use: the environment variable
// FLOEDEM_THREADS (1 to 256) when set (a sweep sets it to each job's share of the cores), else
// the CPUs this process may run on (sched_getaffinity: a batch job bound to 4 cores of a 128-core
// node gets 4, not 128 spinning threads). Results never depend on it (work is split into blocks
// fixed by the problem, joined in a fixed order).
#include <sched.h>

#include <charconv>
#include <cstdlib>
#include <string_view>
#include <thread>

namespace floedem {

inline unsigned worker_threads() {
  if (const char* env = std::getenv("FLOEDEM_THREADS")) {
    const std::string_view text(env);
    unsigned n = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), n);
    if (ec == std::errc{} && end == text.data() + text.size() && n >= 1 && n <= 256) return n;
  }
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (sched_getaffinity(0, sizeof allowed, &allowed) == 0) {
    const int n = CPU_COUNT(&allowed);
    if (n >= 1) return static_cast<unsigned>(n);
  }
  const unsigned hw = std::thread::hardware_concurrency();
  return hw == 0 ? 1 : hw;
}

/// A spin-wait's pause: tells the core a loop is waiting on another thread (frees the pipeline
/// for a sibling hyperthread, saves power).
inline void cpu_relax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#elif defined(__aarch64__)
  asm volatile("yield");
#endif
}

}  // namespace floedem
