// A scene made in code (no scenario file): an iceberg drifting in a 0.3 m/s current into a
// floe, 60 s on the native engine. The run's output is written as `floedem run` writes it, and
// its last frame is read back with the library's reader.
//   scene_in_code [OUT.h5]
#include <cstdio>
#include <exception>
#include <string>

#include "floedem/io/output.hpp"
#include "floedem/run/simulation.hpp"
#include "floedem/scene/input_error.hpp"
#include "floedem/scene/scene.hpp"
#include "floedem/version.hpp"

namespace {

floedem::BodySpec square(const std::string& name, floedem::Vec2 centre, double side) {
  floedem::BodySpec b;
  b.name = name;
  const double h = side / 2.0;
  b.polygon = {centre + floedem::Vec2{-h, -h}, centre + floedem::Vec2{h, -h}, centre + floedem::Vec2{h, h},
               centre + floedem::Vec2{-h, h}};  // counter-clockwise
  return b;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string out = argc > 1 ? argv[1] : "scene_in_code.h5";
  try {
    floedem::Scene scene;
    scene.source_path = "scene_in_code.cpp";  // names the scene in messages and in the output
    scene.run.duration = 60.0;                // s
    scene.run.dt = 0.05;                      // s
    scene.run.output_every = 20;              // a frame each second
    scene.contact.restitution = 0.1;
    scene.contact.friction = 0.3;

    floedem::BodySpec berg = square("berg", {0.0, 0.0}, 40.0);
    berg.kind = floedem::BodyKind::iceberg;
    berg.draft = 30.0;        // m
    berg.freeboard = 5.0;     // m, the sail height
    berg.thickness = berg.draft + berg.freeboard;
    berg.keel = {{0.0, 30.0, 1.0}};  // one slab from the waterline to the keel, the waterline's shape
    berg.added_mass_coefficient = 0.5;
    floedem::BodySpec floe = square("floe", {45.0, 0.0}, 20.0);
    floe.thickness = 1.0;     // m; its draft and freeboard follow from the densities (derive)
    scene.bodies = {berg, floe};

    scene.has_environment = true;
    scene.environment.current = {0.3, 0.0};  // m/s
    scene.derive();  // mass properties and convex parts, as the scenario loader would

    floedem::RunOptions options;
    options.engine = "native";
    options.output = out;
    const floedem::RunSummary summary = floedem::run_scene(scene, options);
    std::printf("%s", floedem::format_summary(scene, summary, out).c_str());

    const floedem::BodyFrame last = floedem::read_body_frame(out);  // -1: the last frame
    for (std::size_t i = 0; i < last.names.size(); ++i)
      std::printf("t = %.1f s  %-5s velocity (%.4f, %.4f) m/s\n", last.time, last.names[i].c_str(),
                  last.velocity[i].x, last.velocity[i].y);
    // Drag pulls both towards the current: the thin floe gains speed faster than the 30 m keel.
    const bool drifting = last.velocity[0].x > 0.0 && last.velocity[1].x > 0.0;
    std::printf("floedem %s: both bodies drift with the current: %s\n", floedem::version(), drifting ? "yes" : "NO");
    return drifting ? 0 : 1;
  } catch (const floedem::InputError& e) {
    std::fprintf(stderr, "scene_in_code: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "scene_in_code: %s\n", e.what());
    return 1;
  }
}
