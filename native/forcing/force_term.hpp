#pragma once
// Non-contact forcing as small independent units (docs/model.md section 2). Each term adds, per
// body, its generalised force Q = (F_x, F_y, torque) at the start of the step and, where it
// depends on the body's velocity, the Jacobian dQ/dq with q = (v_x, v_y, omega); Coriolis adds
// a rotation rate instead. Forcing (forcing.hpp) then takes one linearly implicit step per body
// and hands the engines the equivalent constant loads. A term a scene does not use is never
// built, so it costs nothing. The same terms drive every engine, so that engines differ only
// in contact. Adding a term: one source file with a builder, and one line in forcing.cpp.
#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "floedem/engine/engine.hpp"
#include "floedem/scene/scene.hpp"

namespace floedem {

class CoriolisField;
class DistributedDrag;
class FlowGrid;
struct TowLine;

/// What varies over the scene's plane, each null where the scene has none: the gridded wind and
/// current (flow_grid.hpp), built and prepared once a step by Forcing, and the Coriolis
/// parameter of a geographic scene (coriolis_field.hpp); read by the terms that take them.
struct FlowFields {
  std::unique_ptr<FlowGrid> current, wind;
  std::unique_ptr<CoriolisField> coriolis;
};

/// One body's generalised force Q and Jacobian dQ/dq while a term adds to it point by point:
/// a copy held in registers (the per-point sums would otherwise go through memory, since the
/// compiler cannot rule out aliasing with the quadrature data), added in the same order as
/// point by point into ForceSums, so the result is the same to the bit.
struct BodySum {
  std::array<double, 3> q;
  std::array<double, 9> d;
  /// Adds the force f acting at offset r (world) from the centroid without its Jacobian (a
  /// body whose drag cannot be stiff this step, see ForceTerm::add_rate_bound).
  void add_point_force(Vec2 r, Vec2 f, bool with_torque) {
    q[0] += f.x;
    q[1] += f.y;
    if (with_torque) q[2] += cross(r, f);
  }
  /// Adds the force f acting at offset r (world) from the centroid, with dF/du = a (2x2,
  /// row-major) where u = flow - (v + w k x r): Q += G^T f, dQ/dq -= G^T a G, G = [I, k x r].
  void add_point_force(Vec2 r, Vec2 f, const std::array<double, 4>& a, bool with_torque) {
    // G = [[1, 0, -r_y], [0, 1, r_x]] maps q to the point's velocity.
    const double gx = with_torque ? -r.y : 0.0, gy = with_torque ? r.x : 0.0;
    q[0] += f.x;
    q[1] += f.y;
    if (with_torque) q[2] += cross(r, f);
    // G^T a G, with a = [[a0, a1], [a2, a3]].
    const double a0 = a[0], a1 = a[1], a2 = a[2], a3 = a[3];
    const double c0 = a0 * gx + a1 * gy;  // (a G)_{0,2}
    const double c1 = a2 * gx + a3 * gy;  // (a G)_{1,2}
    d[0] -= a0;
    d[1] -= a1;
    d[2] -= c0;
    d[3] -= a2;
    d[4] -= a3;
    d[5] -= c1;
    d[6] -= gx * a0 + gy * a2;
    d[7] -= gx * a1 + gy * a3;
    d[8] -= gx * c0 + gy * c1;
  }
};

/// Per-body sums the terms add to, in world axes about each body's centroid.
struct ForceSums {
  std::vector<std::array<double, 3>> q;   ///< generalised force (N, N, N m)
  std::vector<std::array<double, 9>> dq;  ///< dQ/dq, row-major 3x3
  std::vector<double> rotation_rate;      ///< f of -m f k x v (1/s); treated exactly, see forcing.cpp
  bool any_jacobian = false;
  bool any_rotation = false;
  /// Each body's rotation at the start of the step, Rot::from_angle(angle): set by Forcing
  /// before the terms add (one sin/cos per body that turned since the last step, not one per
  /// term), for the terms to read.
  std::vector<Rot> rotation;
  /// Per body: whether the terms add dQ/dq (set by Forcing before they add). Zero where the
  /// terms' bound on dt |D| / M shows that the step is explicit whatever D is: D is then never
  /// read, and a term adds Q alone (the same Q to the bit).
  std::vector<std::uint8_t> jacobian;
  /// Per body, filled by ForceTerm::add_rate_bound: upper bounds on the row sums of the
  /// translational block of -D (N s/m) and on |D_ww| (N m s).
  std::vector<std::array<double, 2>> rate_bound;
  /// The bodies that move (a nonzero velocity or spin at the state the terms see), ascending;
  /// set by Forcing before the terms add, when a term reads it (ForceTerm::reads_stirred). A
  /// term in still water and air visits only these (a body at rest listed too costs a look).
  std::vector<std::int32_t> stirred;

