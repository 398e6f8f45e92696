#include "floedem/engine/registry.hpp"

#include <cctype>
#include <stdexcept>

#include "floedem/scene/input_error.hpp"
#include "solver/native_engine.hpp"
#ifdef FLOEDEM_WITH_BOX2D
#include "reference/box2d/box2d_engine.hpp"
#endif
#ifdef FLOEDEM_WITH_BULLET
#include "reference/bullet/bullet_engine.hpp"
#endif
#ifdef FLOEDEM_WITH_MUJOCO
#include "reference/mujoco/mujoco_engine.hpp"
#endif
#ifdef FLOEDEM_WITH_ODE
#include "reference/ode/ode_engine.hpp"
#endif

namespace floedem {

namespace {

std::vector<EngineEntry>& table() {
  static std::vector<EngineEntry> t = {
      {"native", "floedem's planar non-smooth DEM (sequential impulses, exact local Coulomb solve)",
       make_native_engine},
#ifdef FLOEDEM_WITH_BOX2D
      {"box2d", "Box2D 2.4 (reference): the polygons themselves, restitution threshold 0, polygon radius 0",
       make_box2d_engine},
#endif
#ifdef FLOEDEM_WITH_BULLET
      {"bullet", "Bullet 3 double (reference): extruded prisms held in the plane, split impulse, max/min combine",
       make_bullet_engine},
#endif
#ifdef FLOEDEM_WITH_MUJOCO
      {"mujoco", "MuJoCo 2.2 (reference): soft contacts by convex optimisation, extruded prisms on planar joints",
       make_mujoco_engine},
#endif
#ifdef FLOEDEM_WITH_ODE
      {"ode", "ODE 0.16 double (reference): plane-2D joints, QuickStep, contact points from floedem's 2-D narrow phase",
       make_ode_engine},
#endif
  };
  return t;
}

/// floedem's reference engines, built or not: a scenario's settings for one this build lacks
/// are kept for the builds that have it, not refused as a misspelt name.
std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

constexpr const char* kReferenceNames[] = {"box2d", "bullet", "mujoco", "ode"};

}  // namespace

const std::vector<EngineEntry>& engines() { return table(); }

void register_engine(EngineEntry entry) {
  if (entry.name.empty()) throw std::invalid_argument("register_engine: the engine has no name");
  for (const char c : entry.name)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-'))
      throw std::invalid_argument("register_engine: '" + entry.name +
                                  "': allowed letters, digits, '_' and '-' (the name is a TOML key and a file name)");
  for (const auto& e : table())
    if (e.name == entry.name) throw std::invalid_argument("register_engine: an engine '" + entry.name + "' is known already");
  if (!entry.make) throw std::invalid_argument("register_engine: '" + entry.name + "' has no factory");
  table().push_back(std::move(entry));
}

std::unique_ptr<Engine> make_engine(const std::string& name, const Scene& scene) {
  std::string known;
  for (const auto& e : engines()) known += (known.empty() ? "" : ", ") + e.name;
  for (const auto& [key, settings] : scene.engine_settings) {
    bool found = false;
    for (const auto& e : engines()) found = found || e.name == key;
    for (const char* r : kReferenceNames) found = found || key == r;
    if (!found)
      throw InputError(input_message(scene.source_path, settings.source().begin.line, "engine." + key,
                                     "unknown engine; allowed one of " + known));
  }
  for (const auto& e : engines())
    if (e.name == name) return e.make(scene);
  for (const char* r : kReferenceNames)
    if (name == r)
      throw InputError("--engine " + name + ": this build has no " + name + " engine (configured with FLOEDEM_WITH_" +
                       upper(name) + "=OFF, or its library was not found); allowed one of " + known);
  throw InputError("--engine " + name + ": unknown engine; allowed one of " + known);
}

}  // namespace floedem
