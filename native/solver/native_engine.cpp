// The native planar non-smooth DEM. One step (NativeEngine::step) makes the stages of
// floedem/engine/step_stages.hpp from broad_phase to sleep, in that list's order; docs/architecture.md
// describes what each reads and writes.
#include "solver/native_engine.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <vector>

#include "engine/line_vector.hpp"
#include "engine/prefetch.hpp"
#include "floedem/engine/step_stages.hpp"
#include "solver/broad_phase.hpp"
#include "solver/pair_cache.hpp"
#include "solver/contact_islands.hpp"
#include "solver/coloured_sweeps.hpp"
#include "solver/contact_solver.hpp"
#include "solver/headroom.hpp"
#include "solver/island_solve.hpp"
#include "solver/narrow_phase.hpp"
#include "solver/part_set.hpp"
#include "solver/native_settings.hpp"
#include "parallel/thread_pool.hpp"

namespace floedem {

namespace {

/// Where `pair` is, or would go, in a list sorted by (part_a, part_b): manifolds or carried contacts.
template <class List>
auto find_pair(const List& list, PartPair pair) {
  return std::lower_bound(list.begin(), list.end(), pair,
                          [](const auto& m, PartPair p) { return PartPair{m.part_a, m.part_b} < p; });
}

// What the contact list asks for ahead of writing a new manifold: its first five lines, 320 of
// its 384 bytes (pair, bodies, normal, friction and all of the first point and most of the
// second, which fill_manifold writes); the last line, the second point's end and the reference
// face, is written too and left to the hardware's prefetch.
constexpr std::size_t kManifoldWriteBytes = 320;

/// What the next step's contact list reads of one of this step's contacts: its pair, and each
/// point's feature id, kind and accumulated impulses (persistence and the warm start). 56 bytes
/// in a list of their own, written by record() as it reads the impulses, so that the contact
/// list need not read 320 bytes of each of the last step's 384-byte manifolds (at 10^5 floes
/// some 50 MB a step, from memory) nor keep that list a step for them alone.
struct CarriedContact {
  std::int32_t part_a = 0, part_b = 0;
  std::uint32_t id[2] = {};
  std::int32_t point_count = 0;
  ContactKind kind[2] = {};
  double normal_impulse[2] = {}, tangent_impulse[2] = {};
};

class NativeEngine final : public Engine {
 public:
  explicit NativeEngine(const Scene& scene);
  void step(const Loads* loads) override;
  const BodyStates& state() const override { return bodies_; }
  std::span<const Rot> rotations() const override { return bodies_.rotation; }
  std::span<const ContactRecord> contacts() const override { return records_; }
  EngineInfo info() const override;
  void time_stages(bool on) override { stages_.enable(on); }
  void add_stage_times(std::vector<StageTime>& out) const override { stages_.add_to(out); }
  // sweeps: each step's longest island's velocity sweeps (the step's critical path on any
  // number of threads); islands: the islands solved; redetections: the steps solved again.
  void add_work_counts(std::vector<WorkCount>& out) const override {
    out.push_back({"sweeps", static_cast<double>(total_sweeps_)});
    out.push_back({"islands", static_cast<double>(total_islands_)});
    out.push_back({"redetections", static_cast<double>(redetections_)});
  }
  bool save_state(StateWriter& out) const override;
  void restore_state(StateReader& in) override;

 private:
  void find_pairs(const Loads* loads);
  void set_reach(const Loads* loads);  // each body's reach this step, from its velocity after the loads
  bool set_reach(std::size_t body, const Loads* loads);  // ... one body's; whether it changed
  void pair_up();  // parts placed at the bodies' positions (unchanged within a step)
  bool outran_reach();
  // Each part of a body of outran_list_ against each part whose box at the present reaches
  // overlaps its own (the pairs that a broad phase at those reaches finds), until visit(k, j),
  // k the outrun part, returns true; whether one did.
  template <class Visit>
  bool visit_parts_near_outrun(Visit&& visit);
  bool meets_unseen_contact();
  // The step's contacts found and solved again where outran_list_'s bodies widened their reach:
  // only the islands they can touch are solved again, the rest keep their solution.
  void redetect();
  void mark_for_resolve(std::int32_t body);
  bool touches_sleeper() const;  // whether wake_touched would wake a group
  bool unmarked_contacts_held() const;
  void keep_solved_contacts();
  // The narrow phase: each pair's manifold into narrow_; `redetection`: that of a step found
  // again (every part where the step's first narrow phase had it).
  void collide_pairs(bool redetection);
  // narrow_'s contacts into manifolds_, warm-started and classified; `redetection`: those of a
  // step found again, the step's first pass in solved_.
  void build_contact_list(bool redetection);
  void apply_loads(const Loads& loads);
  void integrate();
  void record();
  // Sleeping (NativeSettings::sleep; docs/model.md, sleeping).
  bool asleep(std::int32_t b) const { return sleep_group_[static_cast<std::size_t>(b)] >= 0; }
  void wake_group(std::int32_t group);
  bool wake_on_loads(const Loads* loads);
  bool wake_touched();
  void fall_asleep(bool solved);
  void sleep_group(std::span<const std::int32_t> bodies);
  void settle();          // the sleepers that have been asleep long enough join settled_
  void refresh_active();  // active_bodies_ and active_parts_ again, after a body settled or woke
  // f(i) for each body but the settled sleepers, ascending, in blocks of `grain` on the pool's
  // threads (kSerial: one block, on the calling thread).
  template <class F>
  void for_active_bodies(std::size_t grain, F&& f);
  static constexpr std::size_t kSerial = 0;
  // The balance tolerance, m/s^2: a thousandth of the speed the timer sees over sleep_time.
  double balance_tolerance() const { return 1e-3 * settings_.sleep_speed / settings_.sleep_time; }
  // Whether sleeping body b's load at its first step asleep is not zero, or not yet seen (NaN).
  bool loaded_sleeper(std::size_t b) const {
    return !(sleep_force_[b].x == 0.0 && sleep_force_[b].y == 0.0 && sleep_torque_[b] == 0.0);
  }
  // Whether a load (f, t) on body b moves its fastest point beyond the balance tolerance.
  bool out_of_balance(std::size_t b, Vec2 f, double t) const {
    return length(f) * own_inv_mass_[b] > balance_tolerance() ||
           std::abs(t) * own_inv_inertia_[b] * body_radius_[b] > balance_tolerance();
  }
  PartGeometry part_geometry(std::int32_t k) const;
  double reach_of_part(std::int32_t k) const;
  Aabb reach_box(std::int32_t k, double reach) const;
  void collide_parts(PartPair pair, double reach_a, double reach_b, NarrowManifold& m,
                     SeparationHint* hint = nullptr) const;
  void solve_contacts();
  struct IslandWork;
  int solve_island(std::size_t island, bool checked, IslandWork& work, bool threads);
  // Whether island i is swept colour by colour (NativeSettings::coloured_from; islands_ built).
  bool coloured(std::size_t i) const {
    return static_cast<std::int64_t>(islands_.manifolds(i).size()) >= settings_.coloured_from;
  }
  void solve_islands_directly(double energy_before);
  bool contacts_gain_energy(double energy_before) const;
  double contact_kinetic_energy() const;
  double kinetic_energy_of(std::span<const std::int32_t> bodies) const;
  double twice_kinetic_energy(std::size_t body) const;  // m |v|^2 + I w^2
  double kinematic_work() const;
  double kinematic_work(const Manifold& m) const;

  NativeSettings settings_;
  ContactSettings contact_;
  double dt_;
  // Wall time per stage of step(), when asked for (floedem bench): the stages of
  // floedem/engine/step_stages.hpp from broad_phase to sleep, in step()'s order.
  enum Stage : std::size_t {
    kBroad, kNarrow, kContactList, kLoads, kSolve, kRedetect, kIntegrate, kProject, kRecord, kSleep, kStages
  };
  static_assert(step_stage("sleep") - step_stage("broad_phase") + 1 == kStages);
  StageClock<kStages> stages_{step_stage_names<kStages>(step_stage("broad_phase"))};

