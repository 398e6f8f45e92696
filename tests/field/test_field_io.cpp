// A field reached three ways: the library (field file written and read back), a scenario's
// [field] section (generated around the scenario's own bodies, or loaded from a file), and
// `floedem field` (exit codes, nothing written on bad input).
#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "field/exact_geometry.hpp"
#include "floedem/field/field_file.hpp"
#include "geometry/polygon.hpp"
#include "floedem/io/output.hpp"
#include "floedem/scene/input_error.hpp"
#include "collision/overlap.hpp"
#include "support.hpp"

using namespace floedem;
namespace fs = std::filesystem;

namespace {

FieldSpec small_spec() {
  FieldSpec s;
  s.width = 300.0;
  s.height = 200.0;
  s.concentration = 0.55;
  s.alpha = 2.2;
  s.d_min = 3.0;
  s.d_max = 40.0;
  s.thickness = {ThicknessDistribution::Kind::uniform, 0.0, 0.8, 1.5, 0.0, 0.0};
  s.seed = 9;
  return s;
}

}  // namespace

TEST_CASE("field file: the /bodies layout of a run, read back by the run reader", "[field][io]") {
  const fs::path d = test::temp_dir("field-file");
  const FieldSpec s = small_spec();
  const Field f = generate_field(s);
  const std::string path = (d / "f.h5").string();
  write_field_file(path, f, s, 917.0, "test");
  CHECK_FALSE(fs::exists(path + ".partial"));
  const BodyFrame b = read_body_frame(path);
  REQUIRE(b.polygons.size() == f.floes.size());
  for (std::size_t i = 0; i < f.floes.size(); ++i) {
    REQUIRE(b.polygons[i].size() == f.floes[i].size());
    for (std::size_t k = 0; k < f.floes[i].size(); ++k) {
      CHECK(b.polygons[i][k].x == Approx(f.floes[i][k].x).margin(1e-9));
      CHECK(b.polygons[i][k].y == Approx(f.floes[i][k].y).margin(1e-9));
    }
    CHECK(b.thickness[i] == f.thickness[i]);
    CHECK(b.density[i] == 917.0);
    CHECK(b.velocity[i] == Vec2{});
  }
  CHECK(b.time == 0.0);
  CHECK_THROWS_AS(read_body_frame(path, 1), InputError);  // one frame only
  CHECK_THROWS_AS(read_body_frame((d / "missing.h5").string()), InputError);
  fs::remove_all(d);
}

TEST_CASE("scenario [field]: generated around the scenario's bodies, or loaded from a file", "[field][input]") {
  const std::string head =
      "[run]\nduration = 1.0\ndt = 0.01\n"
      "[[body]]\nname = \"berg\"\nkind = \"iceberg\"\npolygon = [[100,80],[180,80],[190,120],[100,130]]\n"
      "draft = 20\nsail_height = 5\n";
  const std::string field =
      "[field]\nwidth = 300\nheight = 200\nconcentration = 0.5\nalpha = 2\nd_min = 3\nd_max = 30\n"
      "thickness = { min = 0.8, max = 1.4 }\nseed = 4\nvelocity = [0.1, 0]\n"
      "[[field.keep_out]]\npolygon = [[0,0],[40,0],[40,40],[0,40]]\n";
  const Scene scene = test::scene_from(head + field);
  REQUIRE(scene.bodies.size() > 100);
  CHECK(scene.bodies[0].name == "berg");
  CHECK(scene.bodies[1].name == "floe-0");
  CHECK(scene.bodies[1].velocity == Vec2{0.1, 0.0});
  std::vector<std::vector<Vec2>> floes;
  double ice = 0.0;
  for (std::size_t i = 1; i < scene.bodies.size(); ++i) {
    floes.push_back(scene.bodies[i].polygon);
    ice += scene.bodies[i].area;
    CHECK(scene.bodies[i].thickness >= 0.8);
    CHECK(scene.bodies[i].thickness <= 1.4);
    CHECK(test::convex_interiors_disjoint(scene.bodies[i].polygon, {{0, 0}, {40, 0}, {40, 40}, {0, 40}}));
  }
  // No floe overlaps the iceberg (the loader's overlap check has passed) and the concentration
  // over the free area (domain minus the iceberg's and the zone's area) is the target.
  CHECK_FALSE(find_overlap(scene).has_value());
  const double free_area = 300.0 * 200.0 - scene.bodies[0].area - 1600.0;
  CHECK(std::abs(ice / free_area - 0.5) <= 0.005);
  // The run's output says how the field was made, and what it achieved.
  REQUIRE(scene.provenance.size() == 1);
  CHECK(scene.provenance[0].group == "/field");
  const auto& numbers = scene.provenance[0].numbers;
  const auto achieved = std::find_if(numbers.begin(), numbers.end(),
                                     [](const auto& kv) { return kv.first == "concentration_achieved"; });
  REQUIRE(achieved != numbers.end());
  CHECK(achieved->second == Approx(ice / free_area).epsilon(1e-9));

  // The same floes through a field file: `file` reads them back in the same order.
  const fs::path d = test::temp_dir("field-scenario");
  FieldSpec s = small_spec();
  s.d_max = 30.0;
  const Field generated = generate_field(s);
  write_field_file((d / "f.h5").string(), generated, s, 900.0, "test");
  std::ofstream(d / "s.toml") << "[run]\nduration = 1.0\ndt = 0.01\n[field]\nfile = \"f.h5\"\n";
  const Scene loaded = load_scenario((d / "s.toml").string());
  REQUIRE(loaded.bodies.size() == generated.floes.size());
  CHECK(loaded.bodies[7].area == Approx(signed_area(generated.floes[7])).epsilon(1e-12));
  fs::remove_all(d);
}

