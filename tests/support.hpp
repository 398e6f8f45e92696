#pragma once
// Helpers shared by the tests: scenes from TOML text, engines, polygons as TOML.
#include <catch2/catch.hpp>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "floedem/engine/registry.hpp"
#include "floe_polygon.hpp"
#include "forcing/forcing.hpp"
#include "floedem/scenario/scenario.hpp"

namespace floedem::test {

/// The floedem command line run with `args`: exit code and stdout + stderr together.
struct CliResult {
  int code;
  std::string output;
};
/// Runs `floedem ARGS` through /bin/sh, after `shell_prefix` (e.g. "ulimit -f 100; ").
inline CliResult run_cli(const std::string& args, const std::string& shell_prefix = "") {
  const std::string cmd = shell_prefix + std::string(FLOEDEM_EXE) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf{};
  while (std::fgets(buf.data(), buf.size(), p)) out += buf.data();
  const int status = pclose(p);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

/// An empty directory of its own under the system's temporary directory (per test and process).
inline std::filesystem::path temp_dir(const std::string& name) {
  const std::filesystem::path d =
      std::filesystem::temp_directory_path() / ("floedem-test-" + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

inline Scene scene_from(const std::string& toml, const std::vector<std::string>& overrides = {}) {
  return parse_scenario(toml, "test.toml", overrides);
}

/// True when this build has the engine (FLOEDEM_WITH_ODE, _BULLET, _BOX2D); otherwise a
/// warning naming it, and the caller skips what needs it.
inline bool have_engine(const std::string& name) {
  for (const auto& e : engines())
    if (e.name == name) return true;
  WARN("skipped: this build has no " << name << " engine");
  return false;
}

inline std::unique_ptr<Engine> native(const Scene& s) { return make_engine("native", s); }

/// The engine's work count `name` so far (Engine::add_work_counts); 0 where it counts none such.
inline double work_count(const Engine& e, const std::string& name) {
  std::vector<WorkCount> work;
  e.add_work_counts(work);
  for (const WorkCount& w : work)
    if (w.name == name) return w.count;
  return 0.0;
}

/// x component of the contact force on `body` over the engine's last step (its impulses / dt).
inline double contact_force_x(const Engine& e, int body, double dt) {
  double fx = 0.0;
  for (const ContactRecord& c : e.contacts()) {
    const double px = c.normal_impulse * c.normal.x - c.tangent_impulse * c.normal.y;
    if (c.body_b == body) fx += px;
    if (c.body_a == body) fx -= px;
  }
  return fx / dt;
}

/// TOML array of the vertices, e.g. "[[0, 0], [1, 0], [1, 1]]", written exactly (17 digits).
inline std::string toml_polygon(const std::vector<Vec2>& pts) {
  std::ostringstream o;
  o.precision(17);
  o << "[";
  for (std::size_t i = 0; i < pts.size(); ++i) o << (i ? ", " : "") << "[" << pts[i].x << ", " << pts[i].y << "]";
  o << "]";
  return o.str();
}

/// Rectangle w x h centred at c, turned by angle q.
inline std::vector<Vec2> box(Vec2 c, double w, double h, double q = 0.0) {
  const Rot r = Rot::from_angle(q);
  std::vector<Vec2> out;
  for (const Vec2 p : {Vec2{-w / 2, -h / 2}, Vec2{w / 2, -h / 2}, Vec2{w / 2, h / 2}, Vec2{-w / 2, h / 2}})
    out.push_back(c + r.apply(p));
  return out;
}

inline std::string vec_toml(Vec2 v) {
  std::ostringstream o;
  o.precision(17);
  o << "[" << v.x << ", " << v.y << "]";
  return o.str();
}

struct BodyText {
  std::string name;
  std::vector<Vec2> polygon;
  Vec2 velocity{};
  double angular_velocity = 0.0;
  bool fixed = false;
  Vec2 force{};
  double thickness = 1.0;
  double density = 900.0;
};

inline std::string body_toml(const BodyText& b) {
  std::ostringstream o;
  o.precision(17);
  o << "[[body]]\nname = \"" << b.name << "\"\npolygon = " << toml_polygon(b.polygon) << "\nthickness = " << b.thickness
    << "\ndensity = " << b.density << "\nvelocity = " << vec_toml(b.velocity)
    << "\nangular_velocity = " << b.angular_velocity << "\nfixed = " << (b.fixed ? "true" : "false")
    << "\napplied_force = " << vec_toml(b.force) << "\n";
  return o.str();
}

/// The push of the resting-contact tests (test_resting.cpp, test_sleep.cpp) on floe_and_wall's
/// floe: F dt / m = 2.2e-3 m/s at dt 0.01 s.
inline constexpr double kWallPush = 2e4;  // N

/// A 10 x 10 m floe (body 0, centre (5, 5)) touching a fixed 2 x 40 m wall on its +x side
/// (body 1), the floe under `floe_force`.
inline std::string floe_and_wall(Vec2 floe_force = {}) {
  return body_toml({"floe", box({5, 5}, 10, 10), {}, 0.0, false, floe_force}) +
         body_toml({"wall", box({11, 5}, 2, 40), {}, 0.0, true});
}

inline std::string header_toml(double duration, double dt, double e, double mu, const std::string& extra = "") {
  std::ostringstream o;
  o.precision(17);
  o << "[run]\nduration = " << duration << "\ndt = " << dt << "\n[contact]\nrestitution = " << e << "\nfriction = " << mu
    << "\n" << extra << "\n";
  return o.str();
}

}  // namespace floedem::test
