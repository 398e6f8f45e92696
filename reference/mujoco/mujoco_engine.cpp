// MuJoCo 2.2 as a reference engine: a soft, convex contact model beside the three
// complementarity solvers (docs/engines.md, "MuJoCo").
//
// The model is built in code as an MJCF text handed to MuJoCo through its virtual file system
// (nothing is written beside the run): each convex part an extruded prism as a convex mesh geom,
// each free body held in the plane by two slide joints (x, y) and a hinge (z), its mass and
// planar inertia floedem's (an explicit <inertial>, never the meshes' own); fixed bodies have no
// joints. The forcing's loads reach the joints through qfrc_applied.
//
// Contact (MuJoCo's soft constraint). With impedance d and reference acceleration
// a_ref = -B v - K d r along each contact row (r the penetration, v its rate), the solver's
// row acceleration is a1 = (1 - d) a0 + d a_ref (MuJoCo documentation, "Computation: soft
// constraints"), a0 the unconstrained one. A negative solref (-s0, -s1) gives K = s0 / dmax^2,
// B = s1 / dmax, so at d = dmax (a constant impedance: solimp dmin = dmax) the row obeys
//   r'' = -s1 r' - s0 r,
// a damped oscillator in acceleration units, the same for any mass. floedem's compliant law
// (contacts/collision_forces.hpp) is a force law: spring k = (pi / C_tau)^2 and dashpot
// c = 2 zeta sqrt(k m_eff), so that the pulse lasts pi sqrt(m_eff / k). Dividing by the pair's
// m_eff at the middle of its points (the mass the points move together; one row's own m_eff
// would count the turn the other points prevent):
//   s0 = omega^2 = k / m_eff,   s1 = 2 zeta omega,
// set per contact between MuJoCo's collision and its constraint assembly (step() below).
// Settings that matter (measured in docs/engines.md):
//  - the multi-point convex collision (mjENBL_MULTICCD): without it a mesh pair gets one point,
//    and a face-on-face contact turns about it;
//  - collisions between a body and a jointless (fixed) body: MuJoCo's parent filter would drop
//    them (a fixed body is welded to the world, every body's parent), so it is off;
//  - each prism as tall as its body is wide, so that no overlap prefers a normal along z;
//  - substeps: the pulse of the shortest collision resolved by 10 substeps at least (the
//    oscillator is integrated explicitly in r: stable only below omega h = 2);
//  - a towed (prescribed) body keeps its joints with a mass 10^6 times the heaviest free body
//    and its velocity set before and its pose after each substep, since MuJoCo has no kinematic
//    bodies (a mocap body's motion would not enter the contacts' velocities).
#include "reference/mujoco/mujoco_engine.hpp"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <mutex>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "contacts/collision_forces.hpp"
#include "geometry/polygon.hpp"
#include "reference/adapter.hpp"
#include "scenario/table_reader.hpp"

