#include "scene/scene.hpp"

#include <cmath>

#include "geometry/convex_partition.hpp"
#include "geometry/polygon.hpp"
#include "scene/input_error.hpp"

namespace floedem {

std::string input_message(const std::string& file, std::uint32_t line, const std::string& field,
                          const std::string& what) {
  std::string m = file;
  if (line > 0) {
    m.push_back(':');
    m.append(std::to_string(line));
  }
  m.append(": ");
  if (!field.empty()) {
    m.append("field '");
    m.append(field);
    m.append("': ");
  }
  m.append(what);
  return m;
}

std::int64_t RunSettings::steps() const {
  const double n = std::round(duration / dt);
  return n < 1.0 ? 1 : static_cast<std::int64_t>(n);
}

void Scene::derive() {
  for (BodySpec& b : bodies) {
    const AreaMoments m = area_moments(b.polygon);
    b.area = m.area;
    b.centroid = m.centroid;
    b.mass = b.density * b.thickness * m.area;
    b.inertia = b.density * b.thickness * m.polar_moment;
    b.local_polygon.clear();
    for (const Vec2 p : b.polygon) b.local_polygon.push_back(p - m.centroid);
    b.local_parts = convex_partition(b.local_polygon);
    if (b.local_parts.empty())
      throw InputError(input_message(source_path, 0, "body '" + b.name + "'.polygon",
                                     "could not be split into convex parts"));
  }
}

}  // namespace floedem
