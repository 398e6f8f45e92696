#pragma once
// Engines by name. Adding an engine is one source file that defines a factory and one line
// in registry.cpp's table.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "engine/engine.hpp"

namespace floedem {

/// Builds an engine for a scene. Reads and checks the scene's [engine.NAME] table (throwing
/// InputError for bad settings) before anything else.
using EngineFactory = std::function<std::unique_ptr<Engine>(const Scene&)>;

struct EngineEntry {
  std::string name;
  std::string description;
  EngineFactory make;
};

/// Every engine this build has, in a fixed order (native first).
const std::vector<EngineEntry>& engines();

/// Builds the named engine; InputError naming the known engines when there is none such,
/// or when the scene has settings for an engine this build does not know.
std::unique_ptr<Engine> make_engine(const std::string& name, const Scene& scene);

}  // namespace floedem