  void add_force(std::size_t i, Vec2 f, double torque) {
    q[i][0] += f.x;
    q[i][1] += f.y;
    q[i][2] += torque;
  }
  BodySum load(std::size_t i) const { return {q[i], dq[i]}; }
  /// Stores a body's sum back after a term added point forces to it. Safe from several
  /// threads for distinct bodies; the term then sets any_jacobian once if it added any.
  void store(std::size_t i, const BodySum& s) {
    q[i] = s.q;
    dq[i] = s.d;
  }
  /// One point force on body i (BodySum::add_point_force); terms that add many points to a
  /// body use load / store around them instead.
  void add_point_force(std::size_t i, Vec2 r, Vec2 f, const std::array<double, 4>& a, bool with_torque) {
    BodySum s = load(i);
    s.add_point_force(r, f, a, with_torque);
    store(i, s);
    any_jacobian = true;
  }
};

class ForceTerm {
 public:
  virtual ~ForceTerm() = default;
  virtual std::string_view name() const = 0;
  /// Adds this term at the start of a step at `time`.
  virtual void add(const BodyStatesView& state, double time, ForceSums& sums) const = 0;
  /// Adds to sums.rate_bound, per body, upper bounds of what this term adds to the row sums
  /// max(|D_xx| + |D_xy|, |D_yx| + |D_yy|) and to |D_ww| of the Jacobian at this state, and
  /// returns true; or returns false when it cannot bound them (then every body gets the full
  /// Jacobian). A term that adds no Jacobian returns true and adds nothing.
  virtual bool add_rate_bound(const BodyStatesView&, ForceSums&) const { return false; }
  /// True for a term that only adds a constant rotation rate (Coriolis): a scene whose terms
  /// are all such takes a precomputed per-body path (Forcing::evaluate).
  virtual bool constant_rotation_only() const { return false; }
  /// True for a term that reads ForceSums::stirred (Forcing lists the moving bodies only then).
  virtual bool reads_stirred() const { return false; }
  /// True for a term that neither reads nor adds anything for a body at rest (zero velocity
  /// and spin at the state it sees) but, at most, a rotation rate: drag in still water and
  /// air, Coriolis. When every term is such, Forcing works on the moving bodies alone.
  virtual bool idle_at_rest() const { return false; }
  /// Hands the term the scene's gridded fields (once, before the first step); a term that
  /// reads none ignores them.
  virtual void attach_fields(const FlowFields&) {}
  /// Hands the term the run's tow line (towing/tow.hpp: the tug of mode tug, the rope's
  /// parting), which the run's TowMonitor moves; a term that reads none ignores it.
  virtual void attach_tow(const TowLine&) {}
  /// The term as a distributed drag (drag.hpp), which Forcing may hand a shared pass over the
  /// floes; nullptr for every other term.
  virtual DistributedDrag* distributed_drag() { return nullptr; }
};

/// Builds the term for a scene, or returns nullptr when the scene does not use it.
using ForceTermBuilder = std::unique_ptr<ForceTerm> (*)(const Scene&);

// Builders, one per term file.
std::unique_ptr<ForceTerm> build_applied_load(const Scene& scene);
std::unique_ptr<ForceTerm> build_water_form_drag(const Scene& scene);
std::unique_ptr<ForceTerm> build_water_skin_drag(const Scene& scene);
std::unique_ptr<ForceTerm> build_air_form_drag(const Scene& scene);
std::unique_ptr<ForceTerm> build_air_skin_drag(const Scene& scene);
std::unique_ptr<ForceTerm> build_coriolis(const Scene& scene);
std::unique_ptr<ForceTerm> build_sea_surface_tilt(const Scene& scene);
std::unique_ptr<ForceTerm> build_wave_radiation(const Scene& scene);
std::unique_ptr<ForceTerm> build_rope_tow(const Scene& scene);

}  // namespace floedem