  // Hot: touched every step.
  BodyArrays bodies_;
  std::vector<std::uint8_t> moves_;        // 0 for fixed bodies
  bool has_prescribed_ = false;            // a body moves on a prescribed path (towing)
  bool heavy_light_ = false;               // direct solve on, and two moving bodies differ by its mass ratio
  PartSet parts_;
  std::vector<double> linear_reach_;       // per body: dt |v| this step
  std::vector<double> angular_reach_;      // per body: dt |w| this step
  std::vector<double> part_reach_;         // per part: how far any of its points can move this step
  std::vector<std::uint8_t> outran_;       // per body: its impulses sent it beyond its reach this step
  std::vector<std::int32_t> outran_list_;  // ... those bodies
  std::vector<std::int32_t> near_;         // parts near an outrun part's widened box
  // A redetection's reach (redetect()): per body, its island at the last solve (-1: none) and
  // whether it is in an island solved again (those bodies listed); per island of the last
  // solve, whether it is; the contact list as last solved, kept for the islands not solved again
  // and for the classification of the points it held.
  std::vector<std::int32_t> body_island_;
  std::vector<std::uint8_t> resolve_;
  std::vector<std::int32_t> resolve_list_;
  std::vector<std::uint8_t> island_resolved_;
  bool partial_solve_ = false;             // solve_contacts solves only the islands of resolve_
  LineVector<Manifold> solved_;
  LineVector<Aabb> part_boxes_;
  std::vector<double> part_margin_;        // per part: room of its fat box in the pair cache
  PairCache pair_cache_;
  std::vector<PartPair> pairs_;
  LineVector<NarrowManifold> narrow_;    // per pair this step: the narrow phase's result
  // ... and its point count, apart: a pair without contact (most pairs of fat boxes; nearly
  // all of the towing case's, whose floes at rest reuse theirs) is known by this byte alone,
  // its 192-byte slot neither written nor read again (collide_pairs, build_contact_list).
  std::vector<std::uint8_t> narrow_points_, previous_narrow_points_;
  // Per pair, the edges that separated most at its last test, tried first (sat.hpp): the same
  // manifolds, found sooner (a pair's floes turn little in a step).
  std::vector<SeparationHint> narrow_hint_, previous_hint_;
  // Narrow-phase reuse: collide() is a pure function of the two parts' placement and reaches,
  // so a pair of parts that PartSet::place kept where they were at the last step (their bodies'
  // position and rotation the same to the bit) with the same reaches gets the manifold computed
  // last time, not a new one. In the towing case most pairs are of floes at rest.
  bool any_kept_ = false;                  // any part kept (else no reuse is looked for: a drifting field)
  LineVector<NarrowManifold> previous_narrow_;  // the last narrow phase's results ...
  std::vector<PartPair> previous_pairs_;   // ... for these pairs ...
  std::vector<double> previous_reach_;     // ... with these part reaches
  std::vector<std::int32_t> reuse_;        // per pair: its slot in previous_narrow_, or -1
  std::vector<std::size_t> block_contacts_;  // per block of pairs: contacts before it
  std::int64_t narrow_pairs_ = 0, narrow_reused_ = 0;  // pairs tested over the run, and those reused (info)
  void forget_narrow();                    // no reuse at the next narrow phase
  LineVector<Manifold> manifolds_;
  std::vector<CarriedContact> carried_;  // the last step's contacts, as the contact list reads them
  std::vector<ContactRecord> records_;
  ProjectionWork projection_;             // the position projection's stamps (what moved since measured)
  // Measured figures, reported by info(): solver work and warm-start fallbacks over the run.
  std::int64_t total_sweeps_ = 0;          // per step, the most sweeps any island took
  std::int64_t total_islands_ = 0;
  std::int64_t steps_ = 0;
  std::int64_t cold_restarts_ = 0;
  std::int64_t redetections_ = 0;          // steps whose contacts were found again (outran reach)
  static constexpr int kMaxRedetections = 4;  // a struck floe striking the next, and so on
  static constexpr int kMaxWakePasses = 8;    // a woken group's reach meeting the next sleeping group, and so on
  static constexpr int kFrictionRounds = 8;   // cut friction, solve the normals again (drift_in_field: 88 % of solves cut nothing, 99 % within 2 rounds)
  std::int64_t direct_solves_ = 0;    // steps whose islands were solved directly
  std::int64_t direct_reverted_ = 0;  // ... and then given back (they would have made energy)
  ContactIslands islands_;
  /// What one block of islands reports back (its scratch lives in the step-wide lists below).
  struct IslandWork {
    int longest = 0;        // most sweeps an island of the block took
    int cold_restarts = 0;  // islands of the block solved again from zero
  };
  std::vector<IslandWork> island_work_;  // per block of islands
  // The islands' bodies' velocities before their solves (a cold restart puts them back), each
  // island in its slice (its bodies' place in islands_): one list for all, grown with headroom,
  // so a pile that keeps growing (the towing case) does not allocate per block of islands.
  std::vector<Vec2> island_velocity_;
  std::vector<double> island_angular_velocity_;
  SweepWork sweep_work_;  // the islands' sweeps, each in its slice (its manifolds' place in islands_)
  std::vector<std::size_t> island_bundles_;  // coloured sweeps: each island's first bundle in sweep_work_
  static constexpr std::size_t kIslandGrain = 8;  // islands per block
  static constexpr std::size_t kPairGrain = 512;  // pairs per block (narrow phase, contact list)
  static constexpr std::size_t kPrefetchPairs = 4;  // the narrow phase and contact list read this many pairs ahead
  std::vector<Vec2> saved_velocity_;
  std::vector<double> saved_angular_velocity_;
  std::vector<double> saved_impulses_;
  std::vector<std::int32_t> island_index_;  // the manifolds of the islands solved directly
  std::vector<Manifold> island_manifolds_;  // ... copied out for their sweeps
  IslandSolver island_solver_;
  // Sleeping. A sleeping body is held as a fixed one is: zero velocity, zero inverse mass and
  // inertia in bodies_ (so the islands, the solve, the loads and the projection pass it by and
  // its contacts with sleeping or fixed bodies keep their impulses), its own kept here.
  std::vector<double> own_inv_mass_, own_inv_inertia_;  // 0 for fixed and prescribed bodies
  std::vector<double> body_radius_;        // farthest point of a body from its centroid, m
  std::vector<double> rest_time_;          // s each moving body has been at rest (sleep_speed)
  std::vector<std::int32_t> sleep_group_;  // per body: its sleeping group, -1 awake
  // Each group's bodies as a list through the bodies (no allocation as groups come and go):
  // its first body (-1: a free id), and per body the next of its group (-1: the last).
  std::vector<std::int32_t> group_first_, next_in_group_;
  std::vector<std::int32_t> free_groups_;
  std::vector<Vec2> sleep_force_;          // per sleeping body: its load at its first step asleep (NaN: not yet seen)
  std::vector<double> sleep_torque_;
  std::vector<std::uint8_t> in_island_;    // scratch of fall_asleep
  std::int64_t asleep_count_ = 0;          // bodies asleep now
  std::int64_t asleep_steps_ = 0;          // sum over steps of the bodies asleep (info: their mean)
  std::int64_t wakes_ = 0;                 // groups woken over the run
  std::int64_t loaded_sleepers_ = 0;       // sleeping bodies whose load at sleep is not yet seen, or not zero
  // Settled sleepers. A body asleep since the end of step s has, from step s + 2 on, zero
  // velocity and reach and the same placement, part boxes and fat boxes every step, until it
  // wakes (its position could still change in step s + 1: a velocity of zero moves -0 to +0).
  // From step s + 3 the passes over bodies and parts of the broad phase, the loads and the
  // integration leave it out, going over the lists of the rest instead (ascending): the same
  // values to the bit, without a visit to the towing case's 4 000 floes at rest.
  std::vector<std::int64_t> asleep_since_;   // per body: the step at whose end it last fell asleep
  std::vector<std::uint8_t> settled_;        // per body
  std::vector<std::int32_t> settling_;       // bodies that fell asleep and have not settled yet
  std::vector<std::int32_t> active_bodies_, active_parts_;  // the bodies not settled, and their parts
  std::int64_t settled_count_ = 0;
  bool active_stale_ = false;              // a body settled or woke since the lists were made
  const Loads* step_loads_ = nullptr;      // this step's loads (nullptr: none) ...
  bool loads_applied_ = false;             // ... and whether apply_loads has run: a group woken after it gets its loads then
  bool wake_reach_grew_ = false;           // a body woken in the narrow phase has another reach than asleep
  /// The sweeps' limits: extra sweeps while a point would close by more than the allowed overlap within the step.
  SweepLimits sweep_limits() const {
    return {settings_.velocity_iterations, settings_.tolerance, settings_.extra_iterations,
            settings_.allowed_penetration / dt_};
  }
};

NativeEngine::NativeEngine(const Scene& scene)
    : settings_(read_native_settings(scene)),
      contact_(scene.contact),
      dt_(scene.run.dt),
      parts_(scene) {
  const std::size_t n = scene.bodies.size();
  bodies_.position.resize(n);
  bodies_.angle.assign(n, 0.0);
  bodies_.rotation.assign(n, Rot{});
  bodies_.velocity.resize(n);
  bodies_.angular_velocity.resize(n);
  bodies_.inv_mass.resize(n);
  bodies_.inv_inertia.resize(n);
  moves_.resize(n);
  double lightest = std::numeric_limits<double>::infinity(), heaviest = 0.0;  // moving bodies, kg
  for (std::size_t i = 0; i < n; ++i) {
    const BodySpec& b = scene.bodies[i];
    bodies_.position[i] = b.centroid;
    bodies_.velocity[i] = b.velocity;
    bodies_.angular_velocity[i] = b.angular_velocity;
    // Fixed and prescribed (towed at a given velocity) bodies have infinite mass in contacts.
    const bool infinite = b.fixed || b.prescribed;
    bodies_.inv_mass[i] = infinite ? 0.0 : 1.0 / scene.engine_mass(i);
    bodies_.inv_inertia[i] = infinite ? 0.0 : 1.0 / scene.engine_inertia(i);
    moves_[i] = b.fixed ? 0 : 1;
    has_prescribed_ = has_prescribed_ || b.prescribed;
    if (!infinite) {
      heaviest = std::max(heaviest, scene.engine_mass(i));
      lightest = std::min(lightest, scene.engine_mass(i));
    }
  }
  heavy_light_ = settings_.direct_solve && heaviest >= settings_.direct_solve_mass_ratio * lightest;
  own_inv_mass_ = bodies_.inv_mass;
  own_inv_inertia_ = bodies_.inv_inertia;
  body_radius_.assign(n, 0.0);
  for (std::size_t k = 0; k < parts_.size(); ++k) {
    const auto b = static_cast<std::size_t>(parts_.body()[k]);
    body_radius_[b] = std::max(body_radius_[b], parts_.radius(static_cast<std::int32_t>(k)));
  }
  rest_time_.assign(n, 0.0);
  sleep_group_.assign(n, -1);
  sleep_force_.assign(n, Vec2{});
  sleep_torque_.assign(n, 0.0);
  next_in_group_.assign(n, -1);
  group_first_.reserve(n);
  free_groups_.reserve(n);
  in_island_.assign(n, 0);
  asleep_since_.assign(n, 0);
  settled_.assign(n, 0);
  settling_.reserve(n);
  active_bodies_.reserve(n);
  active_parts_.reserve(parts_.size());
  part_boxes_.resize(parts_.size());
  linear_reach_.resize(n);
  angular_reach_.resize(n);
  part_reach_.resize(parts_.size());
  part_margin_.resize(parts_.size());
  outran_.assign(n, 0);
  body_island_.assign(n, -1);
  resolve_.assign(n, 0);
  forget_narrow();
}

EngineInfo NativeEngine::info() const {
  EngineInfo i;
  i.name = "native";
  i.version = "floedem";
  i.settings = {
      {"velocity_iterations", std::to_string(settings_.velocity_iterations)},
      {"extra_iterations", std::to_string(settings_.extra_iterations)},
      {"accelerate", settings_.accelerate ? "true" : "false"},
      {"coloured_from", std::to_string(settings_.coloured_from)},
      {"tolerance", setting_text(settings_.tolerance)},
      {"warm_start", settings_.warm_start ? "true" : "false"},
      {"position_iterations", std::to_string(settings_.position_iterations)},
      {"position_correction", setting_text(settings_.position_correction)},
      {"allowed_penetration", setting_text(settings_.allowed_penetration)},
      {"max_correction", setting_text(settings_.max_correction)},
      {"redetect", settings_.redetect ? "true" : "false"},
      {"direct_solve", settings_.direct_solve ? "true" : "false"},
      {"direct_solve_mass_ratio", setting_text(settings_.direct_solve_mass_ratio)},
      {"sleep", settings_.sleep ? "true" : "false"},
      {"sleep_speed", setting_text(settings_.sleep_speed)},
      {"sleep_time", setting_text(settings_.sleep_time)},
      {"mean_bodies_asleep", setting_text(steps_ > 0 ? static_cast<double>(asleep_steps_) / static_cast<double>(steps_) : 0.0)},
      {"sleeping_groups_woken", std::to_string(wakes_)},
      {"direct_solves", std::to_string(direct_solves_)},
      {"direct_solves_reverted", std::to_string(direct_reverted_)},
      {"mean_sweeps_per_step", setting_text(steps_ > 0 ? static_cast<double>(total_sweeps_) / static_cast<double>(steps_) : 0.0)},
      {"mean_islands_per_step", setting_text(steps_ > 0 ? static_cast<double>(total_islands_) / static_cast<double>(steps_) : 0.0)},
      {"cold_restarts", std::to_string(cold_restarts_)},
      {"narrow_phase_reused", setting_text(narrow_pairs_ > 0 ? static_cast<double>(narrow_reused_) / static_cast<double>(narrow_pairs_) : 0.0)},
      {"redetections", std::to_string(redetections_)},
      {"broad_phase_rebuilds", std::to_string(pair_cache_.rebuilds())},
      {"broad_phase_refreshed_parts", std::to_string(pair_cache_.refreshed_parts())},
  };
  return i;
}

bool NativeEngine::save_state(StateWriter& out) const {
  // What the next steps read: the bodies (the rotation too, so that no sin/cos is redone),
  // last step's manifolds (warm start and persistence: pair, feature id, impulses, kind),
  // the broad phase's cache, and the counts info() reports. Everything else is rebuilt from
  // these (placed parts, boxes, reach) or is scratch.
  out.tag("native");
  out.vector(bodies_.position);
  out.vector(bodies_.angle);
  out.vector(bodies_.rotation);
  out.vector(bodies_.velocity);
  out.vector(bodies_.angular_velocity);
  out.value(static_cast<std::uint64_t>(carried_.size()));  // the step's contacts (record() wrote them)
  for (const CarriedContact& c : carried_) {
    out.value(c.part_a);
    out.value(c.part_b);
    out.value(c.point_count);
    for (int k = 0; k < c.point_count; ++k) {
      out.value(c.id[k]);
      out.value(c.normal_impulse[k]);
      out.value(c.tangent_impulse[k]);
      out.value(c.kind[k]);
    }
  }
  pair_cache_.save(out);
  out.value(total_sweeps_);
  out.value(steps_);
  out.value(cold_restarts_);
  out.value(redetections_);
  out.value(direct_solves_);
  out.value(direct_reverted_);
  out.value(total_islands_);
  out.value(narrow_pairs_);
  out.value(narrow_reused_);
  out.tag("sleep");
  out.vector(rest_time_);
  out.vector(sleep_group_);
  out.vector(sleep_force_);
  out.vector(sleep_torque_);
  out.value(asleep_steps_);
  out.value(wakes_);
  return true;
}

void NativeEngine::restore_state(StateReader& in) {
  in.tag("native");
  const std::size_t n = bodies_.position.size();
  in.vector(bodies_.position, n, "body positions");
  in.vector(bodies_.angle, n, "body angles");
  in.vector(bodies_.rotation, n, "body rotations");
  in.vector(bodies_.velocity, n, "body velocities");
  in.vector(bodies_.angular_velocity, n, "body angular velocities");
  const auto count = in.value<std::uint64_t>();
  if (count > in.left()) throw StateError("checkpoint: truncated");
  carried_.assign(static_cast<std::size_t>(count), CarriedContact{});
  const auto parts = static_cast<std::int32_t>(parts_.size());
  for (CarriedContact& c : carried_) {
    in.value(c.part_a);
    in.value(c.part_b);
    in.value(c.point_count);
    if (c.part_a < 0 || c.part_a >= c.part_b || c.part_b >= parts || c.point_count < 1 || c.point_count > 2)
      throw StateError("checkpoint: a contact manifold that does not fit this scene");
    for (int k = 0; k < c.point_count; ++k) {
      in.value(c.id[k]);
      in.value(c.normal_impulse[k]);
      in.value(c.tangent_impulse[k]);
      in.value(c.kind[k]);
    }
  }
  manifolds_.clear();  // the next step's contact list is made from carried_ alone
  pair_cache_.restore(in, parts_.body(), parts_.immovable());
  in.value(total_sweeps_);
  in.value(steps_);
  in.value(cold_restarts_);
  in.value(redetections_);
  in.value(direct_solves_);
  in.value(direct_reverted_);
  in.value(total_islands_);
  in.value(narrow_pairs_);
  in.value(narrow_reused_);
  in.tag("sleep");
  in.vector(rest_time_, n, "rest times");
  in.vector(sleep_group_, n, "sleeping groups");
  in.vector(sleep_force_, n, "sleeping loads");
  in.vector(sleep_torque_, n, "sleeping torques");
  in.value(asleep_steps_);
  in.value(wakes_);
  // The groups again from each body's (the ids as saved; which ids are free, and the order of
  // a group's list, change no result).
  group_first_.clear();
  free_groups_.clear();
  asleep_count_ = 0;
  loaded_sleepers_ = 0;
  // A restored run places every part afresh (PartSet keeps no placement across a checkpoint):
  // its sleepers settle as if they had just fallen asleep.
  settling_.clear();
  settled_count_ = 0;
  std::fill(settled_.begin(), settled_.end(), 0);
  active_stale_ = true;
  for (std::size_t b = 0; b < n; ++b) {
    const std::int32_t g = sleep_group_[b];
    next_in_group_[b] = -1;
    bodies_.inv_mass[b] = g >= 0 ? 0.0 : own_inv_mass_[b];
    bodies_.inv_inertia[b] = g >= 0 ? 0.0 : own_inv_inertia_[b];
    if (g < 0) continue;
    if (g >= static_cast<std::int32_t>(n) || own_inv_mass_[b] == 0.0) throw StateError("checkpoint: a sleeping body that does not fit this scene");
    if (static_cast<std::size_t>(g) >= group_first_.size()) group_first_.resize(static_cast<std::size_t>(g) + 1, -1);
    next_in_group_[b] = group_first_[static_cast<std::size_t>(g)];
    group_first_[static_cast<std::size_t>(g)] = static_cast<std::int32_t>(b);
    ++asleep_count_;
    loaded_sleepers_ += loaded_sleeper(b);
    asleep_since_[b] = steps_;
    settling_.push_back(static_cast<std::int32_t>(b));
  }
  for (std::size_t g = group_first_.size(); g-- > 0;)
    if (group_first_[g] < 0) free_groups_.push_back(static_cast<std::int32_t>(g));
  records_.clear();  // the contacts of the step before the checkpoint are not needed again
  forget_narrow();   // a restored run computes its first narrow phase afresh, as the saved one did
}

void NativeEngine::step(const Loads* loads) {
  if (loads) {
    for (const PrescribedMotion& p : loads->prescribed) {
      bodies_.velocity[p.body] = p.velocity;
      bodies_.angular_velocity[p.body] = p.angular_velocity;
    }
    if (!loads->any && loads->velocity_turn.empty()) loads = nullptr;  // nothing to add: skip the pass
  }
  step_loads_ = loads && loads->any ? loads : nullptr;
  loads_applied_ = false;
  // 0. a sleeping group whose loads changed wakes (before the reaches: it moves this step)
  if (asleep_count_ > 0) stages_.time(kSleep, [&] { wake_on_loads(step_loads_); });
  // 1. pairs (a velocity turn keeps the speed)
  stages_.time(kBroad, [&] { find_pairs(step_loads_); });
  // 2. manifolds, classified on the velocities before the step; a sleeping group that an awake
  // body reaches wakes, and the pairs are found again with its reach
  stages_.time(kNarrow, [&] {
    collide_pairs(/*redetection=*/false);
    wake_reach_grew_ = false;
    for (int pass = 0; asleep_count_ > 0 && pass < kMaxWakePasses && wake_touched() && wake_reach_grew_; ++pass) {
      wake_reach_grew_ = false;
      pair_up();
      collide_pairs(/*redetection=*/false);
    }
  });
  stages_.time(kContactList, [&] { build_contact_list(/*redetection=*/false); });
  if (loads) stages_.time(kLoads, [&] { apply_loads(*loads); });  // 3. non-contact forces
  loads_applied_ = true;
  if (!manifolds_.empty()) {                                       // 4. contact impulses
    stages_.time(kSolve, [&] { solve_contacts(); });
    // A body the impulses sent further than its reach may meet one the pairs did not include
    // (a floe struck at 5 m/s crosses a 5 cm gap to the next in one 0.01 s step), or reach a
    // point of a pair that was beyond the margin (a floe spun by a collision swings its far
    // corner into its neighbour): where the widened reach shows such a contact, the step's
    // contacts are found again, and the islands that the widened reaches can touch solved
    // again (redetect()).
    stages_.time(kRedetect, [&] {
      for (int pass = 0; settings_.redetect && pass < kMaxRedetections && outran_reach(); ++pass) {
        const bool unseen = meets_unseen_contact();
        if (unseen) {
          redetect();
          ++redetections_;
        }
        for (const std::int32_t b : outran_list_) outran_[b] = 0;
        outran_list_.clear();
        if (!unseen) break;
      }
    });
  }
  stages_.time(kIntegrate, [&] { integrate(); });  // 5. positions
  if (settings_.position_iterations > 0 && !manifolds_.empty())  // 6. drift correction, positions only
    stages_.time(kProject, [&] { solve_positions(manifolds_, bodies_, settings_, projection_); });
  stages_.time(kRecord, [&] { record(); });  // 7. impulses for the recorder
  if (settings_.sleep) stages_.time(kSleep, [&] { fall_asleep(!manifolds_.empty()); });  // 8. islands at rest
  asleep_steps_ += asleep_count_;
  ++steps_;
}

bool NativeEngine::outran_reach() {
  // Per part: how far it can move this step at the velocities after the impulses, against the
  // reach its pairs were found with; beyond it by half the allowed overlap, the reach of its
  // body is widened to the new speed and the step's contacts found again. Only bodies with
  // contacts can have changed speed since the reach was set (from the velocities after the
  // loads), and one within both its linear and its angular reach has no part beyond its own:
  // those checks first (the towing case's 5 000 floes cost nothing more where none is struck).
  // Each moving body of a contact once, from the islands the solve just built (a packed floe
  // has some six contacts: a loop over the manifolds looked at it six times). The bodies found
  // are the same set in another order, and the reaches widened are the same.
  for (const std::int32_t b : islands_.all_bodies()) {
    if (!moves_[b] || outran_[b]) continue;
    const double linear = dt_ * length(bodies_.velocity[b]);
    const double angular = dt_ * std::abs(bodies_.angular_velocity[b]);
    if (linear <= linear_reach_[b] && angular <= angular_reach_[b]) continue;
    bool beyond = false;
    for (std::int32_t k = parts_.first_part(b); k < parts_.first_part(b + 1); ++k)
      beyond = beyond || linear + angular * parts_.radius(k) > part_reach_[k] + 0.5 * settings_.allowed_penetration;
    if (!beyond) continue;
    linear_reach_[b] = std::max(linear_reach_[b], linear);
    angular_reach_[b] = std::max(angular_reach_[b], angular);
    outran_[b] = 1;
    outran_list_.push_back(b);
  }
  return !outran_list_.empty();
}

bool NativeEngine::meets_unseen_contact() {
  // The parts of the bodies that outran their reach, against the parts near their widened
  // boxes: a point the step's manifolds do not hold, closing by more than half the allowed
  // overlap at the velocities the solve left (gap + dt u_n), calls for the step to be solved
  // again. The rest cost a box query and a narrow phase each (towing: most floes the iceberg
  // strikes outrun the reach of a floe at rest, and meet nothing new within the step).
  const double slop = 0.5 * settings_.allowed_penetration;
  NarrowManifold probe;
  return visit_parts_near_outrun([&](std::int32_t k, std::int32_t j) {
    const std::int32_t a = parts_.body()[std::min(j, k)], b = parts_.body()[std::max(j, k)];
    if (a == b || (parts_.immovable()[j] && parts_.immovable()[k])) return false;
    const PartPair pair{std::min(j, k), std::max(j, k)};
    collide_parts(pair, reach_of_part(pair.a), reach_of_part(pair.b), probe);
    if (probe.point_count == 0) return false;
    const auto held = find_pair(manifolds_, pair);
    const bool pair_held = held != manifolds_.end() && held->part_a == pair.a && held->part_b == pair.b;
    for (int q = 0; q < probe.point_count; ++q) {
      const NarrowPoint& p = probe.points[q];
      bool point_held = false;
      for (int h = 0; pair_held && h < held->point_count; ++h) point_held = point_held || held->points[h].id == p.id;
      if (point_held) continue;
      const Vec2 u = relative_velocity(bodies_, a, b, p.point - bodies_.position[a], p.point - bodies_.position[b]);
      if (p.separation + dt_ * dot(u, probe.normal) < -slop) return true;
    }
    return false;
  });
}

template <class Visit>
bool NativeEngine::visit_parts_near_outrun(Visit&& visit) {
  auto grown = [&](std::int32_t k) { return reach_box(k, reach_of_part(k)); };
  for (const std::int32_t body : outran_list_)
    for (std::int32_t k = parts_.first_part(body); k < parts_.first_part(body + 1); ++k) {
      const Aabb box = grown(k);
      pair_cache_.parts_near(box, near_);
      for (const std::int32_t j : near_)
        if (grown(j).overlaps(box) && visit(k, j)) return true;
    }
  return false;
}

void NativeEngine::redetect() {
  // Which contacts can change: those of a part whose reach grew (the bodies of outran_list_).
  // Every other pair keeps its parts' reaches, so the narrow phase gives it the manifold it had
  // (collide_pairs), and a new contact has a body of outran_list_ at one end. So the islands
  // of the last solve that hold such a body, or a body within its widened reach, are all that
  // can change: they are marked, their impulses taken off, and they are solved again from the
  // velocities after the loads. Every other island keeps its solution to the bit. A point the
  // first pass held keeps the classification it had there, made on the velocities before the
  // loads (build_contact_list): on those after them, a floe pressed on a wall by its load
  // approaches it at F dt / m, a collision rather than a resting contact, and with restitution
  // it would bounce off because a floe of its island, or one a kilometre away, was struck
  // (test_impacts.cpp). Only a point the first pass did not hold, which the widened reach
  // found, is classified on the velocities after the loads. Marking is closed: a new island is
  // the union of marked islands joined by new contacts, or an old island untouched.
  const std::size_t ni = islands_.size();
  for (std::size_t i = 0; i < ni; ++i)
    for (const std::int32_t b : islands_.bodies(i)) body_island_[b] = static_cast<std::int32_t>(i);
  island_resolved_.assign(ni, 0);
  for (const std::int32_t body : outran_list_) mark_for_resolve(body);
  visit_parts_near_outrun([&](std::int32_t, std::int32_t j) {
    mark_for_resolve(parts_.body()[j]);
    return false;
  });
  // The accumulated impulses are all that the solve applied (warm start included; a cold
  // restart or a direct solve reset them with the velocities): taken off, the velocities are
  // those after the loads, to rounding. Island by island: each body sees its manifolds in
  // their order in the list, as one pass over the list would apply them.
  auto take_off = [&](std::size_t i) {
    for (const std::int32_t k : islands_.manifolds(i))
      apply_accumulated_impulses({&manifolds_[static_cast<std::size_t>(k)], 1}, bodies_, -1.0);
  };
  for (std::size_t i = 0; i < ni; ++i)
    if (island_resolved_[i]) take_off(i);
  pair_up();
  collide_pairs(/*redetection=*/true);
  // A body struck into a sleeping one wakes its group (with its loads), which joins islands
  // that were not marked: then every island is solved again (rare: the sleepers are far from
  // the floes that strike). Taken off before the wake: a sleeping body held, as in the solve.
  // The same where the unmarked contacts are not the last solve's (the argument above says they
  // are; checked, since a kept island with a contact more or less would be wrong).
  const bool all = (asleep_count_ > 0 && touches_sleeper()) || !unmarked_contacts_held();
  if (all) {
    for (std::size_t i = 0; i < ni; ++i)
      if (!island_resolved_[i]) take_off(i);
    if (asleep_count_ > 0) wake_touched();
  }
  for (std::size_t i = 0; i < ni; ++i)
    for (const std::int32_t b : islands_.bodies(i)) body_island_[b] = -1;
  std::swap(manifolds_, solved_);  // the solved list kept, the new one built over the old
  build_contact_list(/*redetection=*/true);
  if (!all) keep_solved_contacts();
  partial_solve_ = !all;
  solve_contacts();
  partial_solve_ = false;
  for (const std::int32_t b : resolve_list_) resolve_[b] = 0;
  resolve_list_.clear();
}

void NativeEngine::mark_for_resolve(std::int32_t body) {
  // Only a moving body is marked: a fixed, towed or sleeping one joins no island (an impulse
  // cannot change its velocity), and its contacts go with the moving body at their other end.
  if (bodies_.inv_mass[body] == 0.0) return;
  const std::int32_t i = body_island_[body];
  if (i < 0) {
    if (!resolve_[body]) resolve_list_.push_back(body);
    resolve_[body] = 1;
    return;
  }
  if (island_resolved_[i]) return;
  island_resolved_[i] = 1;
  for (const std::int32_t b : islands_.bodies(static_cast<std::size_t>(i))) {
    resolve_[b] = 1;
    resolve_list_.push_back(b);
  }
}

bool NativeEngine::unmarked_contacts_held() const {
  // The new pairs with contact points and no marked body, against the last solve's manifolds
  // with no marked body: the same pairs, in the same order (both sorted by pair).
  auto unmarked = [&](std::int32_t a, std::int32_t b) { return !resolve_[a] && !resolve_[b]; };
  std::size_t old = 0;
  auto next_old = [&] {
    while (old < manifolds_.size() && !unmarked(manifolds_[old].body_a, manifolds_[old].body_b)) ++old;
  };
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    if (narrow_points_[k] == 0) continue;
    const PartPair pair = pairs_[k];
    if (!unmarked(parts_.body()[pair.a], parts_.body()[pair.b])) continue;
    next_old();
    if (old == manifolds_.size() || manifolds_[old].part_a != pair.a || manifolds_[old].part_b != pair.b) return false;
    ++old;
  }
  next_old();
  return old == manifolds_.size();
}

void NativeEngine::keep_solved_contacts() {
  // A contact of two unmarked bodies is the one the last solve left (unmarked_contacts_held):
  // its impulses, its classification on the velocities before the step, and its bodies'
  // velocities stay.
  std::size_t old = 0;
  for (Manifold& m : manifolds_) {
    if (resolve_[m.body_a] || resolve_[m.body_b]) continue;
    while (solved_[old].part_a != m.part_a || solved_[old].part_b != m.part_b) ++old;
    m = solved_[old++];
  }
}

bool NativeEngine::touches_sleeper() const {
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    if (narrow_points_[k] == 0) continue;
    const std::int32_t a = parts_.body()[pairs_[k].a], b = parts_.body()[pairs_[k].b];
    if (asleep(a) != asleep(b) && moves_[asleep(a) ? b : a]) return true;
  }
  return false;
}

