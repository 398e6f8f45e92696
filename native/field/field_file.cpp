#include "floedem/field/field_file.hpp"

#include <filesystem>
#include <sstream>

#include "floedem/engine/engine.hpp"
#include "io/recorder.hpp"

namespace floedem {

std::vector<BodySpec> field_floes(const Field& field, double density, const std::string& prefix) {
  std::vector<BodySpec> out;
  out.reserve(field.floes.size());
  for (std::size_t i = 0; i < field.floes.size(); ++i) {
    BodySpec b;
    b.name = prefix + std::to_string(i);
    b.kind = BodyKind::floe;
    b.polygon = field.floes[i];
    b.thickness = field.thickness[i];
    b.density = density;
    out.push_back(std::move(b));
  }
  return out;
}

std::string describe(const ThicknessDistribution& t) {
  std::ostringstream s;
  s.precision(6);
  switch (t.kind) {
    case ThicknessDistribution::Kind::constant: s << t.value << " m"; break;
    case ThicknessDistribution::Kind::uniform: s << "uniform on [" << t.min << ", " << t.max << "] m"; break;
    case ThicknessDistribution::Kind::lognormal: s << "lognormal, mean " << t.mean << " m, std " << t.std << " m"; break;
  }
  return s.str();
}

Provenance field_provenance(const Field& field, const FieldSpec& spec, double density, std::size_t first_floe) {
  const FieldStats& st = field.stats;
  return {"/field",
          {{"method", "power diagram with cells of prescribed areas (damped Newton), Lloyd steps, cells shrunk to the floe areas"},
           {"thickness", describe(spec.thickness)},
           {"seed", std::to_string(spec.seed)}},
          {{"origin_x", spec.origin.x},
           {"origin_y", spec.origin.y},
           {"width", spec.width},
           {"height", spec.height},
           {"concentration", spec.concentration},
           {"alpha", spec.alpha},
           {"d_min", spec.d_min},
           {"d_max", spec.d_max},
           {"irregularity", spec.irregularity},
           {"density", density},
           {"floes", static_cast<double>(st.floes)},
           {"first_floe", static_cast<double>(first_floe)},
           {"free_area", st.free_area},
           {"ice_area", st.ice_area},
           {"concentration_achieved", st.concentration},
           {"alpha_fitted", st.fit.alpha},
           {"alpha_fitted_stderr", st.fit.stderr_alpha},
           {"newton_iterations", static_cast<double>(st.newton_iterations)},
           {"lloyd_steps", static_cast<double>(st.lloyd_steps)},
           {"max_cell_area_error", st.max_cell_area_error},
           {"floes_short_of_area", static_cast<double>(st.floes_short_of_area)},
           {"floes_dropped_below_d_min", static_cast<double>(st.floes_dropped_below_d_min)}}};
}

std::vector<Provenance> chart_provenance(const Field& field, const IceChart& chart, const std::vector<ChartPolygonStats>& stats,
                                         const FieldSpec& spec, double density, std::size_t first_floe) {
  std::vector<Provenance> out;
  out.push_back({"/field",
                 {{"method", "ice chart: each polygon's part inside the rectangle, free of bodies and keep-out zones, filled "
                             "by the generator with the concentration, floe sizes and thickness of its SIGRID-3 codes"},
                  {"chart", std::filesystem::path(chart.path).filename().string()},
                  {"layer", chart.layer},
                  {"seed", std::to_string(spec.seed)}},
                 {{"origin_x", spec.origin.x},
                  {"origin_y", spec.origin.y},
                  {"width", spec.width},
                  {"height", spec.height},
                  {"alpha", spec.alpha},
                  {"irregularity", spec.irregularity},
                  {"density", density},
                  {"polygons", static_cast<double>(chart.polygons.size())},
                  {"floes", static_cast<double>(field.stats.floes)},
                  {"first_floe", static_cast<double>(first_floe)},
                  {"free_area", field.stats.free_area},
                  {"ice_area", field.stats.ice_area},
                  {"concentration_achieved", field.stats.concentration},
                  {"newton_iterations", static_cast<double>(field.stats.newton_iterations)},
                  {"max_cell_area_error", field.stats.max_cell_area_error},
                  {"floes_short_of_area", static_cast<double>(field.stats.floes_short_of_area)},
                  {"floes_dropped_below_d_min", static_cast<double>(field.stats.floes_dropped_below_d_min)}}});
  for (std::size_t i = 0; i < stats.size(); ++i) {
    const ChartPolygon& p = chart.polygons[i];
    const ChartPolygonStats& st = stats[i];
    out.push_back({"/field/chart_feature_" + std::to_string(p.fid),
                   {},
                   {{"fid", static_cast<double>(p.fid)},
                    {"CT", static_cast<double>(p.ct)},
                    {"SA", static_cast<double>(p.sa)},
                    {"FA", static_cast<double>(p.fa)},
                    {"concentration", p.concentration},
                    {"d_min", p.d_min},
                    {"d_max", p.d_max},
                    {"d_max_used", st.d_max_used},
                    {"thickness_min", p.thickness_min},
                    {"thickness_max", p.thickness_max},
                    {"area", st.area},
                    {"free_area", st.free_area},
                    {"ice_area", st.ice_area},
                    {"concentration_achieved", st.free_area > 0.0 ? st.ice_area / st.free_area : 0.0},
                    {"floes", static_cast<double>(st.floes)},
                    {"pieces", static_cast<double>(st.pieces)},
                    {"pieces_too_small", static_cast<double>(st.pieces_too_small)},
                    {"alpha_fitted", st.fit.alpha},
                    {"alpha_fitted_stderr", st.fit.stderr_alpha}}});
  }
  return out;
}

void write_field_file(const std::string& path, const Field& field, const FieldSpec& spec, double density,
                      const std::string& floedem_version) {
  Scene scene;
  scene.source_path = path;
  scene.bodies = field_floes(field, density);
  scene.output.contacts = ContactOutput::none;
  scene.provenance.push_back(field_provenance(field, spec, density, 0));
  scene.derive();
  EngineInfo engine{"none (field generator)", "", {}, {}};
  Recorder recorder(path, scene, engine, RunInfo{{}, floedem_version});
  BodyStates state;
  state.resize(scene.bodies.size());
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) state.position[i] = scene.bodies[i].centroid;
  recorder.write_frame(0.0, state);
  recorder.write_polygons("/field", "keep_out", spec.keep_out);
  recorder.finish({});
}

}  // namespace floedem
