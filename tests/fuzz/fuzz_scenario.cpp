// libFuzzer target: the scenario loader on arbitrary text. Bad input must end in InputError
// (a message, exit code 2); anything else escaping, a crash, a hang or a sanitizer report is
// a bug. scripts/fuzz.sh builds and runs it (clang, -fsanitize=fuzzer,address,undefined).
#include <cstddef>
#include <cstdint>
#include <string>

#include "floedem/scenario/scenario.hpp"
#include "floedem/scene/input_error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 1 << 16) return 0;  // scenario files are small; longer inputs only slow the search
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const floedem::Scene scene = floedem::parse_scenario(text, "fuzz.toml");
    (void)scene;
  } catch (const floedem::InputError&) {
  }
  return 0;
}