void NativeEngine::find_pairs(const Loads* loads) {
  if (!settling_.empty()) settle();
  set_reach(loads);
  refresh_active();
  if (settled_count_ > 0) {
    parts_.place(bodies_.position, bodies_.rotation, active_parts_);
    any_kept_ = true;  // the settled sleepers' parts, held where they were placed
  } else {
    any_kept_ = parts_.place(bodies_.position, bodies_.rotation);
  }
  pair_up();
}

void NativeEngine::set_reach(const Loads* loads) {
  // Reach: how far any point of a body can travel this step (dt times its speed after the
  // loads, plus spin times the part's radius), so that contacts are found before the bodies
  // would overlap (speculative contact) and their bounds need no rebuild within the step.
  for_active_bodies(8192, [&](std::size_t i) { set_reach(i, loads); });
}

bool NativeEngine::set_reach(std::size_t i, const Loads* loads) {
  double speed = length(bodies_.velocity[i]);
  double spin = std::abs(bodies_.angular_velocity[i]);
  if (loads) {
    speed += dt_ * length(loads->force[i]) * bodies_.inv_mass[i];
    spin += dt_ * std::abs(loads->torque[i]) * bodies_.inv_inertia[i];
  }
  const bool same = same_bits(linear_reach_[i], dt_ * speed) && same_bits(angular_reach_[i], dt_ * spin);
  linear_reach_[i] = dt_ * speed;
  angular_reach_[i] = dt_ * spin;
  return !same;
}

