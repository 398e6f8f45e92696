#pragma once
// Collision forces from impulses (docs/model.md section 4; the paper's central proposal).
//
// The solver resolves a collision within one step, but a real one lasts longer: about
//   tau = C_tau sqrt(m_eff),   m_eff = 1 / (n . M^-1 n)
// at the contact point (rotation included: m_eff = 1 / (1/m_a + (r_a x n)^2 / I_a + 1/m_b +
// (r_b x n)^2 / I_b), the reduced mass m_a m_b / (m_a + m_b) for a head-on hit). This is what a
// linear contact spring of stiffness k gives: a half-sine pulse of duration pi sqrt(m_eff / k),
// so C_tau = pi / sqrt(k). From the collision impulse J the force over the pulse is
//   mean force  J / tau,      peak force  pi J / (2 tau)   (half-sine: integral = 2 F tau / pi).
// A resting contact's force is its impulse divided by dt (not tracked here).
//
// A collision event is one pair of bodies from the step of first impact to the first step in
// which the pair has no contact (separation), possibly several points and steps: J adds up the
// collision impulses of the event; m_eff, approach speed and restitution are those of the impact
// step, at the impulse-weighted contact point. Engine-neutral: it reads the ContactRecords every
// engine reports.
#include <cstdint>
#include <map>
#include <string>
#include <span>
#include <utility>
#include <vector>

#include "floedem/engine/engine.hpp"
#include "floedem/scene/scene.hpp"

namespace floedem {

struct CollisionRow {
  double time = 0.0;                  ///< s, end of the impact step
  std::int32_t body_a = 0, body_b = 0;///< a < b
  double normal_impulse = 0.0;        ///< N s, J: the event's collision impulses added up
  double effective_mass = 0.0;        ///< kg, m_eff along the normal at the contact point
  double approach_speed = 0.0;        ///< m/s, normal closing speed before impact (> 0)
  double restitution_achieved = 0.0;  ///< normal separation speed after the impact step / approach speed
  double duration = 0.0;              ///< s, tau = C_tau sqrt(m_eff)
  double mean_force = 0.0;            ///< N, J / tau
  double peak_force = 0.0;            ///< N, pi J / (2 tau)
  double contact_width = 0.0;         ///< m, pressure_area: the nominal contact width at the peak
  std::uint8_t crushed = 0;           ///< pressure_area: 1 where the crushing pressure capped the force
};

/// docs/model.md 4: the half-sine pulse of a linear spring.
double collision_duration(double duration_coefficient, double effective_mass);
double collision_mean_force(double impulse, double duration);
double collision_peak_force(double impulse, double duration);

/// The pressure-area model (docs/model.md 4): the contact force of the linear model's spring,
/// k delta, capped by the crushing force of the nominal contact area,
///   F(delta) = min(k delta, p(w, h) w h),   p = C_R (h / 1 m)^n (w / h)^m   (ISO 19906 A.8.2.4.3.3),
///   w(delta) = w0 + g delta
/// (delta: the overlap along the normal; h: the thinner body's thickness; w0: the spread of the
/// impact step's contact points; g = 2 tan(alpha / 2) where a corner of interior angle alpha
/// meets the other body, 0 for a face on a face). The pulse is the linear model's: symmetric,
/// half the impulse J loading (m_eff from J / (2 m_eff) to rest against F) and half unloading
/// its mirror image, so that where the cap is never reached it is the linear model's half-sine.
struct CrushingLaw {
  double stiffness = 0.0;            ///< k = (pi / C_tau)^2, N/m
  double coefficient = 0.0;          ///< C_R, Pa
  double width_exponent = 0.0;       ///< m
  double thickness_exponent = 0.0;   ///< n
  bool iso_thickness_exponent = true;///< n = min(-0.3, 0.2 h - 0.5) (h in m) instead
  static CrushingLaw of(const ContactSettings& contact);
  double exponent_n(double thickness) const;
};
struct ContactWidth {
  double thickness = 0.0;  ///< h, m
  double initial = 0.0;    ///< w0, m
  double growth = 0.0;     ///< g, m of width per m of overlap
};
struct CrushingPulse {
  double duration = 0.0;     ///< s, twice the loading time
  double peak_force = 0.0;   ///< N, F at the deepest overlap
  double width = 0.0;        ///< m, w at the deepest overlap
  double overlap = 0.0;      ///< m, the deepest overlap
  bool crushed = false;      ///< the cap was reached
};
CrushingPulse crushing_pulse(double impulse, double effective_mass, const CrushingLaw& law, const ContactWidth& width);
/// The contact thickness of a body: a floe's thickness, an iceberg's draft plus sail height.
double contact_thickness(const BodySpec& body);
/// The nominal contact width's law at an impact: the spread of its points across the normal
/// (`spread`), and where it is a point (spread below 1 % of the smaller body's size) the
/// growth 2 tan(alpha / 2) of the sharper corner at `point` (the corner nearest the point,
/// within that 1 %, of either body). Poses at the start of the impact step.
ContactWidth contact_width_law(const BodySpec& a, Vec2 xa, double angle_a, const BodySpec& b, Vec2 xb, double angle_b,
                               Vec2 point, double spread);

/// m_eff = 1 / (n . M^-1 n) at a point; inverse mass and inertia 0 for a fixed body.
double effective_mass(Vec2 normal, Vec2 r_a, double inv_mass_a, double inv_inertia_a, Vec2 r_b, double inv_mass_b,
                      double inv_inertia_b);

/// How an event's duration is found: estimated from the impulse (tau = C_tau sqrt(m_eff), for
/// engines that resolve a collision in one step), or measured (a compliant engine: the steps
/// from first to last with contact force, the peak of the step forces impulse / dt, J their
/// sum, the restitution from the relative normal velocity once the pair has separated).
enum class DurationModel : std::uint8_t { estimated, measured };

/// The model for an engine: measured when its settings say contact_model = "compliant".
DurationModel duration_model_of(const EngineInfo& engine);
const char* describe(DurationModel model);

/// The compliant contact the reference engines use for measured durations (docs/model.md 4): a
/// linear spring k = (pi / C_tau)^2, so that its undamped half-sine lasts native's estimate
/// C_tau sqrt(m_eff), and a dashpot c = 2 zeta sqrt(k m_eff) with zeta from the restitution,
/// e = exp(-zeta pi / sqrt(1 - zeta^2)) <=> zeta = -ln e / sqrt(pi^2 + ln^2 e) (e = 0: zeta = 1).
struct CompliantContact {
  double stiffness = 0.0;      ///< N/m
  double damping_ratio = 0.0;  ///< zeta
};
CompliantContact compliant_contact(const ContactSettings& contact);

/// The compliant contact as the reference engines apply it: a pair's spring and dashpot
/// shared by its `points` touching points, the dashpot from the pair's m_eff along the normal
/// at the points' middle (at a single corner point m_eff would count the turn that the other
/// points' springs prevent: 0.4 m instead of m for a face contact).
class CompliantContacts {
 public:
  explicit CompliantContacts(const Scene& scene);
  struct PerPoint {
    double stiffness = 0.0;  ///< N/m
    double damping = 0.0;    ///< N s/m
  };
  /// r_a, r_b: lever arms of the points' middle from the centroids of bodies a and b.
  PerPoint per_point(std::size_t a, std::size_t b, Vec2 normal, Vec2 r_a, Vec2 r_b, int points) const;
  /// contact_stiffness and contact_damping_ratio, for EngineInfo::settings.
  void describe(std::map<std::string, std::string>& settings) const;

