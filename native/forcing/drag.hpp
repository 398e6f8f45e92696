#pragma once
// Quadrature of drag over a body's waterline polygon (shared by the drag terms).
//
// Form drag on an edge element of length dl (outward normal n) that faces the relative flow
// u = V - (v + w k x r) (u.n < 0), per unit height:  dF = 1/2 rho C (-u.n) u dl.
// Summed over a convex outline in a uniform flow, sum dl max(0, -n.u^) is the projected
// width normal to the flow, so F = 1/2 rho C (W h) |u| u: the form drag of docs/model.md 2 with the
// width measured on the polygon. Skin drag on an area element: dF = rho C |u| u dA.
// Integrating both over the polygon with the local velocity gives the rotational damping torque.
// Edges: 2-point Gauss rule; area: centroid fan of signed triangles, 3-point edge-midpoint rule
// (exact for quadratic integrands, hence exact in a uniform flow).
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "forcing/force_term.hpp"

namespace floedem {

/// The 2-point Gauss rule's points on an edge from a to b: a + (1/2 -+ g) (b - a), with
/// g = 1 / (2 sqrt 3) (edge_points; DragPass forms the same points from the corners).
inline double gauss_offset() { return 0.5 / std::sqrt(3.0); }

struct EdgePoint {
  Vec2 r;        ///< body frame, from the centroid
  Vec2 normal;   ///< body frame, outward
  double length; ///< m of edge this point stands for
};

struct AreaPoint {
  Vec2 r;
  double area;  ///< m^2 this point stands for (signed for concave outlines)
};

std::vector<EdgePoint> edge_points(const std::vector<Vec2>& local_polygon);
std::vector<AreaPoint> area_points(const std::vector<Vec2>& local_polygon);

struct DragSettings {
  bool rotational = true;        ///< use the local velocity and add the torque
  double reference_speed = 0.0;  ///< > 0: |u| replaced by this (linearised drag)
};

/// The quadrature point by point: the rule that DistributedDrag evaluates in packed form, and
/// the reference the tests hold it to (the same sums to the bit).
/// `jacobian` false: Q alone (the body cannot be stiff this step), the same Q to the bit.
/// Adds form drag of a slab (height h, outline scaled by s) in the flow V: coefficient
/// c = 1/2 rho C h.
void add_form_drag(BodySum& sum, const std::vector<EdgePoint>& edges, double scale, double c,
                   Vec2 flow, Vec2 v, double w, Rot rot, const DragSettings& settings, bool jacobian = true);

/// Adds skin drag over an area (outline scaled by s): coefficient c = rho C.
void add_skin_drag(BodySum& sum, const std::vector<AreaPoint>& points, double scale, double c,
                   Vec2 flow, Vec2 v, double w, Rot rot, const DragSettings& settings, bool jacobian = true);

/// One layer of a body that feels a drag: its coefficient (1/2 rho C h for form drag, rho C
/// for skin drag), the scale of the outline, and the flow it sits in.
struct DragSlab {
  double c = 0.0;
  double scale = 1.0;
  Vec2 flow;
  double depth = 0.0;  ///< m below the surface where a gridded current is read (0 for the air)
};

/// A drag term distributed over the bodies' outlines (form) or areas (skin), slab by slab.
/// The four drag terms are instances of it; each term's file says which bodies and slabs.
class DistributedDrag final : public ForceTerm {
 public:
  enum class Kind { form, skin };
  /// What the slabs' flows are of: the current (water) or the wind (air).
  enum class Medium { water, air };
  DistributedDrag(std::string_view name, Kind kind, const EnvironmentSpec& environment, Medium medium);
  void add_body(std::size_t body, const std::vector<Vec2>& local_polygon, std::vector<DragSlab> slabs);
  /// Whether the medium's flow changes in time (tides, a series: EnvironmentSpec::current_varies,
  /// wind_varies); then every slab's flow is its flow as added plus the change the environment
  /// gives at each step (set_time), the same at every slab: a tidal current or a wind record
  /// is uniform over a scene.
  bool flow_varies() const { return varies_; }
  /// Sets every slab's flow for the step that starts at `time` (Forcing, before add).
  void set_time(double time);
  /// Takes the scene's gridded fields (Forcing's, prepared each step): where the medium has
  /// one, each quadrature point's flow is the grid's at the point (and its slab's depth) plus
  /// the slab's flow; such a term has no lanes and no shared pass.
  void attach_fields(const FlowFields& fields) override;
  bool gridded() const { return grid_ != nullptr; }
  bool empty() const { return entries_.empty(); }
  std::string_view name() const override { return name_; }
  void add(const BodyStatesView& state, double time, ForceSums& sums) const override;
  bool add_rate_bound(const BodyStatesView& state, ForceSums& sums) const override;
  bool reads_stirred() const override { return calm_; }
  bool idle_at_rest() const override { return calm_; }
  DistributedDrag* distributed_drag() override { return this; }

