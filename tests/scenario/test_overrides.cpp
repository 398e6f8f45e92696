#include <catch2/catch.hpp>

#include "floedem/scene/input_error.hpp"
#include "support.hpp"

using namespace floedem;

namespace {
const std::string kText =
    "[run]\nduration = 1.0\ndt = 0.01\n[[body]]\nname = \"a\"\npolygon = [[0,0],[1,0],[1,1],[0,1]]\nthickness = 1.0\n"
    "[[body]]\nname = \"b\"\npolygon = [[2,0],[3,0],[3,1],[2,1]]\nthickness = 1.0\n";
}

TEST_CASE("overrides (--set) change scalars, creates absent tables, and indexes bodies", "[input][set]") {
  const Scene s = test::scene_from(kText, {"run.duration=60", "contact.restitution=0.7", "body[1].density=917",
                                           "body[0].velocity=[0.5, 0]", "output.contacts=collisions"});
  CHECK(s.run.duration == 60.0);
  CHECK(s.contact.restitution == 0.7);
  CHECK(s.bodies[1].density == 917.0);
  CHECK(s.bodies[0].velocity.x == 0.5);
  CHECK(s.output.contacts == ContactOutput::collisions);
  CHECK(s.overrides.size() == 5);
}

TEST_CASE("overrides (--set) are checked like the file's", "[input][set]") {
  CHECK_THROWS_WITH(test::scene_from(kText, {"contact.restitution=2"}), Catch::Contains("contact.restitution") && Catch::Contains("[0, 1]"));
  CHECK_THROWS_WITH(test::scene_from(kText, {"run.duration"}), Catch::Contains("KEY=VALUE"));
  CHECK_THROWS_WITH(test::scene_from(kText, {"body[5].density=1"}), Catch::Contains("body[5]"));
  CHECK_THROWS_WITH(test::scene_from(kText, {"run=3"}), Catch::Contains("table"));
  CHECK_THROWS_WITH(test::scene_from(kText, {"run.durration=3"}), Catch::Contains("run.durration") && Catch::Contains("unknown"));
}
