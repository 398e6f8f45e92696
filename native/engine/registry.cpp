#include "engine/registry.hpp"

#include "scene/input_error.hpp"
#include "reference/box2d/box2d_engine.hpp"
#include "reference/bullet/bullet_engine.hpp"
#include "reference/ode/ode_engine.hpp"
#include "solver/native_engine.hpp"

namespace floedem {

const std::vector<EngineEntry>& engines() {
  static const std::vector<EngineEntry> table = {
      {"native", "floedem's planar non-smooth DEM (sequential impulses, exact local Coulomb solve)",
       make_native_engine},
      {"box2d", "Box2D 2.4 (reference): the polygons themselves, restitution threshold 0, polygon radius 0",
       make_box2d_engine},
      {"bullet", "Bullet 3 double (reference): extruded prisms held in the plane, split impulse, max/min combine",
       make_bullet_engine},
      {"ode", "ODE 0.16 double (reference): plane-2D joints, QuickStep, contact points from floedem's 2-D narrow phase",
       make_ode_engine},
  };
  return table;
}

std::unique_ptr<Engine> make_engine(const std::string& name, const Scene& scene) {
  std::string known;
  for (const auto& e : engines()) known += (known.empty() ? "" : ", ") + e.name;
  for (const auto& [key, table] : scene.engine_settings) {
    bool found = false;
    for (const auto& e : engines()) found = found || e.name == key;
    if (!found)
      throw InputError(input_message(scene.source_path, table.source().begin.line, "engine." + key,
                                     "unknown engine; allowed one of " + known));
  }
  for (const auto& e : engines())
    if (e.name == name) return e.make(scene);
  throw InputError("--engine " + name + ": unknown engine; allowed one of " + known);
}

}  // namespace floedem