 private:
  friend class DragPass;  // reads the packed points and moments, calls add_entry (drag_pass.hpp)
  /// From here on, add and add_rate_bound leave the bodies with shared[body] != 0 to a DragPass,
  /// which adds them (and this term's lanes no longer hold them).
  void leave_to_pass(const std::vector<std::uint8_t>& shared);
  bool passed(std::size_t i) const { return !passed_.empty() && passed_[i] != 0; }
  std::vector<std::uint8_t> passed_;  // per entry: left to a DragPass
  // Packed quadrature, read every step: the same points, weights and order as edge_points /
  // area_points with add_form_drag / add_skin_drag (the same sums to the bit, tested), with
  // each slab's scale and coefficient folded into its points (weight = c s l / 2 for an edge
  // point, c s^2 A / 3 for an area point, in the order those functions multiply them), an
  // edge's normal turned once for its two Gauss points, and the half-vertex that two
  // triangles of the centroid fan share evaluated once.
  struct FormEdge {
    Vec2 first, second;  // the two Gauss points, scaled, body frame
    Vec2 normal;         // outward, body frame
    double weight;       // c s l / 2: each point's share
  };
  struct SkinTriangle {
    Vec2 half_vertex;  // s a_k / 2, shared with the previous triangle (its s a_{k+1} / 2)
    Vec2 middle;       // s (a_k + a_{k+1}) / 2
    double weight;     // c s^2 cross(a_k, a_{k+1}) / 6: each of the three points' share
  };
  struct Slab {
    DragSlab drag;
    std::uint32_t first = 0, count = 0;  // its edges in form_ or triangles in skin_
    std::array<double, 4> moments{};     // sum |k| |r|^j, j = 0..3 (rate bound)
  };
  struct Entry {
    std::size_t body;
    std::uint32_t first_slab, slab_count;  // in slabs_
  };
  void add_form_slab(BodySum& sum, const Slab& slab, Vec2 v, double w, Rot rot, bool jacobian) const;
  void add_skin_slab(BodySum& sum, const Slab& slab, Vec2 v, double w, Rot rot, bool jacobian) const;
  /// The same with the flow of each point: flow_at(r), r the point's offset (world).
  template <class FlowAt>
  void add_form_slab_at(BodySum& sum, const Slab& slab, Vec2 v, double w, Rot rot, bool jacobian, FlowAt flow_at) const;
  template <class FlowAt>
  void add_skin_slab_at(BodySum& sum, const Slab& slab, Vec2 v, double w, Rot rot, bool jacobian, FlowAt flow_at) const;
  /// Entry i in a gridded medium: every slab point by point in the grid's flow.
  bool add_entry_grid(std::size_t i, const BodyStatesView& state, ForceSums& sums) const;
  /// The same without the Jacobian, for quadratic drag, two points at a time (drag.cpp).
  void add_form_slab_lean(BodySum& sum, const Slab& slab, Vec2 v, double w, Rot rot) const;
  void add_skin_slab_lean(BodySum& sum, const Slab& slab, Vec2 v, double w, Rot rot) const;
  /// Entry i's body moves with every slab's flow, without spin: it adds nothing (see drag.cpp).
  bool adds_nothing(std::size_t i, Vec2 v, double w) const;
  /// Entry i's force (and Jacobian where its body needs one); returns whether it added a Jacobian.
  bool add_entry(std::size_t i, const BodyStatesView& state, ForceSums& sums) const;
  void add_entry_bound(std::size_t i, const BodyStatesView& state, ForceSums& sums) const;
  /// One slab's share of the rate bound (add_entry_bound's per-slab sum).
  /// `extra`: a bound on the speed the grid adds to the slab's flow at any point (gridded).
  void add_slab_bound(std::array<double, 2>& b, const std::array<double, 4>& moments, Vec2 flow, Vec2 v,
                      double w, double extra = 0.0) const;
  /// Calls f(i) for each entry that may add something: every entry, or in still water and air
  /// (calm_) only those of the bodies that move (ForceSums::stirred), in blocks of `grain` on
  /// the pool's threads.
  template <class F>
  void for_entries(const ForceSums& sums, std::size_t grain, F&& f) const;
  /// Four floes side by side (drag.cpp): entries of one slab each, in groups of four, their
  /// points transposed so that slot j holds each lane's j-th edge or triangle. Packed on the
  /// first add after the last add_body.
  static constexpr int kLanes = 4;
  struct LaneGroup {
    std::array<std::uint32_t, kLanes> entry{};  // lanes past `lanes` repeat lane 0's
    std::array<std::uint32_t, kLanes> body{};   // each lane's entry's body
    std::array<std::int64_t, kLanes> count{};   // each lane's edges or triangles (0 past `lanes`)
    std::array<double, kLanes> flow_x{}, flow_y{};
    std::array<double, kLanes> start_x{}, start_y{};  // skin: the first half-vertex
    std::uint32_t first = 0, slots = 0, lanes = 0;    // its slots in form_lanes_ or skin_lanes_
  };
  struct FormSlot {
    double first_x[kLanes], first_y[kLanes], second_x[kLanes], second_y[kLanes];
    double normal_x[kLanes], normal_y[kLanes], weight[kLanes];
  };
  struct SkinSlot {
    double next_x[kLanes], next_y[kLanes];  // the triangle's second half-vertex (the next one's first)
    double middle_x[kLanes], middle_y[kLanes], weight[kLanes];
  };
  void pack_lanes() const;
  /// adds_nothing for lane l of a group (one slab, its flow in the group), without the entry's record.
  static bool lane_adds_nothing(const LaneGroup& g, std::uint32_t l, Vec2 v, double w) {
    return w == 0.0 && g.flow_x[l] == v.x && g.flow_y[l] == v.y;
  }
  void add_group(const LaneGroup& g, unsigned mask, const BodyStatesView& state, ForceSums& sums) const;
  struct Quiet {
    std::size_t body;
    Vec2 flow;      // the slabs' flow, when they share one
    bool one_flow;
    bool single;                     // exactly one slab: its moments are here too
    std::array<double, 4> moments;   // the one slab's (rate bound), when single
  };