TEST_CASE("scenario [field]: thickness = { mean, std } draws lognormal thicknesses", "[field][input]") {
  // The scenario's form of the generator's lognormal law (field tests hold the law itself).
  auto thicknesses = [](const std::string& law) {
    const Scene scene = test::scene_from(
        "[run]\nduration = 1.0\ndt = 0.01\n[field]\nwidth = 300\nheight = 200\nconcentration = 0.5\nalpha = 2\n"
        "d_min = 3\nd_max = 30\nthickness = " + law + "\nseed = 4\n");
    std::vector<double> h;
    for (const BodySpec& b : scene.bodies) h.push_back(b.thickness);
    return h;
  };
  const std::vector<double> h = thicknesses("{ mean = 1.2, std = 0.4 }");
  REQUIRE(h.size() > 100);
  double mean = 0.0, square = 0.0;
  for (const double x : h) {
    CHECK(x > 0.0);
    mean += x;
    square += x * x;
  }
  const auto n = static_cast<double>(h.size());
  mean /= n;
  const double sd = std::sqrt(square / n - mean * mean);
  INFO(h.size() << " floes: mean " << mean << " m, standard deviation " << sd << " m");
  // Sampling error: 4 standard errors of the mean (0.4 / sqrt(n)), and a fifth on the spread.
  CHECK(std::abs(mean - 1.2) < 4.0 * 0.4 / std::sqrt(n));
  CHECK(std::abs(sd - 0.4) < 0.2 * 0.4);
  for (const double x : thicknesses("{ mean = 1.2, std = 0.0 }")) CHECK(x == Approx(1.2).epsilon(1e-15));
}

TEST_CASE("scenario [field]: bad keys are refused with file, field and range", "[field][input]") {
  const std::string run = "[run]\nduration = 1.0\ndt = 0.01\n";
  const std::string ok = "width = 300\nheight = 200\nalpha = 2\nd_min = 3\nd_max = 30\nthickness = 1\n";
  struct Bad {
    std::string text;
    std::vector<std::string> expect;
  };
  const std::vector<Bad> cases = {
      {run + "[field]\n" + ok + "concentration = 1.2\n", {"test.toml:11", "'field.concentration'", "(0, 0.99]"}},
      {run + "[field]\n" + ok, {"'field.concentration'", "missing"}},
      {run + "[field]\n" + ok + "concentration = 0.5\ncolour = 3\n", {"'field.colour'", "unknown"}},
      {run + "[field]\nwidth = 20\nheight = 200\nalpha = 2\nd_min = 3\nd_max = 30\nthickness = 1\nconcentration = 0.5\n",
       {"'field.width'", "smaller than d_max"}},
      {run + "[field]\nfile = \"nowhere.h5\"\n", {"'field.file'", "nowhere.h5", "no such file"}},
      {run + "[field]\nfile = \"x.h5\"\nalpha = 2\n", {"'field.alpha'", "generated field"}},
      {run + "[[body]]\nname = \"b\"\npolygon = [[10,10],[50,10],[50,50]]\nthickness = 1\n[field]\n" + ok +
           "concentration = 0.5\n[[field.keep_out]]\npolygon = [[0,0],[30,0],[30,30],[0,30]]\n",
       {"'field.keep_out'", "body 'b' overlaps field.keep_out[0]"}},
  };
  for (const Bad& b : cases) {
    std::string message;
    try {
      test::scene_from(b.text);
    } catch (const InputError& e) {
      message = e.what();
    }
    INFO(b.text << "\n-> " << message);
    for (const std::string& e : b.expect) CHECK(message.find(e) != std::string::npos);
  }
}

TEST_CASE("cli: floedem field writes a field file, and bad input exits 2 naming the flag and writes nothing",
          "[field][cli]") {
  const fs::path d = test::temp_dir("field-cli");
  const std::string common = " --width 200 --height 150 --alpha 2 --dmin 3 --dmax 30 --thickness 1.16 --seed 3";
  const test::CliResult good = test::run_cli("field" + common + " --concentration 0.5 --out " + (d / "f.h5").string());
  INFO(good.output);
  CHECK(good.code == 0);
  CHECK(good.output.find("concentration 0.500000") != std::string::npos);
  CHECK(read_body_frame((d / "f.h5").string()).polygons.size() > 50);

  const std::vector<std::pair<std::string, std::string>> bad = {
      {" --concentration 1.0", "--concentration"},
      {" --concentration 0", "--concentration"},
      {" --concentration nan", "--concentration"},
      {" --concentration 0.5 --keep-out \"0,0 300,0 300,300 0,300\"", "--keep-out"},
      {" --concentration 0.5 --keep-out \"0,0 1,x\"", "--keep-out"},
      {" --concentration 0.5 --irregularity 2", "--irregularity"},
  };
  for (const auto& [args, flag] : bad) {
    const test::CliResult r = test::run_cli("field" + common + args + " --out " + (d / "bad.h5").string());
    INFO(args << " -> " << r.output);
    CHECK(r.code == 2);
    CHECK(r.output.find(flag) != std::string::npos);
    CHECK(std::count(r.output.begin(), r.output.end(), '\n') == 1);
    CHECK_FALSE(fs::exists(d / "bad.h5"));
    CHECK_FALSE(fs::exists(d / "bad.h5.partial"));
  }
  const test::CliResult dmin = test::run_cli("field --width 200 --height 150 --alpha 2 --dmin 30 --dmax 3 --thickness 1 "
                                  "--concentration 0.5 --out " + (d / "bad.h5").string());
  CHECK(dmin.code == 2);
  CHECK(dmin.output.find("--dmax") != std::string::npos);
  fs::remove_all(d);
}
