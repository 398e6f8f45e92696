#pragma once
// A wind or current field on a grid, as the run evaluates it (docs/forcing.md): bilinear in
// x and y, linear in depth and in time, between the samples of a FlowGridSpec. Only the two
// time slices around the step are held in memory (NetcdfSlices reads them).
#include <atomic>
#include <memory>
#include <vector>

#include "floedem/scene/scene.hpp"

namespace floedem {

class NetcdfSlices;

class FlowGrid {
 public:
  explicit FlowGrid(const FlowGridSpec& spec);
  ~FlowGrid();
  FlowGrid(const FlowGrid&) = delete;
  FlowGrid& operator=(const FlowGrid&) = delete;
  /// Holds the slices around time t (s from the run's start) for at(); called once a step,
  /// before the terms (not from several threads).
  void prepare(double t);
  /// The velocity at point p (m, the scene's frame) and depth (m below the surface; the first
  /// or last level beyond the axis), at the prepared time; safe from several threads. A point
  /// off the grid or where the file holds no value gives the nearest value on the grid, and is
  /// noted (problem()), so that the run stops after the step with a message.
  Vec2 at(Vec2 p, double depth) const;
  /// The cell of the grid that holds p at a depth, its corners blended to the prepared time
  /// and the depth: a body's points that fall in it are evaluated from it alone (the same
  /// arithmetic as at(), so the same values to the bit), which spares each point the search
  /// and the sixteen reads of at().
  struct Cell {
    double x0 = 0.0, x1 = 0.0, y0 = 0.0, y1 = 0.0;
    Vec2 c00, c10, c01, c11;  // the corners' velocities: (x0, y0), (x1, y0), (x0, y1), (x1, y1)
    bool contains(Vec2 p) const { return p.x >= x0 && p.x <= x1 && p.y >= y0 && p.y <= y1; }
    Vec2 value(Vec2 p) const;  ///< bilinear, for p inside
  };
  Cell cell(Vec2 p, double depth) const;
  /// dV/dt at p and depth over the prepared slices' interval.
  Vec2 rate_at(Vec2 p, double depth) const;
  /// The largest speed of the prepared slices (m/s): the drag's rate bound takes it.
  double max_speed() const { return max_speed_; }
  /// What went wrong at the last prepared time (empty: nothing): a point off the grid or on a
  /// fill value. Clears it.
  std::string take_problem();
  const FlowGridSpec& spec() const { return spec_; }

 private:
  struct Slice {
    std::size_t index = static_cast<std::size_t>(-1);
    std::vector<double> u, v;
  };
  const Slice& slice(std::size_t k);
  Cell cell_at(Vec2 p, double depth, double wt) const;  // at time weight wt between the slices
  Vec2 at_weight(Vec2 p, double depth, double wt) const;
  double corner_value(std::size_t base0, std::size_t base1, double wz, double wt, std::size_t index, int comp) const;
  const FlowGridSpec& spec_;
  std::unique_ptr<NetcdfSlices> file_;
  Slice slices_[2];
  const Slice* before_ = nullptr;
  const Slice* after_ = nullptr;
  double weight_ = 0.0, span_ = 1.0, time_ = 0.0;
  double max_speed_ = 0.0;
  std::size_t speed_of_[2] = {static_cast<std::size_t>(-1), static_cast<std::size_t>(-1)};  // its slices
  mutable std::atomic<int> off_grid_{0}, no_value_{0};
  mutable std::atomic<double> off_x_{0.0}, off_y_{0.0};
};

}  // namespace floedem
