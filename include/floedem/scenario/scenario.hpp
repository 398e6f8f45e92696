#pragma once
// Scenario file (TOML) -> Scene. Every field is documented in scenarios/README.md.
#include <string>
#include <vector>

#include "floedem/scene/scene.hpp"

namespace floedem {

/// Reads, overrides, checks and derives a scene. Throws InputError on any bad input.
/// overrides: "KEY=VALUE" strings (KEY dotted, with [i] for array elements, e.g.
/// "run.duration=60", "body[2].density=917"); VALUE is a TOML value, or a bare word taken
/// as a string.
Scene load_scenario(const std::string& path, const std::vector<std::string>& overrides = {});

/// The same from text already in memory; `path` is used in messages only.
Scene parse_scenario(const std::string& text, const std::string& path,
                     const std::vector<std::string>& overrides = {});

}  // namespace floedem