  std::string_view name_;
  Kind kind_;
  DragSettings settings_;
  const EnvironmentSpec& environment_;
  Medium medium_;
  bool varies_ = false;
  std::vector<Vec2> given_flow_;  // per slab: its flow as added (varies_ only)
  Vec2 change_;                   // the change the flows hold now (varies_ only)
  const FlowGrid* grid_ = nullptr;  // the medium's gridded field, if it has one
  std::vector<Entry> entries_;
  std::vector<Slab> slabs_;
  std::vector<FormEdge> form_;
  std::vector<SkinTriangle> skin_;
  std::vector<Quiet> quiet_;  // per entry, what adds_nothing reads (kept apart: read every step)
  // Every slab's flow is zero (and the drag is not linearised skin drag, which acts at u = 0):
  // a body at rest adds exactly nothing (adds_nothing), so only moving bodies are visited.
  bool calm_ = true;  // false from the start where the flow varies
  std::vector<std::int32_t> entry_of_body_;  // -1: the body has no entry
  // The lanes (pack_lanes), and per entry whether this step's add left it to them.
  mutable bool lanes_packed_ = false;
  mutable std::vector<LaneGroup> groups_;
  // Each lane's slab moments (rate bound), group by group: read in the groups' order, where
  // reading them from quiet_ by entry (entries sorted within windows of 64) waited for memory.
  mutable std::vector<std::array<double, 4>> lane_moments_;
  mutable std::vector<FormSlot> form_lanes_;
  mutable std::vector<SkinSlot> skin_lanes_;
  mutable std::vector<std::uint8_t> in_lanes_, laned_;  // laned_: the entry has a lane
  // Where the moving bodies alone are visited (not lanes_direct): each laned entry's group, and
  // the groups this step's add left a lane to (listed once each: group_listed_), so that the
  // groups of floes at rest are not looked at (the towing case: 5 245 floes, some 400 moving).
  mutable std::vector<std::uint32_t> group_of_entry_;
  mutable std::vector<std::uint8_t> group_listed_;
  mutable std::vector<std::uint32_t> groups_to_add_;
  mutable std::vector<std::uint32_t> unlaned_;          // the entries without one, in order
  /// A moving flow (not calm_), or still water or air with a quarter of the entries' bodies
  /// or more moving (a drifting field's air drag): the lanes' floes are taken straight from
  /// the groups (rate bound and drag), and add_entry / add_entry_bound visit the other entries
  /// alone (drag.cpp). Otherwise (the towing case's field, mostly at rest) the moving bodies
  /// alone are visited, entry by entry. A floe at rest in still water adds nothing on either
  /// path (adds_nothing, lane_adds_nothing), so both give the same sums to the bit.
  bool lanes_direct(const ForceSums& sums) const {
    return lanes_packed_ && (!calm_ || 4 * sums.stirred.size() >= entries_.size());
  }
};

/// Sorts ids by key(id) within consecutive windows of 64, in place: ids near in the list (bodies
/// near in memory) stay near, and the four floes of a lane group end about together (the
/// terms' lanes and DragPass's groups).
template <class Key>
void sort_in_lane_windows(std::vector<std::uint32_t>& ids, Key key) {
  constexpr std::size_t kWindow = 64;
  for (std::size_t w = 0; w < ids.size(); w += kWindow)
    std::stable_sort(ids.begin() + static_cast<std::ptrdiff_t>(w),
                     ids.begin() + static_cast<std::ptrdiff_t>(std::min(ids.size(), w + kWindow)),
                     [&](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); });
}

/// The term, or nullptr when no body needs it.
inline std::unique_ptr<ForceTerm> if_used(std::unique_ptr<DistributedDrag> term) {
  if (term->empty()) return nullptr;
  return term;
}

}  // namespace floedem
