#pragma once
// Non-contact forcing as small independent units. Each term adds its force and torque to the
// loads of the step; a term a scene does not use is never built, so it costs nothing.
// The same terms drive every engine, so that engines differ only in contact.
// Adding a term: one source file with a builder, and one line in forcing.cpp's table.
#include <memory>
#include <string_view>
#include <vector>

#include "engine/engine.hpp"
#include "scene/scene.hpp"

namespace floedem {

class ForceTerm {
 public:
  virtual ~ForceTerm() = default;
  virtual std::string_view name() const = 0;
  /// Adds this term's force and torque on each body at the start of a step at `time`.
  virtual void add(const BodyStates& state, double time, Loads& loads) const = 0;
};

/// Builds the term for a scene, or returns nullptr when the scene does not use it.
using ForceTermBuilder = std::unique_ptr<ForceTerm> (*)(const Scene&);

/// The terms a scene uses, evaluated together each step.
class Forcing {
 public:
  explicit Forcing(const Scene& scene);
  bool empty() const { return terms_.empty(); }
  std::vector<std::string_view> names() const;
  /// Loads at the start of a step, or nullptr when the scene has no forcing at all.
  const Loads* evaluate(const BodyStates& state, double time);

 private:
  std::vector<std::unique_ptr<ForceTerm>> terms_;
  Loads loads_;
};

// Builders (one per term file).
std::unique_ptr<ForceTerm> build_applied_load(const Scene& scene);

}  // namespace floedem
