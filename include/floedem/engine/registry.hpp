#pragma once
// Engines by name: the native engine, the reference engines this build has (FLOEDEM_WITH_ODE,
// _BULLET, _BOX2D), and any a program registers. An engine of floedem's own is one source file
// that defines a factory and one line in the table of run/registry.cpp; an engine of yours is
// one call to register_engine() (docs/extending.md, examples/).
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "floedem/engine/engine.hpp"

namespace floedem {

/// Builds an engine for a scene. Reads and checks the scene's [engine.NAME] table (throwing
/// InputError for bad settings) before anything else.
using EngineFactory = std::function<std::unique_ptr<Engine>(const Scene&)>;

struct EngineEntry {
  std::string name;
  std::string description;
  EngineFactory make;
};

/// Every engine known, in a fixed order: native first, then the reference engines of this
/// build, then those registered, in the order of registration.
const std::vector<EngineEntry>& engines();

/// Adds an engine under its name, after those already known: make_engine(), run_scene() and
/// a scenario's [engine.NAME] table know it from then on. Call it before any run starts (the
/// table is not locked). std::invalid_argument for an empty name, one with characters other
/// than letters, digits, '_' and '-', a name already known, or an empty factory.
void register_engine(EngineEntry entry);

/// Builds the named engine; InputError naming the known engines when there is none such,
/// or when the scene has settings for an engine this build does not know.
std::unique_ptr<Engine> make_engine(const std::string& name, const Scene& scene);

}  // namespace floedem
