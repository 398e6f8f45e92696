// Every kind of bad scenario gets a one-line error naming the file, the field (with its line)
// and the allowed range.
#include <catch2/catch.hpp>

#include "floedem/scene/input_error.hpp"
#include "support.hpp"

using namespace floedem;

namespace {

const std::string kRun = "[run]\nduration = 1.0\ndt = 0.01\n";
const std::string kBody = "[[body]]\nname = \"a\"\npolygon = [[0,0],[1,0],[1,1],[0,1]]\nthickness = 1.0\n";
const std::string kIceberg =
    "[[body]]\nname = \"berg\"\nkind = \"iceberg\"\npolygon = [[0,0],[50,0],[50,50],[0,50]]\ndraft = 40.0\nsail_height = 10.0\n";

// A tug's tow without its pull: each case adds what it tests.
const std::string kBadTug = "[tow]\nmode = \"tug\"\nbody = \"berg\"\ndirection = [1.0, 0.0]\nstiffness = 1e5\nlength = 100.0\n";

std::string error_of(const std::string& text) {
  try {
    test::scene_from(text);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("bad scenarios are refused with file, field, line and range", "[input]") {
  struct Bad {
    const char* what;
    std::string text;
    std::vector<std::string> expect;  // substrings of the message
  };
  const std::vector<Bad> cases = {
      {"unknown top-level key", "colour = 1\n" + kRun + kBody, {"test.toml:1", "'colour'", "unknown key"}},
      {"unknown key in a table", kRun + "dtt = 3\n" + kBody, {"'run.dtt'", "unknown key"}},
      {"unknown key in a body", kRun + kBody + "densty = 3\n", {"'body[0].densty'", "unknown"}},
      {"missing [run]", kBody, {"'run'", "missing"}},
      {"missing dt", "[run]\nduration = 1.0\n" + kBody, {"'run.dt'", "missing", "(0, inf)"}},
      {"wrong type", "[run]\nduration = \"long\"\ndt = 0.1\n" + kBody, {"test.toml:2", "'run.duration'", "expected a number"}},
      {"nan", "[run]\nduration = nan\ndt = 0.1\n" + kBody, {"'run.duration'", "finite"}},
      {"huge vertex (found by fuzzing: it crashed the convex partition)",
       kRun + "[[body]]\npolygon = [[0,0],[4e75,0],[1,1],[0,1]]\nthickness = 1.0\n",
       {"'body[0].polygon'", "vertex 1", "1e7 m"}},
      {"inf", "[run]\nduration = 1.0\ndt = inf\n" + kBody, {"'run.dt'", "finite"}},
      {"duration <= 0", "[run]\nduration = 0.0\ndt = 0.1\n" + kBody, {"'run.duration'", "out of range", "(0, inf)"}},
      {"dt <= 0", "[run]\nduration = 1.0\ndt = -0.1\n" + kBody, {"'run.dt'", "(0, inf)"}},
      {"dt > duration", "[run]\nduration = 1.0\ndt = 2.0\n" + kBody, {"'run.dt'", "must not exceed"}},
      {"output_every 0", kRun + "output_every = 0\n" + kBody, {"'run.output_every'", "[1,"}},
      {"e > 1", kRun + "[contact]\nrestitution = 1.5\n" + kBody, {"test.toml:5", "'contact.restitution'", "[0, 1]"}},
      {"e < 0", kRun + "[contact]\nrestitution = -0.1\n" + kBody, {"'contact.restitution'", "[0, 1]"}},
      {"friction < 0", kRun + "[contact]\nfriction = -1\n" + kBody, {"'contact.friction'", "[0, inf)"}},
      {"density <= 0", kRun + kBody + "density = 0\n", {"'body[0].density'", "(0, inf)"}},
      {"thickness <= 0", kRun + "[[body]]\npolygon = [[0,0],[1,0],[1,1]]\nthickness = -1\n", {"'body[0].thickness'", "(0, inf)"}},
      {"missing thickness", kRun + "[[body]]\npolygon = [[0,0],[1,0],[1,1]]\n", {"'body[0].thickness'", "missing"}},
      {"two vertices", kRun + "[[body]]\npolygon = [[0,0],[1,0]]\nthickness = 1\n", {"'body[0].polygon'", "at least 3"}},
      {"self-intersecting", kRun + "[[body]]\npolygon = [[0,0],[1,1],[1,0],[0,1]]\nthickness = 1\n",
       {"'body[0].polygon'", "self-intersecting"}},
      {"zero area", kRun + "[[body]]\npolygon = [[0,0],[1,0],[2,0]]\nthickness = 1\n", {"'body[0].polygon'", "zero area"}},
      {"vertex of 3 numbers", kRun + "[[body]]\npolygon = [[0,0,0],[1,0],[1,1]]\nthickness = 1\n",
       {"'body[0].polygon'", "vertex 0", "expected 2"}},
      {"vector of wrong length", kRun + kBody + "velocity = [1.0]\n", {"'body[0].velocity'", "expected 2 components"}},
      {"non-finite vector", kRun + kBody + "velocity = [1.0, nan]\n", {"'body[0].velocity'", "finite"}},
      {"fixed and moving", kRun + kBody + "fixed = true\nvelocity = [1.0, 0.0]\n", {"'body[0].velocity'", "fixed"}},
      {"duplicate names", kRun + kBody + kBody, {"'body[1].name'", "unique"}},
      {"overlapping bodies", kRun + kBody + "[[body]]\nname = \"b\"\npolygon = [[0.5,0.5],[2,0.5],[2,2],[0.5,2]]\nthickness = 1\n",
       {"'a' and 'b'", "overlap"}},
      {"no body", kRun, {"'body'", "at least one"}},
      {"not TOML", "[run\nduration = 1\n", {"test.toml:1", "not valid TOML"}},
      {"bad output choice", kRun + "[output]\ncontacts = \"some\"\n" + kBody, {"'output.contacts'", "\"all\""}},
      {"unknown engine table", kRun + kBody + "[engine.havok]\nx = 1\n", {}},  // refused by the registry (below)
      {"engine settings not a table", kRun + kBody + "[engine]\nnative = 1\n", {"'engine.native'", "expected a table"}},
      {"current profile not deepening", kRun + "[environment]\ncurrent_profile = [[0, 0.1, 0], [10, 0.1, 0], [5, 0, 0]]\n" + kBody,
       {"'environment.current_profile'", "depths must increase", "row 2"}},
      {"sea surface tilt without latitude", kRun + "[environment]\ncurrent = [0.1, 0.0]\nsea_surface_tilt = true\n" + kBody,
       {"'environment.sea_surface_tilt'", "needs a latitude"}},
      {"keel layers short of the draft", kRun + kIceberg + "keel_layers = [[20.0, 1.0], [10.0, 0.8]]\n",
       {"'body[0].keel_layers'", "add up to 30", "the draft, 40"}},
      {"keel layer too wide", kRun + kIceberg + "keel_layers = [[20.0, 1.0], [20.0, 11.0]]\n",
       {"'body[0].keel_layers'", "layer 1", "(0, 10]"}},
      // Towing by a tug (docs/towing.md).
      {"tug without bollard pull", kRun + kIceberg + kBadTug + "free_running_speed = 6.0\n", {"'tow.bollard_pull'", "missing", "(0, 100000000]"}},
      {"tug bollard pull zero", kRun + kIceberg + kBadTug + "bollard_pull = 0.0\nfree_running_speed = 6.0\n",
       {"'tow.bollard_pull'", "(0, 100000000]"}},
      {"tug free-running speed too high", kRun + kIceberg + kBadTug + "bollard_pull = 1e5\nfree_running_speed = 30.0\n",
       {"'tow.free_running_speed'", "(0, 20]"}},
      {"tug heading zero", kRun + kIceberg + "[tow]\nmode = \"tug\"\nbody = \"berg\"\ndirection = [0.0, 0.0]\n"
       "stiffness = 1e5\nlength = 100.0\nbollard_pull = 1e5\nfree_running_speed = 6.0\n",
       {"'tow.direction'", "nonzero"}},
      {"tug headings turning about", kRun + kIceberg + "[tow]\nmode = \"tug\"\nbody = \"berg\"\n"
       "direction_path = [[0.0, 1.0, 0.0], [60.0, -1.0, 0.1]]\nstiffness = 1e5\nlength = 100.0\nbollard_pull = 1e5\n"
       "free_running_speed = 6.0\n",
       {"'tow.direction_path'", "154 deg", "rows 0 and 1"}},
      {"tug mass zero", kRun + kIceberg + kBadTug + "bollard_pull = 1e5\nfree_running_speed = 6.0\ntug_mass = 0.0\n",
       {"'tow.tug_mass'", "(0, 10000000000]"}},
      {"negative breaking load", kRun + kIceberg + kBadTug + "bollard_pull = 1e5\nfree_running_speed = 6.0\nbreaking_load = -1.0\n",
       {"'tow.breaking_load'", "[0, inf)"}},
      {"stall speed too high", kRun + kIceberg + kBadTug + "bollard_pull = 1e5\nfree_running_speed = 6.0\nstall_speed = 11.0\n",
       {"'tow.stall_speed'", "[0, 10]"}},
      {"breaking load on a prescribed path", kRun + kIceberg + "[tow]\nmode = \"velocity\"\nbody = \"berg\"\n"
       "velocity = [0.5, 0.0]\nbreaking_load = 1e6\n",
       {"'tow.breaking_load'", "unknown key"}},
  };
  for (const Bad& b : cases) {
    if (b.expect.empty()) continue;
    INFO(b.what);
    const std::string m = error_of(b.text);
    REQUIRE_FALSE(m.empty());
    CHECK(m.find('\n') == std::string::npos);  // one line
    CHECK(m.rfind("test.toml", 0) == 0);       // starts with the file
    for (const auto& s : b.expect) {
      INFO("message: " << m << "\nexpected to contain: " << s);
      CHECK(m.find(s) != std::string::npos);
    }
  }
}

TEST_CASE("bad --set overrides are refused naming the override", "[input]") {
  // Not the file's fault: the message names the override as given, and why.
  const std::string text = kRun + kBody;
  CHECK_THROWS_WITH(test::scene_from(text, {"body[x].density=917"}),
                    Catch::StartsWith("--set body[x].density=917") && Catch::Contains("not a whole number"));
  CHECK_THROWS_WITH(test::scene_from(text, {"run={ duration = 2.0 }"}),
                    Catch::StartsWith("--set run={ duration = 2.0 }") && Catch::Contains("only scalars"));
  CHECK_THROWS_WITH(test::scene_from(text, {"run.duration"}), Catch::Contains("expected KEY=VALUE"));
}

TEST_CASE("bad engine settings and unknown engines are refused", "[input]") {
  const Scene unknown_table = test::scene_from(kRun + kBody + "[engine.havok]\nx = 1\n");
  CHECK_THROWS_WITH(make_engine("native", unknown_table), Catch::Contains("engine.havok") && Catch::Contains("unknown engine"));
  const Scene s = test::scene_from(kRun + kBody);
  CHECK_THROWS_WITH(make_engine("havok", s), Catch::Contains("unknown engine") && Catch::Contains("native"));
  const Scene bad = test::scene_from(kRun + kBody + "[engine.native]\nvelocity_iterations = 0\n");
  CHECK_THROWS_WITH(make_engine("native", bad), Catch::Contains("engine.native.velocity_iterations"));
  const Scene typo = test::scene_from(kRun + kBody + "[engine.native]\niterations = 3\n");
  CHECK_THROWS_WITH(make_engine("native", typo), Catch::Contains("engine.native.iterations") && Catch::Contains("unknown"));
}

TEST_CASE("clockwise polygons are accepted by reversing them", "[input]") {
  const Scene s = test::scene_from(kRun + "[[body]]\npolygon = [[0,0],[0,1],[1,1],[1,0]]\nthickness = 1\n");
  REQUIRE(s.bodies.size() == 1);
  CHECK(s.bodies[0].reversed_input);
  CHECK(s.bodies[0].area == Approx(1.0));
  CHECK(s.bodies[0].mass == Approx(900.0));
}

TEST_CASE("a refusal stays on one line whatever value it quotes", "[input]") {
  // TOML strings hold newlines; a damaged forcing file's attributes hold any bytes.
  const std::string m = error_of(kRun + "[contact]\nforce_model = \"linear\\nquadratic\"\n" + kBody);
  INFO(m);
  CHECK(m.find('\n') == std::string::npos);
  CHECK(m.find("\"linear\\x0aquadratic\"") != std::string::npos);
  CHECK(one_line("a\tb\r\n") == "a\\x09b\\x0d\\x0a");
  CHECK(printable("m s-1") == "m s-1");
  CHECK(printable(std::string("\x01\xff\n", 3)) == "\\x01\\xff\\x0a");
  CHECK(printable(std::string(100, 'x'), 10) == "xxxxxxxxxx...");
}

TEST_CASE("touching bodies are not an overlap", "[input]") {
  const Scene s = test::scene_from(kRun + kBody +
                                   "[[body]]\nname = \"b\"\npolygon = [[1,0],[2,0],[2,1],[1,1]]\nthickness = 1\n");
  CHECK(s.bodies.size() == 2);
}

TEST_CASE("a missing file or a directory is reported with its name", "[input]") {
  CHECK_THROWS_WITH(load_scenario("/nonexistent/dir/x.toml"), Catch::StartsWith("/nonexistent/dir/x.toml") && Catch::Contains("cannot open"));
  CHECK_THROWS_WITH(load_scenario("/tmp"), Catch::StartsWith("/tmp") && Catch::Contains("not a regular file"));
}

TEST_CASE("a concave body is split into convex parts with the polygon's mass properties", "[input]") {
  const Scene s = test::scene_from(kRun + "[[body]]\npolygon = [[0,0],[20,0],[20,10],[10,10],[10,20],[0,20]]\nthickness = 2\n");
  const BodySpec& b = s.bodies[0];
  CHECK(b.local_parts.size() == 2);
  CHECK(b.area == Approx(300.0));
  CHECK(b.mass == Approx(900.0 * 2.0 * 300.0));
}
