#pragma once
// Plain Gauss-Seidel sweeps of one large island on several threads, the same to the bit as
// the sweeps on one thread (run_sweeps in contact_solver.cpp), for the packed fields whose
// contacts are one island: there the serial sweeps were the step's largest serial part
// (a third of the 4k field's step on two threads).
//
// The serial sweeps update rows 0, 1, ..., R-1, then again, each update reading and writing the
// velocities of its two bodies. Two updates that share no moving body commute, so any order
// that keeps, per moving body, the serial order of the updates that touch it reads and writes
// the same values (fixed and towed bodies are only read). The rows are cut into parts by where
// their bodies lie (slabs across the island's longest extent), one thread per part; each thread
// makes its part's rows in serial order, sweep after sweep, and before an update waits only for
// the updates that the serial order puts just before it on each of its bodies when those belong
// to another part (a counter each part publishes). Only rows near the cuts wait, and only for
// what another thread did about half a sweep before: the parts run as a pipeline, not in lock
// step (a barrier per sweep would leave the later slab waiting for the earlier's rows at the cut).
// This is wavefront (DOACROSS) scheduling of the sweep loop over its per-body dependences, with
// coarse blocks; the fine-grained variant, level scheduling (Anderson and Saad 1989), waited on
// every level and ran 2.7 times slower on two threads than one.
//
// The sweeps stop after the first sweep whose largest impulse change is within the tolerance
// of its largest impulse, known only once every part has made that sweep. A part goes on into
// the next sweep meanwhile (at most one sweep ahead of what is decided) and logs what it
// overwrites; if that sweep is not to be made, the log is put back once every thread has
// stopped, and the state is that of the serial sweeps that stopped there.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "engine/cache_line.hpp"
#include "solver/contact_solver.hpp"

namespace floedem {

class SweepPipeline {
 public:
  struct Result {
    int sweeps = 0;          ///< sweeps made (and kept)
    bool converged = false;  ///< stopped by the tolerance (else: `iterations` sweeps made)
  };

  /// How many parts `rows` rows are cut into on the process's thread pool: 1 where a second
  /// thread would not pay (few rows a part) or there is none.
  static unsigned parts_for(std::size_t rows);

  /// Up to `iterations` plain sweeps over `rows` (no conjugate-gradient step), stopping after
  /// the first whose largest change |dP_n| + |dP_t| is at most `tolerance` times its largest
  /// impulse P_n + |P_t|: run_sweeps' loop to the bit, on parts_for(rows.size()) threads of the
  /// pool. Must not be called from inside a loop of the pool.
  Result run(std::span<SweepRow> rows, BodyArrays& bodies, int iterations, double tolerance);

  /// Parts' sweeps made past the stop (begun before it was known) and put back, over all runs.
  std::int64_t sweeps_put_back() const { return put_back_; }

 private:
  // A part's row, in the part's (serial) order.
  struct PartRow {
    std::int32_t row = 0;
    std::uint8_t flags = 0;  // kWaits, kPublish, kFirstA, kFirstB
  };
  // Before its row, in sweep k: wait until part `part` (of `size` rows) has made k * size + bias
  // updates, bias = offset * size + local + 1 for its update `local` of sweep k + offset
  // (offset -1: that update comes later in the serial order, so in the sweep before).
  struct Wait {
    std::int32_t part = 0;
    std::int32_t size = 0;
    std::int64_t bias = 0;
  };
  struct BodyLog {
    std::int32_t body = 0;
    Vec2 velocity;
    double angular_velocity = 0.0;
  };
  struct alignas(kCacheLine) Part {  // a cache line of its own: each thread writes its part's
    std::vector<PartRow> rows;
    std::vector<Wait> waits;                   // in the order of their rows
    std::vector<BodyLog> body_log;             // a speculative sweep's first write of each body
    std::vector<double> impulse_log;           // a speculative sweep's rows' impulses (n, t)
    std::size_t logged_bodies = 0;
    std::size_t logged_rows = 0;
    int logged_sweep = -1;                     // the sweep the log is of (-1: none)
  };
  struct alignas(kCacheLine) Counter {
    std::atomic<std::int64_t> value{0};
  };
  struct alignas(kCacheLine) SweepSlot {
    std::atomic<int> finished{0};  // parts done with the sweep
  };
  static constexpr int kSlots = 4;  // sweeps in flight at once: at most two

  void plan(std::span<const SweepRow> rows, const BodyArrays& bodies, unsigned parts);
  void run_part(unsigned t, std::span<SweepRow> rows, BodyArrays& bodies);
  template <bool Speculative>
  bool sweep_part(unsigned t, int sweep, std::span<SweepRow> rows, BodyArrays& bodies);
  void undo(Part& part, std::span<SweepRow> rows, BodyArrays& bodies) const;

  struct Place {
    std::int32_t part = 0;
    std::int32_t local = 0;  // in the part's rows
  };
  static constexpr unsigned kMaxParts = 256;
  static constexpr std::size_t kBins = 1024;  // of the histogram the parts are cut from

  std::vector<Part> parts_;
  std::vector<Place> place_;                  // per row
  std::vector<std::int32_t> last_, current_;  // per body: its last row in the sweep; the last seen
  std::vector<double> key_;                   // per row: (x, y) of its further moving body
  std::uint32_t bin_part_[kBins] = {};        // per bin: its row count, then its part
  std::unique_ptr<Counter[]> done_;  // per part: updates made, over all sweeps (n_t per sweep)
  std::size_t counters_ = 0;
  SweepSlot slots_[kSlots];
  std::vector<double> partial_change_, partial_impulse_;  // per slot and part
  std::atomic<int> decided_{0};     // sweeps decided so far (in order)
  std::atomic<int> last_sweep_{0};  // the last sweep to keep (0-based): the cap, or where it converged
  bool converged_ = false;          // written by the decider before decided_ (release)
  int iterations_ = 0;
  double tolerance_ = 0.0;
  unsigned part_count_ = 0;
  std::int64_t put_back_ = 0;
};

}  // namespace floedem