 private:
  CompliantContact law_;
  std::vector<double> inv_mass_, inv_inertia_;
};

class CollisionTracker {
 public:
  explicit CollisionTracker(const Scene& scene, DurationModel model = DurationModel::estimated);

  /// After each step: that step's contacts and the state after it. Events that ended (their
  /// pair had no contact this step) are appended to `finished`, in pair order.
  void observe(double t_end, std::span<const ContactRecord> contacts, const BodyStates& after,
               std::vector<CollisionRow>& finished);
  /// At the end of the run: the events still open, in pair order.
  void finish(const BodyStates& now, std::vector<CollisionRow>& finished);
  /// Checkpoint: the step count and the events still open.
  void save(StateWriter& out) const;
  void restore(StateReader& in);

 private:
  struct Event {
    CollisionRow row;
    std::int64_t first_step = 0, last_step = 0;
    double peak_step_impulse = 0.0;  ///< measured: the largest step impulse
    Vec2 normal;                     ///< measured: for the restitution at separation
    Vec2 local_a, local_b;           ///< measured: the contact point in each body's frame
    ContactWidth width;              ///< pressure_area: the nominal contact width's law
  };
  struct StepPair {
    std::int32_t a = 0, b = 0;
    double collision_impulse = 0.0;  ///< N s, this step's collision impulses
    Vec2 weighted_point, weighted_normal;
    double weighted_approach = 0.0;
    double impulse = 0.0;            ///< N s, all this step's normal impulses (measured model)
    Vec2 tangent;                    ///< pressure_area: across the first point's normal
    double spread_min = 0.0, spread_max = 0.0;  ///< pressure_area: the points along `tangent`
  };
  using PairKey = std::pair<std::int32_t, std::int32_t>;
  /// An event under way: its pair and its slot in events_ (ids, not the events, are merged).
  struct OpenEvent {
    PairKey key;
    std::int32_t slot = 0;
  };
  CollisionRow complete(const Event& event, const BodyStates& now) const;  ///< duration, forces, restitution
  Event open_event(double t_end, const StepPair& pair, const BodyStates& after) const;
  void sum_by_pair(std::span<const ContactRecord> contacts);
  std::int32_t store(const Event& event);

  const Scene& scene_;
  double c_tau_ = 0.0, dt_ = 0.0, threshold_ = 0.0;
  DurationModel model_ = DurationModel::estimated;
  bool crushing_ = false;  ///< contact.force_model = pressure_area
  CrushingLaw crushing_law_;
  std::int64_t step_ = 0;
  // The step's pairs and the open events, each a list sorted by pair, merged in one pass each
  // step; their buffers are kept, so a step allocates nothing once they have grown (a std::map
  // made a node for each pair in contact every step and freed it: a fifth of `floedem run`'s
  // time on the 100k-floe field).
  std::vector<StepPair> step_pairs_;
  std::vector<std::int32_t> order_;  ///< the records in pair order, where the list is not (stable)
  std::vector<OpenEvent> open_, next_open_;
  std::vector<Event> events_;
  std::vector<std::int32_t> free_slots_;
};

}  // namespace floedem