void NativeEngine::forget_narrow() {
  any_kept_ = false;
  previous_pairs_.clear();
  previous_narrow_.clear();
  previous_narrow_points_.clear();
  previous_reach_.clear();
}

void NativeEngine::pair_up() {
  refresh_active();
  const bool skip = settled_count_ > 0;  // a settled sleeper's parts keep what they have
  thread_pool().for_blocks(skip ? active_parts_.size() : parts_.size(), 8192, [&](std::size_t begin, std::size_t end) {
    for (std::size_t j = begin; j < end; ++j) {
      const std::int32_t k = skip ? active_parts_[j] : static_cast<std::int32_t>(j);
      part_reach_[k] = reach_of_part(k);
      part_boxes_[k] = reach_box(k, part_reach_[k]);
      // A part that leaves its fat box gets room for about four steps at its present reach and
      // a tenth of its size besides (so that a floe at rest, or creeping, keeps its box long).
      part_margin_[k] = 4.0 * part_reach_[k] + 0.1 * parts_.radius(k);
    }
  });
  pair_cache_.find_pairs(part_boxes_, part_margin_, parts_.body(), parts_.immovable(), pairs_,
                         skip ? std::span<const std::int32_t>(active_parts_) : std::span<const std::int32_t>());
}

double NativeEngine::reach_of_part(std::int32_t k) const {
  const std::int32_t b = parts_.body()[k];
  return linear_reach_[b] + angular_reach_[b] * parts_.radius(k);
}

