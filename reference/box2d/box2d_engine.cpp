// Box2D 2.4 as a reference engine: the scene's polygons themselves (convex parts of at most
// 8 vertices), mass and inertia set to floedem's values, not Box2D's.
// Settings that matter (measured in docs/engines.md):
//  - restitution threshold 0 on every fixture: the default 1 m/s turns every drift-speed
//    impact into e = 0;
//  - polygon radius 0: the default 0.01 m skin moves the contact point off the vertex and
//    changes the friction lever arm (errors 6e-4 to 2e-3 against the exact answer);
//  - no sleeping, no continuous collision (not needed at drift speeds, and a large part of
//    the step's cost);
//  - single precision: coordinates are taken relative to the scene's mean centroid.
#include "reference/box2d/box2d_engine.hpp"

#include <box2d/box2d.h>

#include <algorithm>
#include <unordered_map>

#include "geometry/polygon.hpp"
#include "reference/adapter.hpp"
#include "floedem/run/simulation.hpp"
#include "scenario/table_reader.hpp"

namespace floedem {

namespace {

struct Box2dSettings {
  int velocity_iterations = 10;
  int position_iterations = 3;
  double polygon_radius = 0.0;  ///< m
};

Box2dSettings read_settings(const Scene& scene) {
  Box2dSettings s;
  reference::read_settings(scene, "box2d", [&](TableReader& r) {
    s.velocity_iterations = static_cast<int>(r.integer("velocity_iterations", s.velocity_iterations, 1, 100000));
    s.position_iterations = static_cast<int>(r.integer("position_iterations", s.position_iterations, 0, 100000));
    s.polygon_radius = r.real("polygon_radius", s.polygon_radius, Range::non_negative());
  });
  return s;
}

class Box2dEngine final : public Engine, public b2ContactListener {
 public:
  explicit Box2dEngine(const Scene& scene);
  void step(const Loads* loads) override;
  const BodyStates& state() const override { return state_; }
  std::span<const ContactRecord> contacts() const override { return records_; }
  EngineInfo info() const override;
  void time_stages(bool on) override { adapter_stages_.enable(on); }
  void add_stage_times(std::vector<StageTime>& out) const override;

  // b2ContactListener
  void PreSolve(b2Contact* contact, const b2Manifold* old_manifold) override;
  void PostSolve(b2Contact* contact, const b2ContactImpulse* impulse) override;

 private:
  void apply_loads(const Loads& loads);
  void publish();
  Vec2 point_velocity(const b2Body* b, b2Vec2 p) const {
    const b2Vec2 v = b->GetLinearVelocityFromWorldPoint(p);
    return {v.x, v.y};
  }

