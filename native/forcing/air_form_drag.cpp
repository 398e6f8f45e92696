// Air form drag on the sail (MODEL.md 2; Bigg et al. 1997):
//   F = 1/2 rho_a C_a A_sail |V_a - v| (V_a - v),  A_sail = projected width x freeboard,
// integrated over the waterline polygon (drag.hpp), which gives its torque too.
#include "forcing/drag.hpp"

namespace floedem {

namespace {

class AirFormDrag final : public ForceTerm {
 public:
  explicit AirFormDrag(const Scene& scene)
      : settings_{scene.environment.rotational_damping, scene.environment.drag_reference_speed},
        wind_(scene.environment.wind) {
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
      const BodySpec& b = scene.bodies[i];
      if (b.fixed || b.drag.air_form == 0.0 || b.freeboard <= 0.0 || scene.environment.air_density == 0.0) continue;
      entries_.push_back({i, 0.5 * scene.environment.air_density * b.drag.air_form * b.freeboard, edge_points(b.local_polygon)});
    }
  }
  bool empty() const { return entries_.empty(); }
  std::string_view name() const override { return "air_form_drag"; }
  void add(const BodyStates& s, double, ForceSums& sums) const override {
    for (const Entry& e : entries_)
      add_form_drag(sums, e.body, e.edges, 1.0, e.c, wind_, s.velocity[e.body], s.angular_velocity[e.body],
                    Rot::from_angle(s.angle[e.body]), settings_);
  }

 private:
  struct Entry {
    std::size_t body;
    double c;  ///< 1/2 rho_a C_a h_sail
    std::vector<EdgePoint> edges;
  };
  DragSettings settings_;
  Vec2 wind_;
  std::vector<Entry> entries_;
};

}  // namespace

std::unique_ptr<ForceTerm> build_air_form_drag(const Scene& scene) {
  if (!scene.has_environment) return nullptr;
  auto t = std::make_unique<AirFormDrag>(scene);
  return t->empty() ? nullptr : std::move(t);
}

}  // namespace floedem