Aabb NativeEngine::reach_box(std::int32_t k, double reach) const {
  // The part's bounds grown by its reach and half the allowed overlap: the pairs' test.
  const double fat = reach + 0.5 * settings_.allowed_penetration;
  return {parts_.boxes()[k].lo - Vec2{fat, fat}, parts_.boxes()[k].hi + Vec2{fat, fat}};
}

void NativeEngine::collide_parts(PartPair pair, double reach_a, double reach_b, NarrowManifold& m,
                                 SeparationHint* hint) const {
  // Contacts within both parts' reach this step (speculative), plus the allowed overlap; the
  // reference face kept unless the other is better by a tenth of it.
  collide(part_geometry(pair.a), part_geometry(pair.b), reach_a + reach_b + settings_.allowed_penetration,
          0.1 * settings_.allowed_penetration, m, hint);
}

PartGeometry NativeEngine::part_geometry(std::int32_t k) const {
  const std::int32_t b = parts_.body()[k];
  return parts_.geometry(k, bodies_.position[b], bodies_.rotation[b]);
}

void NativeEngine::collide_pairs(bool redetection) {
  // Narrow phase: each pair into its own slot, blocks of pairs on the pool's threads (a pure
  // function of the pair: the same manifolds on any number of threads).
  resize_with_headroom(narrow_, pairs_.size());  // with room: the pairs set new highs as a pack breathes
  resize_with_headroom(narrow_points_, pairs_.size());
  // Per pair, its slot at the last narrow phase (both lists sorted): its separation hint
  // carries over, and where both parts were kept in place with the same reaches, its manifold.
  // A redetection's narrow phase follows the step's first one with every part where it was
  // (only the reaches of the bodies that outran theirs grew): each pair of parts whose reaches
  // stayed the same gets the first one's manifold.
  const bool may_reuse = (any_kept_ || redetection) && !previous_pairs_.empty();
  if (may_reuse) resize_with_headroom(reuse_, pairs_.size());
  resize_with_headroom(narrow_hint_, pairs_.size());
  auto same_reach = [&](std::int32_t part) {
    return same_bits(part_reach_[part], previous_reach_[part]);
  };
  std::size_t last = 0;
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    const PartPair pair = pairs_[k];
    while (last < previous_pairs_.size() && previous_pairs_[last] < pair) ++last;
    const bool met = last < previous_pairs_.size() && previous_pairs_[last] == pair;
    narrow_hint_[k] = met ? previous_hint_[last] : SeparationHint{};
    if (!may_reuse) continue;
    reuse_[k] = -1;
    if (met && (redetection || (parts_.kept()[pair.a] && parts_.kept()[pair.b])) && same_reach(pair.a) &&
        same_reach(pair.b)) {
      reuse_[k] = static_cast<std::int32_t>(last);
      ++narrow_reused_;
    }
  }
  narrow_pairs_ += static_cast<std::int64_t>(pairs_.size());
  const std::size_t blocks = (pairs_.size() + kPairGrain - 1) / kPairGrain;
  block_contacts_.assign(blocks + 1, 0);
  thread_pool().for_blocks(pairs_.size(), kPairGrain, [&](std::size_t begin, std::size_t end) {
    // The block's contacts, counted as each slot is written (a second pass would reread every
    // slot, out of cache at 16k floes): they place the block's contacts in the list.
    std::size_t found = 0;
    for (std::size_t k = begin; k < end; ++k) {
      // The geometry of the pair a few on: its second part is anywhere in the field (pairs are
      // sorted by first part), and collide()'s first loads of it, and of the reference face's
      // frame data, waited on memory (perf: about a tenth of its samples at 16k floes). A
      // prefetch changes no value.
      // A pair whose manifold is reused is not collided: its geometry is not asked for.
      if (k + kPrefetchPairs < end && !(may_reuse && reuse_[k + kPrefetchPairs] >= 0)) {
        const PartPair ahead = pairs_[k + kPrefetchPairs];
        parts_.prefetch_world(ahead.b);
        parts_.prefetch_local(ahead.b);
        parts_.prefetch_local(ahead.a);
      }
      if (may_reuse && reuse_[k] >= 0) {
        const auto r = static_cast<std::size_t>(reuse_[k]);
        // A pair without contact is read for its point count alone (most pairs of fat boxes).
        narrow_points_[k] = previous_narrow_points_[r];
        if (narrow_points_[k] != 0) copy_manifold(previous_narrow_[r], narrow_[k]);
        found += narrow_points_[k] != 0;
        continue;
      }
      const PartPair pair = pairs_[k];
      // Every field the solver reads is set here or by collide() (which sets the face and
      // each point it adds in full); a slot is not cleared first (a NarrowManifold is 192 bytes,
      // and most pairs of fat boxes have no contact).
      NarrowManifold& m = narrow_[k];
      m.part_a = pair.a;
      m.part_b = pair.b;
      m.body_a = parts_.body()[pair.a];
      m.body_b = parts_.body()[pair.b];
      m.friction = contact_.friction;
      m.restitution = contact_.restitution;
      collide_parts(pair, part_reach_[pair.a], part_reach_[pair.b], m, &narrow_hint_[k]);
      narrow_points_[k] = static_cast<std::uint8_t>(m.point_count);
      found += m.point_count != 0;
    }
    block_contacts_[begin / kPairGrain + 1] = found;
  });
}

