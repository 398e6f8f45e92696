#pragma once
// Wall time per stage of a step, for `floedem bench` (where a step's time goes: the report's
// speed section). Off unless asked for (Engine::time_stages, `floedem bench --stages`): then
// each stage reads the clock twice: nothing against a field's step, but several times a
// two-floe impact's whole step, hence the switch. The timing changes nothing the step computes.
#include <array>
#include <chrono>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace floedem {

/// One stage's wall time, summed over the steps since timing was switched on.
struct StageTime {
  std::string name;
  double seconds = 0.0;
};

/// Sums of wall time for N named stages.
template <std::size_t N>
class StageClock {
 public:
  explicit StageClock(std::array<const char*, N> names) : names_(names) {}

  void enable(bool on) { on_ = on; }
  bool enabled() const { return on_; }

  /// Runs f(), its wall time added to `stage` when enabled.
  template <class F>
  void time(std::size_t stage, F&& f) {
    if (!on_) {
      std::forward<F>(f)();
      return;
    }
    const auto start = std::chrono::steady_clock::now();
    std::forward<F>(f)();
    seconds_[stage] += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }

  /// Appends each stage's sum, in the stages' order (those never timed too, at 0).
  void add_to(std::vector<StageTime>& out) const {
    for (std::size_t k = 0; k < N; ++k) out.push_back({names_[k], seconds_[k]});
  }

 private:
  std::array<const char*, N> names_;
  std::array<double, N> seconds_{};
  bool on_ = false;
};

}  // namespace floedem
