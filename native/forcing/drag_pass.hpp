#pragma once
// The drag terms of a floe in one pass over its outline.
//
// Water form, water skin, air form and air skin drag (drag.hpp) each integrate over the same
// waterline polygon, one after the other in Forcing's order. For a drifting field each floe
// takes every term's four-floe lanes, and each term streams its own packed points from memory
// (about 5 MB a term at 16 000 floes, evicted by the rest of the step) and turns them into the
// world itself. DragPass reads each floe's corners once (64 bytes an edge for four terms, where
// the terms' lanes take 192), forms the rule's points from them with the terms' own operations
// (a Gauss point a + (1/2 -+ 1/(2 sqrt 3)) (b - a), a half-vertex a / 2, a middle (a + b) / 2),
// turns each into the world once and evaluates every term at it.
//
// The same sums to the bit: a body's sum is a chain of additions in term order, so the first
// term adds as it goes, the others' contributions wait in a buffer and are added after, term
// by term, point by point, as the terms would add them. Each lane takes the terms' IEEE
// operations in their order (-ffp-contract=off); a point a term would skip (past the floe's
// outline, facing away from the flow, or the body at rest in that term's flow) adds -0, and
// x + (-0) = x for every x. Built only for floes that every term of the run holds in one slab
// of scale 1 with quadratic drag; the pass checks, body by body, that the points it forms are
// the terms' packed points to the bit, and leaves any other body to the terms. A shared floe
// that needs the Jacobian takes each term's own path (DistributedDrag::add_entry), in term
// order; in still water and air only the groups with a moving floe are visited.
#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "engine/line_vector.hpp"
#include "forcing/drag.hpp"

namespace floedem {

class DragPass {
 public:
  static constexpr int kMaxTerms = 4;
  static constexpr std::uint32_t kMaxCorners = 24;  ///< larger outlines are left to the terms

  /// `terms`: consecutive terms of Forcing's order (at most kMaxTerms), every body added; from
  /// here on they leave the floes the pass takes to it (DistributedDrag::leave_to_pass), so the
  /// run is added through the pass alone. `polygon` gives a body's waterline polygon as the
  /// terms were given it (BodySpec::local_polygon).
  DragPass(const std::vector<DistributedDrag*>& terms, const std::function<const std::vector<Vec2>&(std::size_t)>& polygon);
  /// How many floes the pass takes (0: the terms keep every body).
  std::size_t floes() const { return floes_; }
  /// Adds the run's terms as they would add one after the other: each term its own bodies,
  /// then the shared floes in one pass.
  void add(const BodyStatesView& state, double time, ForceSums& sums) const;
  /// Takes the terms' flows again into the groups, after a term whose flow varies set them
  /// for a step (DistributedDrag::set_time).
  void refresh_flows();
  /// The run's rate bounds (ForceTerm::add_rate_bound), likewise.
  void add_rate_bound(const BodyStatesView& state, ForceSums& sums) const;

  static constexpr int kLanes = 4;
  struct Group {
    std::array<std::uint32_t, kLanes> body{};  // lanes past `lanes` repeat lane 0's
    std::array<std::int64_t, kLanes> count{};  // each lane's edges (0 past `lanes`)
    std::array<std::array<double, kLanes>, kMaxTerms> flow_x{}, flow_y{};
    std::array<std::array<std::uint32_t, kLanes>, kMaxTerms> entry{};  // each lane's entry in each term
    std::uint32_t first = 0, slots = 0, lanes = 0;  // slots: edges + 1 (the closing corner)
  };
  /// Edge j of four floes: its first corner, its outward normal and each term's weight (the
  /// term's packed FormEdge or SkinTriangle weight). Slot count_l holds lane l's first corner
  /// again, so that an edge's second corner is always the next slot's.
  struct Slot {
    double corner_x[kLanes], corner_y[kLanes];
    double normal_x[kLanes], normal_y[kLanes];
    double weight[kMaxTerms][kLanes];
  };
  /// A group's slab moments sum |k| |r|^j (j = 0..3) for each term, lane by lane (the rate bound).
  struct Moments {
    double m[kMaxTerms][4][kLanes];
  };
  /// The run's shape, read by the kernel: each term's kind, and whether any is form or skin.
  struct Shape {
    int terms = 0;  // 2 to kMaxTerms
    std::array<bool, kMaxTerms> form{};
    bool any_form = false, any_skin = false, rotational = true;
  };

 private:
  std::vector<const DistributedDrag*> terms_;
  Shape shape_;
  LineVector<Group> groups_;
  LineVector<Slot> slots_;
  LineVector<Moments> moments_;  // one per group, read in the groups' order
  std::vector<std::uint8_t> shared_;  // per body: 1 where the pass adds it
  std::size_t floes_ = 0;
  /// The groups to visit this step (drag_pass.cpp).
  std::span<const std::uint32_t> groups_to_visit(const ForceSums& sums) const;
  bool calm_ = false;                       // every term's flows are zero (DistributedDrag::calm_)
  std::vector<std::int32_t> group_of_body_;  // -1: not shared
  mutable std::vector<std::uint32_t> visit_;  // a moving flow: every group, fixed
  mutable std::vector<std::uint8_t> listed_;
};

}  // namespace floedem