void NativeEngine::build_contact_list(bool redetection) {
  // The contact list is written over the last one (or, redetecting, over the one before the
  // step's first, which solved_ keeps), slot by slot (fill_manifold writes what each contact
  // holds, not the whole struct), and cut to length at the end; what the warm start needs of
  // the last step's is in carried_.
  // The contacts, in pair order, each into its slot of the list: per block of pairs (the
  // narrow phase's blocks), its first slot is the count of contacts in the blocks before it.
  const std::size_t blocks = block_contacts_.size() - 1;
  for (std::size_t b = 0; b < blocks; ++b) block_contacts_[b + 1] += block_contacts_[b];
  const std::size_t contacts = block_contacts_[blocks];
  if (manifolds_.size() < contacts) resize_with_headroom(manifolds_, contacts);
  // Blocks on the pool's threads again: each manifold is written from its own slot, its
  // impulses carried over from last step's list (both lists are sorted by (part_a, part_b):
  // a merge from where the block's first pair would be) and classified, a function of the
  // manifold and the bodies alone: the same list on any number of threads. Redetecting, a point
  // the step's first pass held is classified as it was there (prepare_contact), found by the
  // same merge over that pass's list.
  thread_pool().for_blocks(pairs_.size(), kPairGrain, [&](std::size_t begin, std::size_t end) {
    std::size_t slot = block_contacts_[begin / kPairGrain];
    auto old = static_cast<std::size_t>(find_pair(carried_, pairs_[begin]) - carried_.begin());
    std::size_t first = redetection ? static_cast<std::size_t>(find_pair(solved_, pairs_[begin]) - solved_.begin()) : 0;
    for (std::size_t k = begin; k < end; ++k) {
      // The narrow slots it reads and the manifolds it writes, a few records on (perf: a third
      // of its samples waited on their first lines at 16k floes; the carried contacts, 56
      // bytes each in order, are left to the hardware's prefetch). A prefetch changes no value.
      if (k + kPrefetchPairs < end) prefetch_lines(&narrow_[k + kPrefetchPairs], sizeof(NarrowManifold));
      const PartPair pair = pairs_[k];
      if (narrow_points_[k] == 0) continue;
      if (slot + 2 < contacts) prefetch_lines(&manifolds_[slot + 2], kManifoldWriteBytes);
      const NarrowManifold& found = narrow_[k];  // narrow_ keeps the narrow phase's own result (reuse)
      Manifold& m = manifolds_[slot++];
      fill_manifold(found, m);
      // Read from the narrow phase's slot, not the fresh copy: a load from a block just copied
      // waits for the copy's stores to retire.
      while (old < carried_.size() && PartPair{carried_[old].part_a, carried_[old].part_b} < pair) ++old;
      if (old < carried_.size() && carried_[old].part_a == pair.a && carried_[old].part_b == pair.b) {
        const CarriedContact& prev = carried_[old];
        for (int q = 0; q < found.point_count; ++q) {
          for (int j = 0; j < prev.point_count; ++j) {
            if (prev.id[j] != found.points[q].id) continue;
            // Pressed last step: the bodies are already in contact here, so this is no collision.
            m.points[q].persistent = prev.normal_impulse[j] > 0.0;
            // Only resting impulses are a good first guess: a collision's impulse is a one-off.
            // A manifold between two held bodies (sleeping or fixed) keeps its impulses whatever
            // the warm start: nothing solves it, and they are the load it carries.
            const bool held = bodies_.inv_mass[m.body_a] == 0.0 && bodies_.inv_mass[m.body_b] == 0.0;
            if ((settings_.warm_start || held) && prev.kind[j] == ContactKind::resting) {
              m.points[q].normal_impulse = prev.normal_impulse[j];
              m.points[q].tangent_impulse = prev.tangent_impulse[j];
            }
          }
        }
      }
      const Manifold* held = nullptr;
      if (redetection) {
        while (first < solved_.size() && PartPair{solved_[first].part_a, solved_[first].part_b} < pair) ++first;
        if (first < solved_.size() && solved_[first].part_a == pair.a && solved_[first].part_b == pair.b)
          held = &solved_[first];
      }
      // Classified here, while the manifold is at hand (one pass over the contact list, not three).
      prepare_contact(m, bodies_, dt_, contact_.collision_threshold, held);
    }
  });
  manifolds_.resize(contacts);
  std::swap(narrow_, previous_narrow_);
  std::swap(narrow_points_, previous_narrow_points_);
  std::swap(narrow_hint_, previous_hint_);
  reserve_with_headroom(previous_pairs_, pairs_.size());
  previous_pairs_.assign(pairs_.begin(), pairs_.end());
  previous_reach_.assign(part_reach_.begin(), part_reach_.end());
}

void NativeEngine::solve_contacts() {
  // Islands (contact_islands.hpp) share no moving body, so each is solved apart: its sweeps
  // stop when its own impulses have converged (or its limits are spent), and its energy is
  // checked on its own. One island's hard case (the pile ahead of a towed iceberg, a pressed
  // chain) no longer keeps every other contact of the scene sweeping, and an island that made
  // energy is solved again without touching the rest. A scene that is one island is solved
  // exactly as one solve over all its manifolds.
  const bool checked = settings_.warm_start || settings_.accelerate;
  const double before = heavy_light_ ? contact_kinetic_energy() : 0.0;
  islands_.build(manifolds_, bodies_);
  // Blocks of islands on the pool's threads: an island touches only its own manifolds and
  // moving bodies (the velocity of a fixed or prescribed body is never written, see
  // apply_impulse), and each is solved the same way on any thread, so the result does not
  // depend on the thread count.
  const std::size_t n = islands_.size();
  // A redetection solves only the islands it marked (redetect()); an island is marked whole.
  auto kept = [&](std::size_t i) { return partial_solve_ && !resolve_[islands_.bodies(i)[0]]; };
  const std::size_t blocks = std::max<std::size_t>(1, (n + kIslandGrain - 1) / kIslandGrain);
  if (island_work_.size() < blocks) island_work_.resize(blocks + blocks / 2);
  bool any_coloured = false;
  for (std::size_t i = 0; i < n && !any_coloured; ++i) any_coloured = coloured(i);
  const std::size_t colour_bodies = any_coloured ? bodies_.inv_mass.size() : 0;
  sweep_work_.reserve(manifolds_.size(), settings_.accelerate, colour_bodies);
  if (any_coloured) {
    // The islands coloured first, so that each island's bundles get a slice of exactly their
    // number (a bound per island, bundles_for, came to a bundle a manifold for the many small
    // islands: a 768-byte bundle each, and a total that grew as the pack broke up and closed again).
    resize_with_headroom(island_bundles_, n + 1);
    island_bundles_[0] = 0;
    for (std::size_t i = 0; i < n; ++i) {
      island_bundles_[i + 1] = island_bundles_[i];
      if (!coloured(i) || kept(i)) continue;
      const SweepSpace space = sweep_work_.slice(islands_.manifold_offset(i), islands_.manifolds(i).size());
      island_bundles_[i + 1] += colour_manifolds(manifolds_, islands_.manifolds(i), bodies_, space.overflow,
                                                 space.body_colours);
    }
    sweep_work_.reserve(manifolds_.size(), settings_.accelerate, colour_bodies, island_bundles_[n]);
  }
  if (checked) {
    resize_with_headroom(island_velocity_, islands_.body_count());
    resize_with_headroom(island_angular_velocity_, islands_.body_count());
  }
  for (IslandWork& w : island_work_) w.longest = w.cold_restarts = 0;
  // A large island swept in colour order (the packed field's one large island) is left out of
  // the blocks and solved after them on every thread at once, its colours swept on the pool:
  // on two threads, the rest of the islands and it would otherwise wait for the one thread
  // that has it.
  const bool threads = thread_pool().size() > 1;
  auto large = [&](std::size_t i) {
    return threads && coloured(i) && islands_.manifolds(i).size() >= kColouredOnThreads;
  };
  thread_pool().for_blocks(n, kIslandGrain, [&](std::size_t begin, std::size_t end) {
    IslandWork& w = island_work_[begin / kIslandGrain];
    for (std::size_t i = begin; i < end; ++i)
      if (!large(i) && !kept(i)) w.longest = std::max(w.longest, solve_island(i, checked, w, false));
  });
  for (std::size_t i = 0; threads && i < n; ++i)
    if (large(i) && !kept(i)) {
      IslandWork& w = island_work_[i / kIslandGrain];
      w.longest = std::max(w.longest, solve_island(i, checked, w, true));
    }
  int longest = 0;
  for (const IslandWork& w : island_work_) {
    longest = std::max(longest, w.longest);
    cold_restarts_ += w.cold_restarts;
  }
  total_sweeps_ += longest;
  std::size_t solved = n;  // a redetection counts the islands it solved again
  if (partial_solve_)
    for (std::size_t i = 0; i < n; ++i) solved -= kept(i);
  total_islands_ += static_cast<std::int64_t>(solved);

  // Out of sweeps: an island Gauss-Seidel cannot hold (heavy-light chains) gets its normal
  // impulses solved directly. Below a mass ratio of a few hundred the sweeps hold a chain
  // (measured in the stress suite: 0.5 mm at 1e2 with 50 sweeps, 5 mm at 1e3), and a scene
  // without such a ratio between any two moving bodies never looks (heavy_light_). It looks at
  // every island, those a redetection kept too: one that the step's first pass left out of
  // sweeps was solved directly then, unless that would have made energy, and may be tried again.
  if (heavy_light_ && longest >= settings_.velocity_iterations) solve_islands_directly(before);
}

int NativeEngine::solve_island(std::size_t island, bool checked, IslandWork& work, bool threads) {
  // Gauss-Seidel from zero impulses cannot raise the kinetic energy: with a non-positive target
  // each local update moves the velocity to the constraint set along M^-1 J^T, which never
  // raises 1/2 v'Mv (a projection in the metric of M). Warm starting (last step's impulses
  // applied before the sweeps) and the conjugate-gradient steps leave that argument: when the
  // sweep limit stops the solve short of convergence (long pressed chains), what remains of the
  // warm start, or of a step, can raise it. So an island whose contact impulses would add
  // kinetic energy is solved again from zero with plain sweeps (the test: see
  // contacts_gain_energy).
  const std::span<const std::int32_t> manifolds = islands_.manifolds(island);
  const std::span<const std::int32_t> bodies = islands_.bodies(island);
  const std::size_t at = islands_.body_offset(island);  // its bodies' slice of the saved velocities
  double before = 0.0;
  if (checked) {
    before = kinetic_energy_of(bodies);
    for (std::size_t x = 0; x < bodies.size(); ++x) {
      island_velocity_[at + x] = bodies_.velocity[bodies[x]];
      island_angular_velocity_[at + x] = bodies_.angular_velocity[bodies[x]];
    }
  }
  SweepSpace space = sweep_work_.slice(islands_.manifold_offset(island), manifolds.size());
  const bool colour = coloured(island);
  if (colour) {
    space = sweep_work_.slice(islands_.manifold_offset(island), manifolds.size(), island_bundles_[island],
                              island_bundles_[island + 1] - island_bundles_[island]);
    space.colours_given = true;  // by solve_contacts
  }
  int sweeps = solve_velocities(manifolds_, manifolds, bodies_, sweep_limits(), space,
                                {.warm_start = settings_.warm_start,
                                 .accelerate = settings_.accelerate,
                                 .colour = colour,
                                 .threads = threads});
  if (!checked) return sweeps;
  double pushed = 0.0;  // the work of towed bodies on this island's floes (contacts_gain_energy)
  if (has_prescribed_)
    for (const std::int32_t k : manifolds) pushed += kinematic_work(manifolds_[k]);
  if (kinetic_energy_of(bodies) - 2.0 * pushed <= before) return sweeps;
  for (std::size_t x = 0; x < bodies.size(); ++x) {
    bodies_.velocity[bodies[x]] = island_velocity_[at + x];
    bodies_.angular_velocity[bodies[x]] = island_angular_velocity_[at + x];
  }
  for (const std::int32_t k : manifolds) {
    Manifold& m = manifolds_[k];
    for (int j = 0; j < m.point_count; ++j) m.points[j].normal_impulse = m.points[j].tangent_impulse = 0.0;
  }
  space.colours_given = false;  // the first solve kept its list of rows beyond the colours there: colour again
  sweeps += solve_velocities(manifolds_, manifolds, bodies_, sweep_limits(), space,  // plain sweeps: no energy made
                             {.colour = colour, .threads = threads});
  ++work.cold_restarts;
  return sweeps;
}

