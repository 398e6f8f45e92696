// ODE 0.16 (double precision) as a reference engine: bodies held in the plane by a plane-2D
// joint, mass and planar inertia set to floedem's values, contacts solved by ODE's QuickStep.
// Contact points come from floedem's 2-D narrow phase (the prisms' side faces, projected):
// ODE's own convex-convex collider returns one point per step on a top corner, which gave
// e = 0.19 to 0.22 instead of 0.3 with spurious spin (docs/engines.md), so
// only the contact *solution* is ODE's here; the geometry is the same as native's.
// Settings that matter (measured in the notes):
//  - QuickStep: dWorldStep caps friction at mu times the frictionless normal impulse and never
//    updates the cap, wrong whenever friction slides; it also fails on packs;
//  - dContactApprox1: otherwise mu is a force limit in newtons;
//  - friction along the in-plane tangent only (fdir1, mu2 = 0): the second direction is z;
//  - CFM tiny: the CFM error is about CFM / (dt W), W the effective inverse mass;
//  - the ERP correction velocity capped: ODE takes the larger of the bounce and the
//    correction, so an uncapped correction inflates restitution (erp 0.8 gave e = 0.5);
//  - the plane-2D joint drifts unless each step resets the rotation's x/y parts and the
//    angular velocity's x/y (tilt 3e-5 rad otherwise).
#include "reference/ode/ode_engine.hpp"

#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <mutex>

#include "contacts/collision_forces.hpp"
#include "scenario/table_reader.hpp"
#include "collision/broad_phase.hpp"
#include "collision/part_set.hpp"
#include "reference/adapter.hpp"

namespace floedem {

namespace {

struct OdeSettings {
  bool quick_step = true;  ///< dWorldQuickStep; "world" = dWorldStep (dense LCP: see above)
  int iterations = 50;
  double cfm = 1e-16;
  double erp = 0.2;
  double max_correcting_velocity = 0.01;  ///< m/s
  /// "impulse" (Newton restitution, the default) or "compliant": each contact a linear spring
  /// k = (pi / C_tau)^2 with a dashpot of damping ratio zeta from the restitution (below), as
  /// ODE's soft ERP/CFM, so that collisions last and their duration can be measured.
  bool compliant = false;
};

OdeSettings read_settings(const Scene& scene) {
  OdeSettings s;
  reference::read_settings(scene, "ode", [&](TableReader& r) {
    s.quick_step = r.string("step", "quick", {"quick", "world"}) == "quick";
    s.iterations = static_cast<int>(r.integer("iterations", s.iterations, 1, 100000));
    s.cfm = r.real("cfm", s.cfm, Range::non_negative());
    s.erp = r.real("erp", s.erp, Range::closed(0.0, 1.0));
    s.max_correcting_velocity = r.real("max_correcting_velocity", s.max_correcting_velocity, Range::non_negative());
    s.compliant = r.string("contact_model", "impulse", {"impulse", "compliant"}) == "compliant";
  });
  return s;
}

class OdeEngine final : public Engine {
 public:
  explicit OdeEngine(const Scene& scene);
  ~OdeEngine() override;
  void step(const Loads* loads) override;
  const BodyStates& state() const override { return state_; }
  std::span<const ContactRecord> contacts() const override { return records_; }
  EngineInfo info() const override;

 private:
  struct Pending {
    dJointID joint;
    ContactRecord record;
    bool b_is_body1;  // else a is body 1 (b is static)
  };
  void publish();
  void keep_in_plane();

