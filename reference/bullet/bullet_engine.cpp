// Bullet 3.24 (double precision) as a reference engine: each convex part an extruded prism
// (btConvexHullShape), held in the plane by linear factor (1, 1, 0) and angular factor
// (0, 0, 1), mass and planar inertia set to floedem's values.
// Settings that matter (measured in docs/engines.md; Bullet's defaults give
// e = 0.22, 0.62, or 0 instead of 0.3 on the same impact):
//  - restitution of a pair = max, friction = min (the default multiplies both: mu 0.3 -> 0.09);
//  - split impulse on for any penetration (m_splitImpulsePenetrationThreshold = 0), so that
//    the penetration push does not add to the bounce;
//  - contact processing threshold 0 and a restitution velocity threshold of the scene's
//    collision threshold (default 0.2 m/s kills drift-speed bounces);
//  - hull points moved inward by the collision margin (the margin lies outside the hull:
//    bodies would start overlapped);
//  - stepSimulation(dt, 0): one step of exactly dt (the default is fixed 1/60 s substeps);
//  - the prism is far taller than any overlap can get: otherwise a deep sideways overlap picks
//    a normal along z, which the plane constraint absorbs, and floes pass through each other;
//  - only points with distance <= 0 are read: getAppliedImpulse() keeps stale values on
//    points that were not solved this step.
#include "reference/bullet/bullet_engine.hpp"

#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>

#include "contacts/collision_forces.hpp"
#include "geometry/polygon.hpp"
#include "reference/adapter.hpp"
#include "scenario/table_reader.hpp"

namespace floedem {

namespace {

struct BulletSettings {
  int iterations = 50;
  double margin = 0.01;  ///< m, collision margin
  /// "impulse" (restitution, the default) or "compliant": each contact a linear spring
  /// k = (pi / C_tau)^2 with a dashpot of damping ratio zeta(e), through Bullet's contact
  /// stiffness and damping (CFM = 1 / (dt k + c), ERP = dt k / (dt k + c)), split impulse off
  /// (it would turn the spring's push into a position correction without momentum).
  bool compliant = false;
};

BulletSettings read_settings(const Scene& scene) {
  BulletSettings s;
  reference::read_settings(scene, "bullet", [&](TableReader& r) {
    s.iterations = static_cast<int>(r.integer("iterations", s.iterations, 1, 100000));
    s.margin = r.real("margin", s.margin, Range::positive());
    s.compliant = r.string("contact_model", "impulse", {"impulse", "compliant"}) == "compliant";
  });
  return s;
}

btScalar combined_restitution(const btCollisionObject* a, const btCollisionObject* b) {
  return std::max(a->getRestitution(), b->getRestitution());
}
btScalar combined_friction(const btCollisionObject* a, const btCollisionObject* b) {
  return std::min(a->getFriction(), b->getFriction());
}

/// The dynamics world with a hook between collision detection and the solver (where the
/// compliant model sets each contact point's spring and dashpot).
class PlanarWorld final : public btDiscreteDynamicsWorld {
 public:
  using btDiscreteDynamicsWorld::btDiscreteDynamicsWorld;
  std::function<void()> before_solve;
  void solveConstraints(btContactSolverInfo& info) override {
    if (before_solve) before_solve();
    btDiscreteDynamicsWorld::solveConstraints(info);
  }
};

class BulletEngine final : public Engine {
 public:
  explicit BulletEngine(const Scene& scene);
  ~BulletEngine() override;
  void step(const Loads* loads) override;
  const BodyStates& state() const override { return state_; }
  std::span<const ContactRecord> contacts() const override { return records_; }
  EngineInfo info() const override;

 private:
  void publish();
  void collect_contacts();
  void set_compliance();

