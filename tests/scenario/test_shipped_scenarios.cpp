// Every scenario shipped in scenarios/ loads (parse, checks, field generation, no overlap):
// the files and their documentation cannot drift from the loader unnoticed.
#include <catch2/catch.hpp>

#include <filesystem>

#include "floedem/scenario/scenario.hpp"

TEST_CASE("every shipped scenario loads", "[input]") {
  std::size_t count = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(std::string(FLOEDEM_SOURCE_DIR) + "/scenarios")) {
    if (entry.path().extension() != ".toml") continue;
    INFO(entry.path().string());
    CHECK_NOTHROW(floedem::load_scenario(entry.path().string()));
    ++count;
  }
  CHECK(count >= 6);
}
