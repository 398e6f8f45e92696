#pragma once
// Contact loads on chosen bodies ([output] loads): the force the other bodies exert on each
// through contact, as means over the steps between rows of /loads. For a grounded iceberg or a
// structure this is the ice load; for a towed body, the ice part of the towing force (towing/).
#include <cstdint>
#include <span>
#include <vector>

#include "floedem/engine/engine.hpp"
#include "floedem/scene/scene.hpp"

namespace floedem {

/// The step's contact impulse on `body` (N s): normal and friction impulses of its points, the
/// normal pointing from body_a to body_b (so body_b receives +p, body_a -p).
Vec2 contact_impulse_on(std::int32_t body, std::span<const ContactRecord> contacts);

class ContactLoads {
 public:
  explicit ContactLoads(const Scene& scene);
  bool active() const { return !bodies_.empty(); }
  void after_step(std::span<const ContactRecord> contacts);
  /// N, per listed body: the mean contact force over the steps since the last call.
  const std::vector<Vec2>& take_row();
  /// Checkpoint: the sums of the row under way.
  void save(StateWriter& out) const;
  void restore(StateReader& in);

 private:
  std::vector<std::int32_t> bodies_;
  double dt_ = 0.0;
  std::vector<Vec2> sum_, row_;
  long steps_ = 0;
};

}  // namespace floedem
