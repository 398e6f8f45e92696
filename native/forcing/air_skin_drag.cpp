// Air skin drag on the top (MODEL.md 2): F = rho_a C_da A_top |V_a - v| (V_a - v),
// integrated over the waterline polygon (drag.hpp), which gives its torque too.
#include "forcing/drag.hpp"

namespace floedem {

namespace {

class AirSkinDrag final : public ForceTerm {
 public:
  explicit AirSkinDrag(const Scene& scene)
      : settings_{scene.environment.rotational_damping, scene.environment.drag_reference_speed},
        wind_(scene.environment.wind) {
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
      const BodySpec& b = scene.bodies[i];
      if (b.fixed || b.drag.air_skin == 0.0 || scene.environment.air_density == 0.0) continue;
      entries_.push_back({i, scene.environment.air_density * b.drag.air_skin, area_points(b.local_polygon)});
    }
  }
  bool empty() const { return entries_.empty(); }
  std::string_view name() const override { return "air_skin_drag"; }
  void add(const BodyStates& s, double, ForceSums& sums) const override {
    for (const Entry& e : entries_)
      add_skin_drag(sums, e.body, e.points, 1.0, e.rho_c, wind_, s.velocity[e.body], s.angular_velocity[e.body],
                    Rot::from_angle(s.angle[e.body]), settings_);
  }

 private:
  struct Entry {
    std::size_t body;
    double rho_c;
    std::vector<AreaPoint> points;
  };
  DragSettings settings_;
  Vec2 wind_;
  std::vector<Entry> entries_;
};

}  // namespace

std::unique_ptr<ForceTerm> build_air_skin_drag(const Scene& scene) {
  if (!scene.has_environment) return nullptr;
  auto t = std::make_unique<AirSkinDrag>(scene);
  return t->empty() ? nullptr : std::move(t);
}

}  // namespace floedem