  OdeSettings settings_;
  double dt_;
  ContactSettings contact_;
  dWorldID world_ = nullptr;
  dJointGroupID contact_group_ = nullptr;
  unsigned long random_seed_ = 0;  ///< QuickStep's constraint shuffle (ODE's initial seed is 0)
  std::vector<dBodyID> bodies_;  // nullptr for fixed bodies
  std::vector<Vec2> fixed_position_;
  PartSet parts_;
  BroadPhase broad_phase_;
  std::vector<PartPair> pairs_;
  std::vector<Rot> rotation_;
  std::vector<dJointFeedback> feedback_;
  std::vector<Pending> pending_;
  std::vector<ContactRecord> records_;
  BodyStates state_;
  double max_out_of_plane_ = 0.0;
  CompliantContacts compliance_;  ///< used when settings_.compliant
};

OdeEngine::OdeEngine(const Scene& scene)
    : settings_(read_settings(scene)), dt_(scene.run.dt), contact_(scene.contact), parts_(scene), compliance_(scene) {
  static std::once_flag init;
  std::call_once(init, [] { dInitODE2(0); });
  world_ = dWorldCreate();
  dWorldSetGravity(world_, 0, 0, 0);
  dWorldSetCFM(world_, settings_.cfm);
  dWorldSetERP(world_, settings_.erp);
  // A compliant contact is all correction: its spring must not be capped.
  dWorldSetContactMaxCorrectingVel(world_, settings_.compliant ? dInfinity : settings_.max_correcting_velocity);
  dWorldSetQuickStepNumIterations(world_, settings_.iterations);
  dWorldSetAutoDisableFlag(world_, 0);
  contact_group_ = dJointGroupCreate(0);
  const std::size_t n = scene.bodies.size();
  for (std::size_t i = 0; i < n; ++i) {
    const BodySpec& b = scene.bodies[i];
    fixed_position_.push_back(b.centroid);
    if (b.fixed) {
      bodies_.push_back(nullptr);
      continue;
    }
    dBodyID body = dBodyCreate(world_);
    dBodySetPosition(body, b.centroid.x, b.centroid.y, 0.0);
    dBodySetLinearVel(body, b.velocity.x, b.velocity.y, 0.0);
    dBodySetAngularVel(body, 0.0, 0.0, b.angular_velocity);
    if (b.prescribed) {
      dBodySetKinematic(body);
    } else {
      dMass m;
      const double izz = scene.engine_inertia(i);
      // Only I_zz matters in the plane; the others are set equal to keep the tensor valid.
      dMassSetParameters(&m, scene.engine_mass(i), 0, 0, 0, izz, izz, izz, 0, 0, 0);
      dBodySetMass(body, &m);
      dJointID plane = dJointCreatePlane2D(world_, 0);
      dJointAttach(plane, body, nullptr);
    }
    bodies_.push_back(body);
  }
  rotation_.resize(n);
  state_.resize(n);
  publish();
}

OdeEngine::~OdeEngine() {
  dJointGroupDestroy(contact_group_);
  dWorldDestroy(world_);
}

EngineInfo OdeEngine::info() const {
  EngineInfo i;
  i.name = "ode";
  i.version = "0.16 (double)";
  i.settings = {{"iterations", std::to_string(settings_.iterations)},
                {"step", settings_.quick_step ? "dWorldQuickStep" : "dWorldStep"},
                {"cfm", setting_text(settings_.cfm)},
                {"erp", setting_text(settings_.erp)},
                {"max_correcting_velocity", setting_text(settings_.max_correcting_velocity)},
                {"contact_model", settings_.compliant ? "compliant" : "impulse"},
                {"friction", "dContactApprox1, in-plane tangent only"},
                {"contact_geometry", "floedem 2-D narrow phase"},
                {"max_out_of_plane", setting_text(max_out_of_plane_)}};
  if (settings_.compliant) compliance_.describe(i.settings);
  i.limitations = {"contact points from floedem's 2-D narrow phase, not ODE's colliders (one point per step for convex prisms)",
                   "contacts found only once bodies touch (no speculative contact): impacts resolve after up to v dt of overlap"};
  return i;
}

void OdeEngine::step(const Loads* loads) {
  // Contact points at the start of the step, from floedem's narrow phase.
  for (std::size_t i = 0; i < bodies_.size(); ++i) rotation_[i] = Rot::from_angle(state_.angle[i]);
  parts_.place(state_.position, rotation_);
  broad_phase_.find_pairs(parts_.boxes(), parts_.body(), parts_.immovable(), pairs_);
  pending_.clear();
  feedback_.resize(0);
  feedback_.reserve(2 * pairs_.size());
  for (const PartPair& pair : pairs_) {
    const std::int32_t a = parts_.body()[pair.a], b = parts_.body()[pair.b];
    Manifold m;
    const double touch = 1e-9 * (parts_.radius(pair.a) + parts_.radius(pair.b));  // round-off of touching
    collide(parts_.geometry(pair.a, state_.position[a], rotation_[a]), parts_.geometry(pair.b, state_.position[b], rotation_[b]),
            touch, 1e-6, m);
    for (int k = 0; k < m.point_count; ++k) {
      const ManifoldPoint& p = m.points[k];
      const bool b_is_body1 = bodies_[b] != nullptr;
      dContact c{};
      c.surface.mode = dContactBounce | dContactSoftCFM | dContactApprox1 | dContactFDir1 | dContactMu2;
      c.surface.mu = contact_.friction;
      c.surface.mu2 = 0.0;
      c.surface.bounce = contact_.restitution;
      c.surface.bounce_vel = contact_.collision_threshold;
      c.surface.soft_cfm = settings_.cfm;
      if (settings_.compliant) {
        // The pair's spring k and dashpot c shared by the manifold's points (contacts/
        // collision_forces.hpp), as ODE's implicit spring-damper: ERP = h k / (h k + c),
        // CFM = 1 / (h k + c) (ODE manual, "Soft constraint and constraint force mixing").
        Vec2 middle;
        for (int q = 0; q < m.point_count; ++q) middle += (1.0 / m.point_count) * m.points[q].point;
        const auto [stiffness, damping] = compliance_.per_point(static_cast<std::size_t>(a), static_cast<std::size_t>(b), m.normal,
                                                                middle - state_.position[a], middle - state_.position[b],
                                                                m.point_count);
        c.surface.mode = dContactSoftERP | dContactSoftCFM | dContactApprox1 | dContactFDir1 | dContactMu2;
        c.surface.soft_erp = dt_ * stiffness / (dt_ * stiffness + damping);
        c.surface.soft_cfm = 1.0 / (dt_ * stiffness + damping);
      }
      // ODE: moving body 1 along the normal by depth separates the bodies.
      const Vec2 normal = b_is_body1 ? m.normal : -m.normal;
      c.geom.pos[0] = p.point.x;
      c.geom.pos[1] = p.point.y;
      c.geom.pos[2] = 0.0;
      c.geom.normal[0] = normal.x;
      c.geom.normal[1] = normal.y;
      c.geom.normal[2] = 0.0;
      c.geom.depth = std::max(0.0, -p.separation);
      const Vec2 t = perp(normal);
      c.fdir1[0] = t.x;
      c.fdir1[1] = t.y;
      c.fdir1[2] = 0.0;
      dJointID j = dJointCreateContact(world_, contact_group_, &c);
      if (b_is_body1)
        dJointAttach(j, bodies_[b], bodies_[a]);
      else
        dJointAttach(j, bodies_[a], nullptr);
      ContactRecord r;
      r.body_a = a;
      r.body_b = b;
      r.point = p.point;
      r.normal = m.normal;
      r.separation = p.separation;
      reference::classify(r, state_, contact_.collision_threshold);
      pending_.push_back({j, r, b_is_body1});
    }
  }
  for (Pending& p : pending_) {
    feedback_.push_back(dJointFeedback{});
    dJointSetFeedback(p.joint, &feedback_.back());
  }
  if (loads)
    reference::hand_loads(
        *loads, bodies_.size(), [&](std::size_t i) { return bodies_[i] && !dBodyIsKinematic(bodies_[i]); },
        [&](const PrescribedMotion& p) {
          dBodySetLinearVel(bodies_[p.body], p.velocity.x, p.velocity.y, 0.0);
          dBodySetAngularVel(bodies_[p.body], 0.0, 0.0, p.angular_velocity);
        },
        [&](std::size_t i) {
          const dReal* v = dBodyGetLinearVel(bodies_[i]);
          return Vec2{v[0], v[1]};
        },
        [&](std::size_t i, Vec2 v) { dBodySetLinearVel(bodies_[i], v.x, v.y, 0.0); },
        [&](std::size_t i, Vec2 force, double torque) {
          dBodyAddForce(bodies_[i], force.x, force.y, 0.0);
          dBodyAddTorque(bodies_[i], 0.0, 0.0, torque);
        });
  // QuickStep shuffles its constraint order with ODE's one global random generator, so a
  // second world in the same process (a test, a sweep) would continue the first one's stream
  // and give another result. Each engine keeps its own seed across steps instead: a run is
  // the same wherever it is made.
  dRandSetSeed(random_seed_);
  if (settings_.quick_step)
    dWorldQuickStep(world_, dt_);
  else
    dWorldStep(world_, dt_);
  random_seed_ = dRandGetSeed();
  keep_in_plane();
  // Impulses: the joints' forces on body 1 times dt.
  records_.clear();
  for (std::size_t k = 0; k < pending_.size(); ++k) {
    const dJointFeedback& f = feedback_[k];
    ContactRecord r = pending_[k].record;
    const Vec2 on_body1{f.f1[0] * dt_, f.f1[1] * dt_};
    const Vec2 on_b = pending_[k].b_is_body1 ? on_body1 : -on_body1;
    r.normal_impulse = dot(on_b, r.normal);
    r.tangent_impulse = dot(on_b, perp(r.normal));
    if (r.normal_impulse != 0.0 || r.tangent_impulse != 0.0) records_.push_back(r);
  }
  dJointGroupEmpty(contact_group_);
  publish();
}

void OdeEngine::keep_in_plane() {
  for (dBodyID b : bodies_) {
    if (!b) continue;
    const dReal* r = dBodyGetRotation(b);
    const dReal* p = dBodyGetPosition(b);
    const dReal* w = dBodyGetAngularVel(b);
    max_out_of_plane_ = std::max({max_out_of_plane_, std::abs(p[2]), std::abs(r[8]), std::abs(r[9])});  // z, tilt
    const double angle = std::atan2(r[4], r[0]);
    dMatrix3 rz;
    dRFromAxisAndAngle(rz, 0, 0, 1, angle);
    dBodySetRotation(b, rz);
    dBodySetAngularVel(b, 0, 0, w[2]);
    dBodySetPosition(b, p[0], p[1], 0.0);
    const dReal* v = dBodyGetLinearVel(b);
    dBodySetLinearVel(b, v[0], v[1], 0.0);
  }
}

void OdeEngine::publish() {
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    const dBodyID b = bodies_[i];
    if (!b) {
      state_.position[i] = fixed_position_[i];
      continue;
    }
    const dReal* p = dBodyGetPosition(b);
    const dReal* r = dBodyGetRotation(b);
    const dReal* v = dBodyGetLinearVel(b);
    const dReal* w = dBodyGetAngularVel(b);
    state_.position[i] = {p[0], p[1]};
    state_.angle[i] = std::atan2(r[4], r[0]);
    state_.velocity[i] = {v[0], v[1]};
    state_.angular_velocity[i] = w[2];
  }
}

}  // namespace

std::unique_ptr<Engine> make_ode_engine(const Scene& scene) { return std::make_unique<OdeEngine>(scene); }

}  // namespace floedem