  Box2dSettings settings_;
  double dt_;
  double threshold_;
  Vec2 origin_;  // world = origin + Box2D coordinates
  b2World world_{b2Vec2(0.0f, 0.0f)};
  std::vector<b2Body*> bodies_;
  std::unordered_map<const b2Body*, std::int32_t> index_;
  // Approach velocities by contact, filled in PreSolve (collide phase) and looked up in
  // PostSolve (solve phase, another order): a vector sorted once between the two, so that a
  // step allocates nothing once it has grown (a hash map allocated a node per contact).
  std::vector<std::pair<const b2Contact*, std::array<double, 2>>> approach_;
  bool approach_sorted_ = false;
  std::vector<ContactRecord> records_;
  BodyStates state_;
  // Stage times (floedem bench): the adapter's own work around b2World::Step, and Box2D's
  // b2Profile of each step (its own timers, which run whether or not they are read), summed.
  enum AdapterStage : std::size_t { kLoads, kPublish, kAdapterStages };
  StageClock<kAdapterStages> adapter_stages_{{"loads", "publish"}};
  struct ProfileSums {
    double collide = 0.0, broadphase = 0.0, solve = 0.0, solve_init = 0.0, solve_velocity = 0.0,
           solve_position = 0.0, toi = 0.0, step = 0.0;  // ms
  } profile_;
};

Box2dEngine::Box2dEngine(const Scene& scene)
    : settings_(read_settings(scene)), dt_(scene.run.dt), threshold_(scene.contact.collision_threshold) {
  for (const BodySpec& b : scene.bodies) origin_ += b.centroid;
  origin_ = (1.0 / static_cast<double>(scene.bodies.size())) * origin_;
  world_.SetAllowSleeping(false);
  world_.SetContinuousPhysics(false);
  world_.SetContactListener(this);
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const BodySpec& spec = scene.bodies[i];
    b2BodyDef def;
    def.type = spec.fixed ? b2_staticBody : spec.prescribed ? b2_kinematicBody : b2_dynamicBody;
    def.position.Set(static_cast<float>(spec.centroid.x - origin_.x), static_cast<float>(spec.centroid.y - origin_.y));
    def.angle = 0.0f;
    def.linearVelocity.Set(static_cast<float>(spec.velocity.x), static_cast<float>(spec.velocity.y));
    def.angularVelocity = static_cast<float>(spec.angular_velocity);
    def.allowSleep = false;
    b2Body* body = world_.CreateBody(&def);
    for (const auto& part : spec.local_parts) {
      for (const auto& piece : split_convex(part, b2_maxPolygonVertices)) {
        std::vector<b2Vec2> pts;
        for (const Vec2 p : piece) pts.emplace_back(static_cast<float>(p.x), static_cast<float>(p.y));
        b2PolygonShape shape;
        shape.Set(pts.data(), static_cast<int32>(pts.size()));
        shape.m_radius = static_cast<float>(settings_.polygon_radius);
        b2FixtureDef fd;
        fd.shape = &shape;
        fd.density = 1.0f;  // replaced by SetMassData below
        fd.friction = static_cast<float>(scene.contact.friction);
        fd.restitution = static_cast<float>(scene.contact.restitution);
        fd.restitutionThreshold = 0.0f;
        body->CreateFixture(&fd);
      }
    }
    if (def.type == b2_dynamicBody) {
      b2MassData md;
      md.mass = static_cast<float>(scene.engine_mass(i));
      md.center.SetZero();  // the body origin is the polygon's centroid
      md.I = static_cast<float>(scene.engine_inertia(i));
      body->SetMassData(&md);
    }
    index_[body] = static_cast<std::int32_t>(i);
    bodies_.push_back(body);
  }
  state_.resize(bodies_.size());
  publish();
}

EngineInfo Box2dEngine::info() const {
  EngineInfo i;
  i.name = "box2d";
  i.version = std::to_string(b2_version.major) + "." + std::to_string(b2_version.minor) + "." +
              std::to_string(b2_version.revision);
  i.settings = {{"velocity_iterations", std::to_string(settings_.velocity_iterations)},
                {"position_iterations", std::to_string(settings_.position_iterations)},
                {"polygon_radius", setting_text(settings_.polygon_radius)},
                {"restitution_threshold", "0"},
                {"sleeping", "off"},
                {"continuous_collision", "off"}};
  i.limitations = {"a body may move at most 2 m (b2_maxTranslation) and turn pi/2 per step: longer steps are refused",
                   "single precision (coordinates relative to the scene's mean centroid)",
                   "friction of a pair mixes as sqrt(mu_a mu_b) (equal here: one mu per scene)",
                   "position correction by Box2D's own nonlinear Gauss-Seidel (linear slop 0.005 m)"};
  return i;
}

void Box2dEngine::PreSolve(b2Contact* contact, const b2Manifold*) {
  // Normal approach velocity of each point before the step (the solve has not run yet).
  b2WorldManifold wm;
  contact->GetWorldManifold(&wm);
  const b2Body* a = contact->GetFixtureA()->GetBody();
  const b2Body* b = contact->GetFixtureB()->GetBody();
  std::array<double, 2> u{0.0, 0.0};
  for (int k = 0; k < contact->GetManifold()->pointCount; ++k)
    u[k] = dot(point_velocity(b, wm.points[k]) - point_velocity(a, wm.points[k]), Vec2{wm.normal.x, wm.normal.y});
  approach_.emplace_back(contact, u);
  approach_sorted_ = false;
}

void Box2dEngine::PostSolve(b2Contact* contact, const b2ContactImpulse* impulse) {
  b2WorldManifold wm;
  contact->GetWorldManifold(&wm);
  const std::int32_t ia = index_.at(contact->GetFixtureA()->GetBody());
  const std::int32_t ib = index_.at(contact->GetFixtureB()->GetBody());
  const Vec2 n{wm.normal.x, wm.normal.y};  // from A to B
  const Vec2 t{n.y, -n.x};                 // Box2D's tangent: b2Cross(normal, 1)
  if (!approach_sorted_) {
    std::sort(approach_.begin(), approach_.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    approach_sorted_ = true;
  }
  const auto at = std::lower_bound(approach_.begin(), approach_.end(), contact,
                                   [](const auto& x, const b2Contact* c) { return x.first < c; });
  const std::array<double, 2>* found = at != approach_.end() && at->first == contact ? &at->second : nullptr;
  // impulse->count, not the manifold's point count: Box2D solves a two-point manifold whose
  // block system is ill-conditioned as one point (b2ContactSolver sets pointCount = 1) and then
  // reports one impulse; the second slot is left uninitialised (read here, it made runs differ).
  const int count = std::min(impulse->count, contact->GetManifold()->pointCount);
  for (int k = 0; k < count; ++k) {
    const double pn = impulse->normalImpulses[k], pt = impulse->tangentImpulses[k];
    if (pn == 0.0 && pt == 0.0) continue;
    // Box2D: the normal from A to B, the impulses on B.
    ContactRecord r = reference::oriented_record(ia, ib, origin_ + Vec2{wm.points[k].x, wm.points[k].y}, n,
                                                 pn * n + pt * t, wm.separations[k]);
    r.approach_velocity = found ? (*found)[k] : 0.0;
    r.kind = r.approach_velocity < -threshold_ ? ContactKind::collision : ContactKind::resting;
    records_.push_back(r);
  }
}

void Box2dEngine::step(const Loads* loads) {
  records_.clear();
  approach_.clear();
  if (loads) adapter_stages_.time(kLoads, [&] { apply_loads(*loads); });
  world_.Step(static_cast<float>(dt_), settings_.velocity_iterations, settings_.position_iterations);
  if (adapter_stages_.enabled()) {
    const b2Profile& p = world_.GetProfile();
    profile_.collide += p.collide;
    profile_.broadphase += p.broadphase;
    profile_.solve += p.solve;
    profile_.solve_init += p.solveInit;
    profile_.solve_velocity += p.solveVelocity;
    profile_.solve_position += p.solvePosition;
    profile_.toi += p.solveTOI;
    profile_.step += p.step;
  }
  adapter_stages_.time(kPublish, [&] { publish(); });
  // Box2D clamps a body's motion per step at b2_maxTranslation (2 m) and b2_maxRotation
  // (pi/2) without a word: refuse rather than return a silently slowed run.
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    const double move = length(state_.velocity[i]) * dt_;
    const double turn = std::abs(state_.angular_velocity[i]) * dt_;
    if (move >= 0.999 * b2_maxTranslation || turn >= 0.999 * b2_maxRotation)
      throw SolverFailure("box2d: body " + std::to_string(i) + " would move at least " + std::to_string(move) +
                          " m (or turn " + std::to_string(turn) + " rad) in one step of " + std::to_string(dt_) +
                          " s; Box2D caps a step at 2 m and pi/2 rad and would slow it silently: use a shorter dt");
  }
}

void Box2dEngine::add_stage_times(std::vector<StageTime>& out) const {
  // b2World::Step (Box2D 2.4.1): Collide() (the narrow phase of every contact whose fat boxes
  // overlap, our PreSolve included), then Solve(): islands built, each integrated and solved
  // (solveInit: warm start and constraint set-up; solveVelocity; solvePosition), then the
  // fixtures synchronised and new pairs found (broadphase); then SolveTOI (off here). What
  // Solve() spends outside those (island search, integration) is "islands_integrate".
  std::vector<StageTime> own;
  adapter_stages_.add_to(own);
  const ProfileSums& p = profile_;
  const double solver = p.solve_init + p.solve_velocity + p.solve_position;
  out.push_back(own[kLoads]);
  out.push_back({"narrow_phase", 1e-3 * p.collide});
  out.push_back({"contact_solve", 1e-3 * solver});
  out.push_back({"islands_integrate", 1e-3 * std::max(0.0, p.solve - solver - p.broadphase)});
  out.push_back({"broad_phase", 1e-3 * p.broadphase});
  out.push_back({"toi", 1e-3 * p.toi});
  out.push_back({"step_other", 1e-3 * std::max(0.0, p.step - p.collide - p.solve - p.toi)});
  out.push_back(own[kPublish]);
}

void Box2dEngine::apply_loads(const Loads& loads) {
  const auto b2 = [](Vec2 v) { return b2Vec2(static_cast<float>(v.x), static_cast<float>(v.y)); };
  reference::hand_loads(
      loads, bodies_.size(), [&](std::size_t i) { return bodies_[i]->GetType() == b2_dynamicBody; },
      [&](const PrescribedMotion& p) {
        bodies_[p.body]->SetLinearVelocity(b2(p.velocity));
        bodies_[p.body]->SetAngularVelocity(static_cast<float>(p.angular_velocity));
      },
      [&](std::size_t i) {
        const b2Vec2 v = bodies_[i]->GetLinearVelocity();
        return Vec2{v.x, v.y};
      },
      [&](std::size_t i, Vec2 v) { bodies_[i]->SetLinearVelocity(b2(v)); },
      [&](std::size_t i, Vec2 force, double torque) {
        bodies_[i]->ApplyForceToCenter(b2(force), true);
        bodies_[i]->ApplyTorque(static_cast<float>(torque), true);
      });
}

void Box2dEngine::publish() {
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    const b2Body* b = bodies_[i];
    state_.position[i] = origin_ + Vec2{b->GetPosition().x, b->GetPosition().y};
    state_.angle[i] = b->GetAngle();
    state_.velocity[i] = {b->GetLinearVelocity().x, b->GetLinearVelocity().y};
    state_.angular_velocity[i] = b->GetAngularVelocity();
  }
}

}  // namespace

std::unique_ptr<Engine> make_box2d_engine(const Scene& scene) { return std::make_unique<Box2dEngine>(scene); }

}  // namespace floedem