bool NativeEngine::contacts_gain_energy(double before) const {
  // A body moved on a prescribed path (towing at constant speed) does work on the floes it
  // pushes: W = sum over its contact points of p . u_k, p the impulse on the floe and u_k the
  // velocity of the towed body's point there. For one contact with target -e u_r, the floe's
  // change of kinetic energy is W + lambda u_r (1 - e) / 2 <= W (lambda >= 0 the impulse,
  // u_r < 0 the approach speed); so the test is Delta KE <= W, which is Delta KE <= 0 where
  // nothing moves on a path (the floes' energy gain from the iceberg is real, not the warm
  // start's: without W nearly every towing step was solved twice).
  return contact_kinetic_energy() - (has_prescribed_ ? 2.0 * kinematic_work() : 0.0) > before;
}

void NativeEngine::solve_islands_directly(double before) {
  // Trigger: a point still approaching faster than its target by 1e-3 of allowed_penetration /
  // dt (a creep of 1e-3 of the allowed overlap per step, which the position projection cannot
  // take back in a heavy-light chain either), in an island of mass ratio direct_solve_mass_ratio.
  const double trigger = 1e-3 * settings_.allowed_penetration / dt_;
  if (!island_solver_.select(manifolds_, bodies_, trigger, settings_.direct_solve_mass_ratio)) return;
  saved_impulses_.clear();
  for (const Manifold& m : manifolds_)
    for (int k = 0; k < m.point_count; ++k) {
      saved_impulses_.push_back(m.points[k].normal_impulse);
      saved_impulses_.push_back(m.points[k].tangent_impulse);
    }
  saved_velocity_ = bodies_.velocity;
  saved_angular_velocity_ = bodies_.angular_velocity;
  // First the normals alone, friction taken off: the sweeps' friction was found against their
  // wrong normals (in a heavy-light chain, tangential impulses of the size of the wrong normal
  // ones), and held it throws light floes sideways.
  if (!island_solver_.solve(manifolds_, bodies_, /*without_friction=*/true)) return;
  // Then sweeps bring friction back to its law for the exact normals, and the normals are
  // solved again with the friction they leave (the sweeps cannot hold the normals of a
  // heavy-light chain themselves), until the sweeps leave them within the trigger. Last,
  // friction beyond a fallen normal's cone is cut back to it, and the normals solved again with
  // the cut friction held, in turn until nothing is cut (a staggered projection: Kaufman, Sueda,
  // James and Pai, "Staggered projections for frictional contact in multibody systems", 2008).
  // Cutting alone undid the normals: a floe wedged between the iceberg and heavy floes was left
  // approaching at 0.1 m/s after 112 cuts, 18 mm of overlap in the next step (drift_in_field,
  // field seed 3; 1.4 mm deepest in that run now).
  // The sweeps run on the islands' manifolds alone (the rest stays as Gauss-Seidel left it):
  // copied out, solved, copied back.
  island_index_.assign(island_solver_.island_manifolds().begin(), island_solver_.island_manifolds().end());
  island_manifolds_.clear();
  for (const std::int32_t k : island_index_) island_manifolds_.push_back(manifolds_[k]);
  // The normals again with friction held, where a point is still left beyond the trigger.
  auto solve_normals_again = [&] {
    return island_solver_.select(island_manifolds_, bodies_, trigger, settings_.direct_solve_mass_ratio) &&
           island_solver_.solve(island_manifolds_, bodies_, /*without_friction=*/false);
  };
  for (int pass = 0; pass < 3; ++pass) {
    total_sweeps_ +=
        solve_velocities(island_manifolds_, bodies_, {settings_.velocity_iterations, settings_.tolerance},
                         sweep_work_.space(island_manifolds_.size(), false));
    if (!solve_normals_again()) break;
  }
  for (int round = 0; round < kFrictionRounds && clamp_friction(island_manifolds_, bodies_) > 0; ++round)
    if (!solve_normals_again()) break;
  for (std::size_t x = 0; x < island_index_.size(); ++x) manifolds_[island_index_[x]] = island_manifolds_[x];
  ++direct_solves_;
  if (!contacts_gain_energy(before)) return;
  // Newton's law on several simultaneous collisions can make energy in a joint solve (it cannot
  // in Gauss-Seidel's point by point): keep Gauss-Seidel's answer then.
  bodies_.velocity = saved_velocity_;
  bodies_.angular_velocity = saved_angular_velocity_;
  std::size_t x = 0;
  for (Manifold& m : manifolds_)
    for (int k = 0; k < m.point_count; ++k) {
      m.points[k].normal_impulse = saved_impulses_[x++];
      m.points[k].tangent_impulse = saved_impulses_[x++];
    }
  ++direct_reverted_;
}

double NativeEngine::kinematic_work() const {
  double w = 0.0;
  for (const Manifold& m : manifolds_) w += kinematic_work(m);
  return w;
}

double NativeEngine::kinematic_work(const Manifold& m) const {
  // Work of the contact impulses of bodies on a prescribed path on the bodies they touch
  // (fixed bodies do none: their points do not move).
  const bool a_kinematic = bodies_.inv_mass[m.body_a] == 0.0, b_kinematic = bodies_.inv_mass[m.body_b] == 0.0;
  if (!a_kinematic && !b_kinematic) return 0.0;
  double w = 0.0;
  const Vec2 t = perp(m.normal);
  for (int k = 0; k < m.point_count; ++k) {
    const ManifoldPoint& p = m.points[k];
    const Vec2 impulse_on_b = p.normal_impulse * m.normal + p.tangent_impulse * t;
    if (a_kinematic)
      w += dot(impulse_on_b, bodies_.velocity[m.body_a] + cross(bodies_.angular_velocity[m.body_a], p.ra));
    if (b_kinematic)
      w -= dot(impulse_on_b, bodies_.velocity[m.body_b] + cross(bodies_.angular_velocity[m.body_b], p.rb));
  }
  return w;
}

double NativeEngine::twice_kinetic_energy(std::size_t i) const {
  return length_squared(bodies_.velocity[i]) / bodies_.inv_mass[i] +
         bodies_.angular_velocity[i] * bodies_.angular_velocity[i] / bodies_.inv_inertia[i];
}

double NativeEngine::kinetic_energy_of(std::span<const std::int32_t> bodies) const {
  // Twice the kinetic energy of these moving bodies, as contact_kinetic_energy.
  double e = 0.0;
  for (const std::int32_t i : bodies) e += twice_kinetic_energy(static_cast<std::size_t>(i));
  return e;
}

double NativeEngine::contact_kinetic_energy() const {
  // Twice the kinetic energy of the moving bodies: enough to compare before and after.
  double e = 0.0;
  const std::size_t nb = bodies_.position.size();
  for (std::size_t i = 0; i < nb; ++i)
    if (bodies_.inv_mass[i] != 0.0) e += twice_kinetic_energy(i);
  return e;
}

void NativeEngine::apply_loads(const Loads& loads) {
  // A settled sleeper is left out: its velocity is zero, turned or pushed through its zero
  // inverse mass it stays zero.
  if (!loads.velocity_turn.empty())
    for_active_bodies(kSerial, [&](std::size_t i) { bodies_.velocity[i] = loads.velocity_turn[i].apply(bodies_.velocity[i]); });
  if (!loads.any) return;
  for_active_bodies(8192, [&](std::size_t i) {
    bodies_.velocity[i] += (dt_ * bodies_.inv_mass[i]) * loads.force[i];
    bodies_.angular_velocity[i] += dt_ * bodies_.inv_inertia[i] * loads.torque[i];
  });
}

void NativeEngine::integrate() {
  for_active_bodies(4096, [&](std::size_t i) {
    if (!moves_[i]) return;
    bodies_.position[i] += dt_ * bodies_.velocity[i];
    if (bodies_.angular_velocity[i] != 0.0) {
      bodies_.angle[i] += dt_ * bodies_.angular_velocity[i];
      bodies_.rotation[i] = Rot::from_angle(bodies_.angle[i]);
    }
  });
}

void NativeEngine::record() {
  // The step's contacts with an impulse, for the recorder; and each contact as the next step's
  // contact list reads it (carried_), in the same pass over the manifolds.
  records_.clear();
  resize_with_headroom(carried_, manifolds_.size());
  for (std::size_t i = 0; i < manifolds_.size(); ++i) {
    const Manifold& m = manifolds_[i];
    CarriedContact& c = carried_[i];
    c.part_a = m.part_a;
    c.part_b = m.part_b;
    c.point_count = m.point_count;
    for (int k = 0; k < m.point_count; ++k) {
      const ManifoldPoint& p = m.points[k];
      c.id[k] = p.id;
      c.kind[k] = p.kind;
      c.normal_impulse[k] = p.normal_impulse;
      c.tangent_impulse[k] = p.tangent_impulse;
      if (p.normal_impulse == 0.0 && p.tangent_impulse == 0.0) continue;
      records_.push_back(ContactRecord{m.body_a, m.body_b, p.point, m.normal, p.normal_impulse, p.tangent_impulse,
                                       p.approach_velocity, p.separation, p.kind});
    }
  }
}