  BulletSettings settings_;
  double dt_;
  double threshold_;
  double height_ = 0.0;  // prism height, m
  btDefaultCollisionConfiguration configuration_;
  btCollisionDispatcher dispatcher_{&configuration_};
  btDbvtBroadphase broadphase_;
  btSequentialImpulseConstraintSolver solver_;
  PlanarWorld world_{&dispatcher_, &broadphase_, &solver_, &configuration_};
  std::vector<std::unique_ptr<btCollisionShape>> shapes_;
  std::vector<std::unique_ptr<btDefaultMotionState>> motion_states_;
  std::vector<std::unique_ptr<btRigidBody>> bodies_;
  std::vector<std::uint8_t> kinematic_;
  BodyStates state_, before_;
  std::vector<ContactRecord> records_;
  double max_out_of_plane_ = 0.0;  // m and rad, over the run
  CompliantContacts compliance_;  // used when settings_.compliant
};

BulletEngine::BulletEngine(const Scene& scene)
    : settings_(read_settings(scene)), dt_(scene.run.dt), threshold_(scene.contact.collision_threshold), compliance_(scene) {
  gCalculateCombinedRestitutionCallback = combined_restitution;
  gCalculateCombinedFrictionCallback = combined_friction;
  world_.setGravity(btVector3(0, 0, 0));
  btContactSolverInfo& info = world_.getSolverInfo();
  info.m_numIterations = settings_.iterations;
  info.m_splitImpulse = settings_.compliant ? 0 : 1;
  info.m_splitImpulsePenetrationThreshold = 0;
  if (settings_.compliant) world_.before_solve = [this] { set_compliance(); };
  info.m_restitutionVelocityThreshold = threshold_;

  // Taller than any overlap can get: four times the largest body.
  for (const BodySpec& b : scene.bodies) {
    const Aabb box = bounds_of(b.local_polygon);
    height_ = std::max(height_, 4.0 * length(box.hi - box.lo));
  }
  const double m = settings_.margin;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const BodySpec& spec = scene.bodies[i];
    std::vector<btCollisionShape*> hulls;
    for (const auto& part : spec.local_parts) {
      auto hull = std::make_unique<btConvexHullShape>();
      for (const Vec2 p : inset_convex(part, m))
        for (const double z : {-0.5 * height_ + m, 0.5 * height_ - m}) hull->addPoint(btVector3(p.x, p.y, z), false);
      hull->recalcLocalAabb();
      hull->setMargin(m);
      hulls.push_back(hull.get());
      shapes_.push_back(std::move(hull));
    }
    btCollisionShape* shape = hulls.front();
    if (hulls.size() > 1) {
      auto compound = std::make_unique<btCompoundShape>();
      btTransform identity;
      identity.setIdentity();
      for (btCollisionShape* h : hulls) compound->addChildShape(identity, h);
      shape = compound.get();
      shapes_.push_back(std::move(compound));
    }
    btTransform start;
    start.setIdentity();
    start.setOrigin(btVector3(spec.centroid.x, spec.centroid.y, 0));
    motion_states_.push_back(std::make_unique<btDefaultMotionState>(start));
    const bool dynamic = !spec.fixed && !spec.prescribed;
    const double mass = dynamic ? scene.engine_mass(i) : 0.0;
    const double izz = scene.engine_inertia(i);
    // Only I_zz matters: the angular factor (0, 0, 1) removes the other axes.
    btRigidBody::btRigidBodyConstructionInfo ci(mass, motion_states_.back().get(), shape,
                                                dynamic ? btVector3(izz, izz, izz) : btVector3(0, 0, 0));
    ci.m_restitution = settings_.compliant ? 0.0 : scene.contact.restitution;
    ci.m_friction = scene.contact.friction;
    ci.m_linearDamping = 0;
    ci.m_angularDamping = 0;
    auto body = std::make_unique<btRigidBody>(ci);
    body->setLinearFactor(btVector3(1, 1, 0));
    body->setAngularFactor(btVector3(0, 0, 1));
    body->setLinearVelocity(btVector3(spec.velocity.x, spec.velocity.y, 0));
    body->setAngularVelocity(btVector3(0, 0, spec.angular_velocity));
    body->setActivationState(DISABLE_DEACTIVATION);
    body->setContactProcessingThreshold(0);
    body->setUserIndex(static_cast<int>(i));
    if (spec.prescribed) body->setCollisionFlags(body->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
    kinematic_.push_back(spec.prescribed ? 1 : 0);
    world_.addRigidBody(body.get());
    bodies_.push_back(std::move(body));
  }
  state_.resize(bodies_.size());
  publish();
}

BulletEngine::~BulletEngine() {
  for (auto& b : bodies_) world_.removeRigidBody(b.get());
}

EngineInfo BulletEngine::info() const {
  EngineInfo i;
  i.name = "bullet";
  i.version = std::to_string(btGetVersion() / 100) + "." + std::to_string(btGetVersion() % 100) + " (double)";
  i.settings = {{"iterations", std::to_string(settings_.iterations)},
                {"margin", setting_text(settings_.margin)},
                {"prism_height", setting_text(height_)},
                {"split_impulse", settings_.compliant ? "off" : "on, threshold 0"},
                {"contact_model", settings_.compliant ? "compliant" : "impulse"},
                {"restitution_velocity_threshold", setting_text(threshold_)},
                {"combine", "restitution max, friction min"},
                {"max_out_of_plane", setting_text(max_out_of_plane_)}};
  if (settings_.compliant) compliance_.describe(i.settings);
  i.limitations = {"bodies are prisms held in the plane by linear and angular factors",
                   "up to 4 contact points per pair, top and bottom of the prism (compare impulses summed per pair)"};
  return i;
}

void BulletEngine::step(const Loads* loads) {
  before_ = state_;
  if (loads)
    reference::hand_loads(
        *loads, bodies_.size(), [&](std::size_t i) { return bodies_[i]->getInvMass() != 0; },
        [&](const PrescribedMotion& p) {
          // Kinematic bodies: Bullet takes their velocity from the motion state's change.
          btRigidBody* b = bodies_[p.body].get();
          btTransform t = b->getWorldTransform();
          t.setOrigin(t.getOrigin() + btVector3(p.velocity.x, p.velocity.y, 0) * dt_);
          b->getMotionState()->setWorldTransform(t);
        },
        [&](std::size_t i) {
          const btVector3& v = bodies_[i]->getLinearVelocity();
          return Vec2{v.x(), v.y()};
        },
        [&](std::size_t i, Vec2 v) { bodies_[i]->setLinearVelocity(btVector3(v.x, v.y, 0)); },
        [&](std::size_t i, Vec2 force, double torque) {
          bodies_[i]->applyCentralForce(btVector3(force.x, force.y, 0));
          bodies_[i]->applyTorque(btVector3(0, 0, torque));
        });
  world_.stepSimulation(dt_, 0);
  publish();
  collect_contacts();
}

void BulletEngine::set_compliance() {
  // Per pair: spring and dashpot shared by its touching points (up to four: the prism's top
  // and bottom), from the points' middle (contacts/collision_forces.hpp).
  const int manifolds = dispatcher_.getNumManifolds();
  for (int k = 0; k < manifolds; ++k) {
    btPersistentManifold* pm = dispatcher_.getManifoldByIndexInternal(k);
    const int i0 = pm->getBody0()->getUserIndex(), i1 = pm->getBody1()->getUserIndex();
    int touching = 0;
    Vec2 middle;
    for (int j = 0; j < pm->getNumContacts(); ++j) {
      const btManifoldPoint& pt = pm->getContactPoint(j);
      if (pt.getDistance() > 0) continue;
      const btVector3 p = 0.5 * (pt.getPositionWorldOnA() + pt.getPositionWorldOnB());
      middle += Vec2{p.x(), p.y()};
      ++touching;
    }
    if (touching == 0) continue;
    middle = (1.0 / touching) * middle;
    const auto centre = [&](int i) {
      const btVector3& c = bodies_[static_cast<std::size_t>(i)]->getCenterOfMassPosition();
      return Vec2{c.x(), c.y()};
    };
    const btVector3& nb = pm->getContactPoint(0).m_normalWorldOnB;
    const auto [stiffness, damping] = compliance_.per_point(static_cast<std::size_t>(i0), static_cast<std::size_t>(i1),
                                                            {nb.x(), nb.y()}, middle - centre(i0), middle - centre(i1),
                                                            touching);
    for (int j = 0; j < pm->getNumContacts(); ++j) {
      btManifoldPoint& pt = pm->getContactPoint(j);
      pt.m_combinedContactStiffness1 = stiffness;
      pt.m_combinedContactDamping1 = damping;
      pt.m_contactPointFlags |= BT_CONTACT_FLAG_CONTACT_STIFFNESS_DAMPING;
    }
  }
}

void BulletEngine::collect_contacts() {
  records_.clear();
  const int manifolds = dispatcher_.getNumManifolds();
  for (int k = 0; k < manifolds; ++k) {
    const btPersistentManifold* pm = dispatcher_.getManifoldByIndexInternal(k);
    const int i0 = pm->getBody0()->getUserIndex(), i1 = pm->getBody1()->getUserIndex();
    for (int j = 0; j < pm->getNumContacts(); ++j) {
      const btManifoldPoint& pt = pm->getContactPoint(j);
      if (pt.getDistance() > 0) continue;  // not solved this step: its impulse is stale
      // Bullet pushes body 0 along m_normalWorldOnB: the normal from body 0 towards body 1 is
      // its opposite, and body 1 takes the opposite of body 0's impulse.
      const btVector3 on0 = pt.m_appliedImpulse * pt.m_normalWorldOnB + pt.m_appliedImpulseLateral1 * pt.m_lateralFrictionDir1 +
                            pt.m_appliedImpulseLateral2 * pt.m_lateralFrictionDir2;
      if (on0.length2() == 0) continue;
      const Vec2 n0{pt.m_normalWorldOnB.x(), pt.m_normalWorldOnB.y()};
      const btVector3 p = 0.5 * (pt.getPositionWorldOnA() + pt.getPositionWorldOnB());
      ContactRecord r = reference::oriented_record(i0, i1, {p.x(), p.y()}, normalized(-n0), Vec2{-on0.x(), -on0.y()},
                                                   pt.getDistance());
      reference::classify(r, before_, threshold_);
      records_.push_back(r);
    }
  }
}

void BulletEngine::publish() {
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    const btRigidBody* b = bodies_[i].get();
    const btTransform& t = b->getWorldTransform();
    btScalar yaw, pitch, roll;
    t.getBasis().getEulerZYX(yaw, pitch, roll);
    state_.position[i] = {t.getOrigin().x(), t.getOrigin().y()};
    state_.angle[i] = yaw;
    state_.velocity[i] = {b->getLinearVelocity().x(), b->getLinearVelocity().y()};
    state_.angular_velocity[i] = b->getAngularVelocity().z();
    max_out_of_plane_ = std::max({max_out_of_plane_, std::abs(t.getOrigin().z()), std::abs(pitch), std::abs(roll)});
  }
}

}  // namespace

std::unique_ptr<Engine> make_bullet_engine(const Scene& scene) { return std::make_unique<BulletEngine>(scene); }

}  // namespace floedem