namespace floedem {

namespace {

struct MujocoSettings {
  std::string solver = "newton";    ///< newton, cg or pgs
  int iterations = 100;
  double tolerance = 1e-10;
  std::string cone = "elliptic";    ///< elliptic or pyramidal
  bool multiccd = true;
  int substeps = 0;                 ///< 0: chosen from the shortest pulse
  bool scene_solref = true;         ///< solref from the scene's law, per contact (above)
  Vec2 solref;                      ///< else MuJoCo's own, for every contact
  std::vector<double> solimp = {0.99, 0.99, 0.001, 0.5, 2.0};
  int max_contacts = 0;             ///< nconmax; 0: from the body count
};

MujocoSettings read_settings(const Scene& scene) {
  MujocoSettings s;
  reference::read_settings(scene, "mujoco", [&](TableReader& r) {
    s.solver = r.string("solver", s.solver, {"newton", "cg", "pgs"});
    s.iterations = static_cast<int>(r.integer("iterations", s.iterations, 1, 100000));
    s.tolerance = r.real("tolerance", s.tolerance, Range::non_negative());
    s.cone = r.string("cone", s.cone, {"elliptic", "pyramidal"});
    s.multiccd = r.boolean("multiccd", s.multiccd);
    if (r.has("substeps")) s.substeps = static_cast<int>(r.integer("substeps", std::nullopt, 1, 100000));
    if (r.has("solref")) {
      s.scene_solref = false;
      s.solref = r.vec2("solref", std::nullopt);
      // MuJoCo's two forms: (time constant, damping ratio), both positive, or (-stiffness,
      // -damping) in acceleration units, the stiffness negative and the damping not positive.
      const bool timeconst = s.solref.x > 0 && s.solref.y > 0, direct = s.solref.x < 0 && s.solref.y <= 0;
      if (!timeconst && !direct)
        r.fail("solref", "allowed [timeconst > 0, dampratio > 0] or [-stiffness < 0, -damping <= 0], got [" +
                             setting_text(s.solref.x) + ", " + setting_text(s.solref.y) + "]");
    }
    // MuJoCo's impedance limits (mjMINIMP, mjMAXIMP): d = 0 would make a row inert, d = 1 hard.
    const Range impedance = Range::closed(1e-4, 0.9999);
    s.solimp = r.reals("solimp", s.solimp, {impedance, impedance, Range::positive(), Range::closed(0.0, 1.0), Range::closed(1.0, 1e3)});
    if (r.has("max_contacts")) s.max_contacts = static_cast<int>(r.integer("max_contacts", std::nullopt, 1, 10000000));
  });
  return s;
}

/// MuJoCo reports errors through a global hook that exits by default: floedem throws instead
/// (the library keeps unwind tables, and a failed model is freed with the engine).
void throw_error(const char* message) { throw std::runtime_error(std::string("MuJoCo: ") + message); }
thread_local std::string* warnings = nullptr;
void keep_warning(const char* message) {
  if (warnings && warnings->empty()) *warnings = message;
}

std::string number(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

class MujocoEngine final : public Engine {
 public:
  explicit MujocoEngine(const Scene& scene);
  ~MujocoEngine() override;
  void step(const Loads* loads) override;
  const BodyStates& state() const override { return state_; }
  std::span<const ContactRecord> contacts() const override { return records_; }
  EngineInfo info() const override;
  bool save_state(StateWriter& out) const override;
  void restore_state(StateReader& in) override;
  void add_work_counts(std::vector<WorkCount>& out) const override;

 private:
  std::string model_text(const Scene& scene) const;
  void substep();
  void set_contact_parameters();
  void collect_contacts();
  void publish();

  MujocoSettings settings_;
  double dt_, h_ = 0.0;
  int substeps_ = 1;
  ContactSettings contact_;
  CompliantContact law_;
  double prescribed_mass_ = 0.0;
  std::vector<double> inv_mass_, inv_inertia_;
  std::vector<Vec2> origin_;            ///< each body's centroid at qpos = 0
  std::vector<std::int32_t> dof_;       ///< first dof (x) of each body, -1 when fixed
  std::vector<std::uint8_t> prescribed_;
  std::vector<std::int32_t> body_of_geom_;
  std::vector<double> height_;          ///< prism height per body, m
  mjModel* model_ = nullptr;
  mjData* data_ = nullptr;
  std::vector<PrescribedMotion> motion_;
  BodyStates state_, before_;
  std::vector<ContactRecord> records_;
  std::vector<std::int32_t> order_;
  std::vector<double> towed_qpos_;      ///< the towed bodies' joints before a substep's integration
  int contacts_ = 0;                    ///< MuJoCo's nconmax
  std::uint64_t contact_rows_ = 0, solver_iterations_ = 0, substeps_made_ = 0;
  double shortest_pulse_ = 0.0;
  std::string warning_;
};

std::string MujocoEngine::model_text(const Scene& scene) const {
  std::ostringstream x;
  x << "<mujoco model=\"floedem\">\n"
       "<compiler inertiafromgeom=\"false\" angle=\"radian\"/>\n";
  const int n = static_cast<int>(scene.bodies.size());
  const int rows = (settings_.cone == "elliptic" ? 3 : 4) * contacts_;
  const int nv = 3 * n;
  // The stack holds the solver's work arrays: Newton's dense nv x nv Hessian, its dense
  // product of the rows' Jacobian (rows x nv) and a few vectors per row and per dof.
  const long stack = 2L * nv * nv + 2L * rows * nv + 40L * rows + 40L * nv + 100000;
  x << "<size nconmax=\"" << contacts_ << "\" njmax=\"" << rows << "\" nstack=\"" << stack << "\"/>\n<asset>\n";
  for (int i = 0; i < n; ++i) {
    const BodySpec& b = scene.bodies[static_cast<std::size_t>(i)];
    for (std::size_t k = 0; k < b.local_parts.size(); ++k) {
      x << "<mesh name=\"m" << i << "_" << k << "\" vertex=\"";
      for (const Vec2 p : b.local_parts[k])
        for (const double z : {-0.5, 0.5}) x << number(p.x) << ' ' << number(p.y) << ' ' << number(z * height_[static_cast<std::size_t>(i)]) << ' ';
      x << "\"/>\n";
    }
  }
  x << "</asset>\n<worldbody>\n";
  for (int i = 0; i < n; ++i) {
    const std::size_t u = static_cast<std::size_t>(i);
    const BodySpec& b = scene.bodies[u];
    x << "<body name=\"b" << i << "\" pos=\"" << number(b.centroid.x) << ' ' << number(b.centroid.y) << " 0\">\n";
    if (!b.fixed) {
      const double mass = b.prescribed ? prescribed_mass_ : scene.engine_mass(u);
      const double izz = b.prescribed ? prescribed_mass_ * std::max(scene.engine_inertia(u) / scene.engine_mass(u), 1.0)
                                      : scene.engine_inertia(u);
      // Only I_zz acts in the plane; the others equal it to keep the tensor valid.
      x << "<inertial pos=\"0 0 0\" mass=\"" << number(mass) << "\" diaginertia=\"" << number(izz) << ' ' << number(izz)
        << ' ' << number(izz) << "\"/>\n"
        << "<joint type=\"slide\" axis=\"1 0 0\" limited=\"false\" damping=\"0\" armature=\"0\"/>\n"
        << "<joint type=\"slide\" axis=\"0 1 0\" limited=\"false\" damping=\"0\" armature=\"0\"/>\n"
        << "<joint type=\"hinge\" axis=\"0 0 1\" limited=\"false\" damping=\"0\" armature=\"0\"/>\n";
    }
    for (std::size_t k = 0; k < b.local_parts.size(); ++k)
      // Frictionless contacts are MuJoCo's condim 1: a cone of zero friction would hold the
      // normal force at zero too (its rows are scaled by the friction coefficients).
      x << "<geom type=\"mesh\" mesh=\"m" << i << "_" << k << "\" condim=\"" << (contact_.friction > 0.0 ? 3 : 1)
        << "\" margin=\"0\" gap=\"0\" friction=\"" << number(contact_.friction) << " 0 0\"/>\n";
    x << "</body>\n";
  }
  x << "</worldbody>\n</mujoco>\n";
  return x.str();
}

MujocoEngine::MujocoEngine(const Scene& scene)
    : settings_(read_settings(scene)), dt_(scene.run.dt), contact_(scene.contact), law_(compliant_contact(scene.contact)) {
  static std::once_flag hooks;
  std::call_once(hooks, [] {
    mju_user_error = throw_error;
    mju_user_warning = keep_warning;
  });
  const std::size_t n = scene.bodies.size();
  double heaviest = 0.0, lightest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    const BodySpec& b = scene.bodies[i];
    inv_mass_.push_back(scene.engine_inverse_mass(i));
    inv_inertia_.push_back(scene.engine_inverse_inertia(i));
    origin_.push_back(b.centroid);
    prescribed_.push_back(b.prescribed ? 1 : 0);
    const Aabb box = bounds_of(b.local_polygon);
    height_.push_back(length(box.hi - box.lo));
    if (!b.fixed && !b.prescribed) {
      heaviest = std::max(heaviest, scene.engine_mass(i));
      lightest = std::min(lightest, scene.engine_mass(i));
    }
  }
  prescribed_mass_ = 1e6 * std::max(heaviest, 1.0);
  contacts_ = settings_.max_contacts > 0 ? settings_.max_contacts : 2 * static_cast<int>(n) + 100;
  // The shortest pulse: pi sqrt(m_eff / k) with m_eff at most the lightest free body's mass
  // (half of it head-on against its like; a lever arm lowers it further, which the margin of
  // 10 substeps a pulse covers).
  shortest_pulse_ = std::isfinite(lightest) ? std::numbers::pi * std::sqrt(0.5 * lightest / law_.stiffness) : dt_;
  substeps_ = settings_.substeps > 0 ? settings_.substeps
                                     : std::max(1, static_cast<int>(std::ceil(10.0 * dt_ / shortest_pulse_)));
  h_ = dt_ / substeps_;

  const std::string text = model_text(scene);
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  const char* name = "floedem.xml";
  if (mj_makeEmptyFileVFS(vfs.get(), name, static_cast<int>(text.size())) != 0)
    throw std::runtime_error("MuJoCo: the model does not fit its virtual file system");
  const int file = mj_findFileVFS(vfs.get(), name);
  std::memcpy(vfs->filedata[file], text.data(), text.size());
  char error[1000] = "";
  model_ = mj_loadXML(name, vfs.get(), error, sizeof error);
  mj_deleteVFS(vfs.get());
  mj_freeLastXML();  // MuJoCo keeps the parsed text for mj_saveLastXML, a process-wide copy
  if (!model_) {
    // MuJoCo 2.2 allocates its data for the whole scene when it compiles the model: its
    // constraint arrays for max_contacts (some as their square) and the solver's stack.
    if (std::strstr(error, "mjData"))
      throw std::runtime_error("MuJoCo could not allocate its arrays for " + std::to_string(n) + " bodies and " +
                               std::to_string(contacts_) +
                               " contacts (it sizes them for the whole scene at the start): lower [engine.mujoco] "
                               "max_contacts, or run a smaller scene");
    throw std::runtime_error(std::string("MuJoCo could not build the scene's model: ") + error);
  }
  mjOption& o = model_->opt;
  o.timestep = h_;
  mju_zero3(o.gravity);
  o.integrator = mjINT_EULER;
  o.cone = settings_.cone == "elliptic" ? mjCONE_ELLIPTIC : mjCONE_PYRAMIDAL;
  o.solver = settings_.solver == "newton" ? mjSOL_NEWTON : settings_.solver == "cg" ? mjSOL_CG : mjSOL_PGS;
  o.iterations = settings_.iterations;
  o.tolerance = settings_.tolerance;
  o.disableflags |= mjDSBL_FILTERPARENT | mjDSBL_GRAVITY;
  if (settings_.multiccd) o.enableflags |= mjENBL_MULTICCD;
  data_ = mj_makeData(model_);
  if (!data_) throw std::runtime_error("MuJoCo could not allocate the scene's data (try a smaller [engine.mujoco] max_contacts)");

  for (int g = 0; g < model_->ngeom; ++g) body_of_geom_.push_back(model_->geom_bodyid[g] - 1);  // MuJoCo body 0: the world
  for (std::size_t i = 0; i < n; ++i) {
    const int body = static_cast<int>(i) + 1;
    dof_.push_back(model_->body_jntnum[body] > 0 ? model_->jnt_dofadr[model_->body_jntadr[body]] : -1);
    const BodySpec& b = scene.bodies[i];
    if (dof_[i] >= 0) {
      data_->qvel[dof_[i]] = b.velocity.x;
      data_->qvel[dof_[i] + 1] = b.velocity.y;
      data_->qvel[dof_[i] + 2] = b.angular_velocity;
    }
  }
  state_.resize(n);
  publish();
}

MujocoEngine::~MujocoEngine() {
  if (data_) mj_deleteData(data_);
  if (model_) mj_deleteModel(model_);
}

EngineInfo MujocoEngine::info() const {
  EngineInfo i;
  i.name = "mujoco";
  i.version = mj_versionString();
  i.settings = {{"solver", settings_.solver},
                {"iterations", std::to_string(settings_.iterations)},
                {"tolerance", setting_text(settings_.tolerance)},
                {"cone", settings_.cone},
                {"multiccd", settings_.multiccd ? "on" : "off"},
                {"substeps", std::to_string(substeps_)},
                {"substep", setting_text(h_)},
                {"shortest_pulse", setting_text(shortest_pulse_)},
                {"solref", settings_.scene_solref ? "per contact from the scene's law: [-k/m_eff, -2 zeta sqrt(k/m_eff)]"
                                                  : "[" + setting_text(settings_.solref.x) + ", " + setting_text(settings_.solref.y) + "]"},
                {"solimp", "[" + setting_text(settings_.solimp[0]) + ", " + setting_text(settings_.solimp[1]) + ", " +
                               setting_text(settings_.solimp[2]) + ", " + setting_text(settings_.solimp[3]) + ", " +
                               setting_text(settings_.solimp[4]) + "]"},
                {"max_contacts", std::to_string(model_->nconmax)},
                {"contact_model", "compliant"},
                {"contact_geometry", "MuJoCo's convex mesh collision (libccd)"},
                {"prescribed_mass", setting_text(prescribed_mass_)}};
  if (!warning_.empty()) i.settings["warning"] = warning_;
  i.settings["contact_stiffness"] = setting_text(law_.stiffness);
  i.settings["contact_damping_ratio"] = setting_text(law_.damping_ratio);
  i.limitations = {"soft contacts: bodies overlap by the spring's compression, a pulse lasts pi sqrt(m_eff / k)",
                   "one record per contact point and substep",
                   "towed bodies are heavy jointed bodies driven on their path (no kinematic bodies in MuJoCo)",
                   "MuJoCo 2.2 allocates its constraint arrays for max_contacts at the start (memory grows as its square)"};
  return i;
}

void MujocoEngine::set_contact_parameters() {
  // Between mj_collision and mj_makeConstraint: each contact's friction, impedance and, from
  // the scene's law, its pair's oscillator (s0, s1) = (k / m_eff, 2 zeta sqrt(k / m_eff)).
  const int ncon = data_->ncon;
  order_.resize(static_cast<std::size_t>(ncon));
  for (int c = 0; c < ncon; ++c) order_[static_cast<std::size_t>(c)] = c;
  const auto pair_of = [&](int c) {
    const mjContact& k = data_->contact[c];
    const std::int32_t a = body_of_geom_[static_cast<std::size_t>(k.geom1)], b = body_of_geom_[static_cast<std::size_t>(k.geom2)];
    return std::pair{std::min(a, b), std::max(a, b)};
  };
  std::stable_sort(order_.begin(), order_.end(), [&](int p, int q) { return pair_of(p) < pair_of(q); });
  for (std::size_t s = 0; s < order_.size();) {
    std::size_t e = s;
    const auto key = pair_of(order_[s]);
    Vec2 middle;
    while (e < order_.size() && pair_of(order_[e]) == key) {
      const mjtNum* p = data_->contact[order_[e]].pos;
      middle += Vec2{p[0], p[1]};
      ++e;
    }
    middle = (1.0 / static_cast<double>(e - s)) * middle;
    const auto [a, b] = key;
    const std::size_t ua = static_cast<std::size_t>(a), ub = static_cast<std::size_t>(b);
    for (std::size_t q = s; q < e; ++q) {
      mjContact& k = data_->contact[order_[q]];
      // Touching is not yet overlapping: at zero distance MuJoCo's convex collider picks a
      // normal from the touching features' round-off (a face on a face gave one at 76 degrees
      // from the true normal), and the soft contact's dashpot would act along it.
      if (k.dist > -1e-12 * height_[ua]) k.exclude = 1;
      k.friction[0] = contact_.friction;
      k.friction[1] = contact_.friction;
      std::copy(settings_.solimp.begin(), settings_.solimp.end(), k.solimp);
      if (!settings_.scene_solref) {
        k.solref[0] = settings_.solref.x;
        k.solref[1] = settings_.solref.y;
        continue;
      }
      const Vec2 normal = normalized(Vec2{k.frame[0], k.frame[1]});
      const double m_eff = effective_mass(normal, middle - state_.position[ua], inv_mass_[ua], inv_inertia_[ua],
                                          middle - state_.position[ub], inv_mass_[ub], inv_inertia_[ub]);
      const double omega = std::sqrt(law_.stiffness / m_eff);
      k.solref[0] = -omega * omega;
      k.solref[1] = -2.0 * law_.damping_ratio * omega;
    }
    s = e;
  }
}

void MujocoEngine::substep() {
  // mj_step with one stage opened up: MuJoCo 2.2's mj_fwdPosition is these calls in this order,
  // with the contacts' parameters set between collision and constraint assembly.
  mjData* d = data_;
  for (const PrescribedMotion& p : motion_) {
    d->qvel[dof_[p.body]] = p.velocity.x;
    d->qvel[dof_[p.body] + 1] = p.velocity.y;
    d->qvel[dof_[p.body] + 2] = p.angular_velocity;
  }
  mj_kinematics(model_, d);
  mj_comPos(model_, d);
  mj_tendon(model_, d);
  mj_crb(model_, d);
  mj_factorM(model_, d);
  mj_collision(model_, d);
  set_contact_parameters();
  mj_makeConstraint(model_, d);
  mj_transmission(model_, d);
  mj_projectConstraint(model_, d);
  mj_forwardSkip(model_, d, mjSTAGE_POS, 1);
  towed_qpos_.clear();
  for (const PrescribedMotion& p : motion_) towed_qpos_.insert(towed_qpos_.end(), d->qpos + dof_[p.body], d->qpos + dof_[p.body] + 3);
  collect_contacts();
  mj_Euler(model_, d);
  for (std::size_t k = 0; k < motion_.size(); ++k) {
    const PrescribedMotion& p = motion_[k];
    d->qpos[dof_[p.body]] = towed_qpos_[3 * k] + h_ * p.velocity.x;
    d->qpos[dof_[p.body] + 1] = towed_qpos_[3 * k + 1] + h_ * p.velocity.y;
    d->qpos[dof_[p.body] + 2] = towed_qpos_[3 * k + 2] + h_ * p.angular_velocity;
  }
  contact_rows_ += static_cast<std::uint64_t>(d->nefc);
  solver_iterations_ += static_cast<std::uint64_t>(d->solver_iter);
  ++substeps_made_;
  if (d->warning[mjWARN_CONTACTFULL].number > 0 || d->warning[mjWARN_CNSTRFULL].number > 0)
    throw std::runtime_error("MuJoCo: more contacts than [engine.mujoco] max_contacts = " + std::to_string(model_->nconmax) +
                             " (raise it; MuJoCo 2.2 allocates its constraint arrays for that many)");
  if (d->warning[mjWARN_BADQACC].number > 0 || d->warning[mjWARN_BADQVEL].number > 0)
    throw std::runtime_error("MuJoCo: the state became non-finite (a contact too stiff for the substep: raise "
                             "[engine.mujoco] substeps)");
}

void MujocoEngine::collect_contacts() {
  // Forces of this substep (after the constraint solve), as impulses over the substep. The
  // contact frame's first axis is the normal from geom 1 to geom 2 and mj_contactForce the
  // force of geom 1 on geom 2 in that frame.
  for (int c = 0; c < data_->ncon; ++c) {
    const mjContact& k = data_->contact[c];
    if (k.efc_address < 0) continue;
    mjtNum f[6];
    mj_contactForce(model_, data_, c, f);
    const mjtNum* fr = k.frame;
    const Vec2 on2{f[0] * fr[0] + f[1] * fr[3] + f[2] * fr[6], f[0] * fr[1] + f[1] * fr[4] + f[2] * fr[7]};
    if (on2.x == 0.0 && on2.y == 0.0) continue;
    const std::int32_t g1 = body_of_geom_[static_cast<std::size_t>(k.geom1)], g2 = body_of_geom_[static_cast<std::size_t>(k.geom2)];
    ContactRecord r =
        reference::oriented_record(g1, g2, {k.pos[0], k.pos[1]}, normalized(Vec2{fr[0], fr[1]}), h_ * on2, k.dist);
    reference::classify(r, before_, contact_.collision_threshold);
    records_.push_back(r);
  }
}

void MujocoEngine::step(const Loads* loads) {
  before_ = state_;
  records_.clear();
  motion_.clear();
  mjData* d = data_;
  mju_zero(d->qfrc_applied, model_->nv);
  if (loads)
    reference::hand_loads(
        *loads, dof_.size(), [&](std::size_t i) { return dof_[i] >= 0 && !prescribed_[i]; },
        [&](const PrescribedMotion& p) { motion_.push_back(p); },  // set on each substep
        [&](std::size_t i) { return Vec2{d->qvel[dof_[i]], d->qvel[dof_[i] + 1]}; },
        [&](std::size_t i, Vec2 v) {
          d->qvel[dof_[i]] = v.x;
          d->qvel[dof_[i] + 1] = v.y;
        },
        [&](std::size_t i, Vec2 force, double torque) {
          d->qfrc_applied[dof_[i]] = force.x;
          d->qfrc_applied[dof_[i] + 1] = force.y;
          d->qfrc_applied[dof_[i] + 2] = torque;
        });
  std::string warning;
  warnings = &warning;
  try {
    for (int s = 0; s < substeps_; ++s) substep();
  } catch (...) {
    warnings = nullptr;
    throw;
  }
  warnings = nullptr;
  if (warning_.empty() && !warning.empty()) warning_ = warning;
  publish();
}

void MujocoEngine::publish() {
  for (std::size_t i = 0; i < dof_.size(); ++i) {
    if (dof_[i] < 0) {
      state_.position[i] = origin_[i];
      continue;
    }
    const mjtNum* q = data_->qpos + dof_[i];
    const mjtNum* v = data_->qvel + dof_[i];
    state_.position[i] = origin_[i] + Vec2{q[0], q[1]};
    state_.angle[i] = q[2];
    state_.velocity[i] = {v[0], v[1]};
    state_.angular_velocity[i] = v[2];
  }
}

// Everything MuJoCo's next steps read: the joint state, the time and the solver's warm start
// (qacc_warmstart), so that a resumed run continues to the bit.
bool MujocoEngine::save_state(StateWriter& out) const {
  out.tag("mujoco");
  const auto put = [&](const mjtNum* p, int count) { out.vector(std::vector<double>(p, p + count)); };
  put(data_->qpos, model_->nq);
  put(data_->qvel, model_->nv);
  put(data_->qacc_warmstart, model_->nv);
  out.value(data_->time);
  return true;
}

void MujocoEngine::restore_state(StateReader& in) {
  in.tag("mujoco");
  std::vector<double> v;
  in.vector(v, static_cast<std::size_t>(model_->nq), "mujoco qpos");
  std::copy(v.begin(), v.end(), data_->qpos);
  in.vector(v, static_cast<std::size_t>(model_->nv), "mujoco qvel");
  std::copy(v.begin(), v.end(), data_->qvel);
  in.vector(v, static_cast<std::size_t>(model_->nv), "mujoco qacc_warmstart");
  std::copy(v.begin(), v.end(), data_->qacc_warmstart);
  in.value(data_->time);
  publish();
}

void MujocoEngine::add_work_counts(std::vector<WorkCount>& out) const {
  out.push_back({"substeps", static_cast<double>(substeps_made_)});
  out.push_back({"constraint_rows", static_cast<double>(contact_rows_)});
  out.push_back({"solver_iterations", static_cast<double>(solver_iterations_)});
}

}  // namespace

std::unique_ptr<Engine> make_mujoco_engine(const Scene& scene) { return std::make_unique<MujocoEngine>(scene); }

}  // namespace floedem