void NativeEngine::sleep_group(std::span<const std::int32_t> bodies) {
  std::int32_t g = 0;
  if (free_groups_.empty()) {
    g = static_cast<std::int32_t>(group_first_.size());
    group_first_.push_back(-1);
  } else {
    g = free_groups_.back();
    free_groups_.pop_back();
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const std::int32_t b : bodies) {
    next_in_group_[b] = group_first_[static_cast<std::size_t>(g)];
    group_first_[static_cast<std::size_t>(g)] = b;
    sleep_group_[b] = g;
    bodies_.velocity[b] = Vec2{};
    bodies_.angular_velocity[b] = 0.0;
    bodies_.inv_mass[b] = bodies_.inv_inertia[b] = 0.0;
    sleep_force_[b] = Vec2{nan, nan};  // taken at its first step asleep, at rest
    sleep_torque_[b] = nan;
    asleep_since_[b] = steps_;
    settling_.push_back(b);
  }
  asleep_count_ += static_cast<std::int64_t>(bodies.size());
  loaded_sleepers_ += static_cast<std::int64_t>(bodies.size());
}

void NativeEngine::settle() {
  // A body asleep since the end of step s settles at the start of step s + 3 (the lists'
  // comment says why): its parts are held as placed, and the lists are made again.
  std::size_t left = 0;
  for (const std::int32_t b : settling_) {
    if (!asleep(b) || settled_[b]) continue;  // woken since (or listed twice, asleep again)
    if (steps_ < asleep_since_[b] + 3) {
      settling_[left++] = b;
      continue;
    }
    settled_[b] = 1;
    ++settled_count_;
    for (std::int32_t k = parts_.first_part(b); k < parts_.first_part(b + 1); ++k) parts_.hold(k);
    active_stale_ = true;
  }
  settling_.resize(left);
}

void NativeEngine::refresh_active() {
  if (!active_stale_) return;
  active_stale_ = false;
  active_bodies_.clear();
  active_parts_.clear();
  for (std::size_t b = 0; b < settled_.size(); ++b) {
    if (settled_[b]) continue;
    const auto body = static_cast<std::int32_t>(b);
    active_bodies_.push_back(body);
    for (std::int32_t k = parts_.first_part(body); k < parts_.first_part(body + 1); ++k) active_parts_.push_back(k);
  }
}

template <class F>
void NativeEngine::for_active_bodies(std::size_t grain, F&& f) {
  refresh_active();
  const bool skip = settled_count_ > 0;
  const std::size_t count = skip ? active_bodies_.size() : bodies_.position.size();
  auto body = [&](std::size_t j) { return skip ? static_cast<std::size_t>(active_bodies_[j]) : j; };
  if (grain == kSerial) {
    for (std::size_t j = 0; j < count; ++j) f(body(j));
    return;
  }
  thread_pool().for_blocks(count, grain, [&](std::size_t begin, std::size_t end) {
    for (std::size_t j = begin; j < end; ++j) f(body(j));
  });
}

void NativeEngine::wake_group(std::int32_t group) {
  std::int64_t count = 0;
  for (std::int32_t b = group_first_[static_cast<std::size_t>(group)]; b >= 0; b = next_in_group_[b], ++count) {
    sleep_group_[b] = -1;
    rest_time_[b] = 0.0;
    loaded_sleepers_ -= loaded_sleeper(b);
    if (settled_[b]) {
      settled_[b] = 0;
      --settled_count_;
      active_stale_ = true;
    }
    bodies_.inv_mass[b] = own_inv_mass_[b];
    bodies_.inv_inertia[b] = own_inv_inertia_[b];
    // Woken in the narrow phase: its loads may give it a reach it did not have asleep, and
    // then the step's pairs are found again (at rest in calm water it keeps none).
    if (!loads_applied_) wake_reach_grew_ = set_reach(static_cast<std::size_t>(b), step_loads_) || wake_reach_grew_;
    // Woken after the loads were applied (by a body the impulses sent into it): its own now.
    if (loads_applied_ && step_loads_) {
      bodies_.velocity[b] += (dt_ * bodies_.inv_mass[b]) * step_loads_->force[b];
      bodies_.angular_velocity[b] += dt_ * bodies_.inv_inertia[b] * step_loads_->torque[b];
    }
  }
  asleep_count_ -= count;
  group_first_[static_cast<std::size_t>(group)] = -1;
  free_groups_.push_back(group);
  ++wakes_;
}

bool NativeEngine::wake_on_loads(const Loads* loads) {
  // A sleeping body's load (forcing and applied loads) against the one it had at its first step
  // asleep: a change that would move it faster than the balance tolerance (below) wakes its
  // group. Steady wind and current on a body that does not move give the same load to the bit;
  // a changing wind, a wave or a load switched on does not.
  bool woke = false;
  auto check = [&](std::size_t b) {
    const std::int32_t g = sleep_group_[b];
    if (g < 0) return;
    const Vec2 f = loads ? loads->force[b] : Vec2{};
    const double t = loads ? loads->torque[b] : 0.0;
    if (std::isnan(sleep_torque_[b])) {
      sleep_force_[b] = f;
      sleep_torque_[b] = t;
      loaded_sleepers_ -= !loaded_sleeper(b);
      return;
    }
    if (out_of_balance(b, f - sleep_force_[b], t - sleep_torque_[b])) {
      wake_group(g);
      woke = true;
    }
  };
  // Where every sleeper's load at sleep was zero (the towing case), only a sleeper with a load
  // now can wake: with no loads, none; with the loaded bodies listed (Loads::listed), a listed one.
  if (loaded_sleepers_ == 0 && !loads) return false;
  if (loaded_sleepers_ == 0 && loads->listed) {
    for (const std::int32_t b : loads->loaded) check(static_cast<std::size_t>(b));
    return woke;
  }
  for (std::size_t b = 0; b < sleep_group_.size(); ++b) check(b);
  return woke;
}

bool NativeEngine::wake_touched() {
  // A pair with contact points (speculative ones included: within the reach of this step)
  // between a sleeping body and an awake one that moves wakes the sleeping body's group; and
  // again over the pairs, while any woke (a woken group touching the next).
  bool woke = false;
  for (bool again = true; again;) {
    again = false;
    for (std::size_t k = 0; k < pairs_.size(); ++k) {
      if (narrow_points_[k] == 0) continue;
      const std::int32_t a = parts_.body()[pairs_[k].a], b = parts_.body()[pairs_[k].b];
      const bool sa = asleep(a), sb = asleep(b);
      if (sa == sb) continue;
      const std::int32_t sleeper = sa ? a : b, other = sa ? b : a;
      if (!moves_[other]) continue;
      wake_group(sleep_group_[sleeper]);
      again = woke = true;
    }
  }
  return woke;
}

void NativeEngine::fall_asleep(bool solved) {
  // The rule (docs/model.md, sleeping): a moving body is at rest in a step when no point of it
  // moves faster than sleep_speed (|v| + |w| r, r its farthest point from the centroid). An
  // island (bodies joined by contacts) whose every body has been at rest for sleep_time falls
  // asleep, unless a towed body touches it or nothing holds it: an island without a contact with
  // a fixed (or sleeping) body must carry a net load below the balance tolerance, as must a body
  // without contacts. A body out of balance by more than sleep_speed / sleep_time leaves the
  // speed within sleep_time, so the tolerance on loads, a thousandth of that, is what the timer
  // cannot see for itself: about 1.7e-10 m/s^2 at the defaults.
  const double rest = settings_.sleep_time * (1.0 - 1e-9);  // a sum of steps, to rounding
  bool ready = false;  // any awake body at rest for sleep_time (else nothing more to look at)
  for_active_bodies(kSerial, [&](std::size_t i) {
    if (own_inv_mass_[i] == 0.0 || sleep_group_[i] >= 0) return;
    // |v| + |w| r <= sleep_speed, without the square root: |v|^2 <= (sleep_speed - |w| r)^2.
    const double left = settings_.sleep_speed - std::abs(bodies_.angular_velocity[i]) * body_radius_[i];
    const Vec2 v = bodies_.velocity[i];
    rest_time_[i] = left >= 0.0 && v.x * v.x + v.y * v.y <= left * left ? rest_time_[i] + dt_ : 0.0;
    ready = ready || rest_time_[i] >= rest;
  });
  if (!ready) return;
  if (has_prescribed_)
    for (const Manifold& m : manifolds_) {
      const bool towed_a = moves_[m.body_a] && own_inv_mass_[m.body_a] == 0.0;
      const bool towed_b = moves_[m.body_b] && own_inv_mass_[m.body_b] == 0.0;
      if (towed_a) rest_time_[m.body_b] = 0.0;
      if (towed_b) rest_time_[m.body_a] = 0.0;
    }
  auto force = [&](std::int32_t b) { return step_loads_ ? step_loads_->force[b] : Vec2{}; };
  for (std::size_t i = 0; solved && i < islands_.size(); ++i) {
    const std::span<const std::int32_t> bodies = islands_.bodies(i);
    bool rested = true;
    for (const std::int32_t b : bodies) {
      in_island_[b] = 1;
      rested = rested && rest_time_[b] >= rest;
    }
    if (!rested) continue;
    bool held = false;
    for (const std::int32_t k : islands_.manifolds(i)) {
      const Manifold& m = manifolds_[k];
      held = held || bodies_.inv_mass[m.body_a] == 0.0 || bodies_.inv_mass[m.body_b] == 0.0;
    }
    if (!held) {
      Vec2 net{};
      double mass = 0.0;
      for (const std::int32_t b : bodies) {
        net += force(b);
        mass += 1.0 / own_inv_mass_[b];
      }
      if (length(net) > balance_tolerance() * mass) continue;
    }
    sleep_group(bodies);
  }
  for_active_bodies(kSerial, [&](std::size_t i) {
    if (own_inv_mass_[i] == 0.0 || sleep_group_[i] >= 0 || in_island_[i] || rest_time_[i] < rest) return;
    const auto b = static_cast<std::int32_t>(i);
    if (out_of_balance(i, force(b), step_loads_ ? step_loads_->torque[i] : 0.0)) return;
    sleep_group({&b, 1});
  });
  if (solved)
    for (const std::int32_t b : islands_.all_bodies()) in_island_[b] = 0;  // for the next step
}

}  // namespace

std::unique_ptr<Engine> make_native_engine(const Scene& scene) { return std::make_unique<NativeEngine>(scene); }

}  // namespace floedem
