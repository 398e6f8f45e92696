// libFuzzer target: the forcing files and ice charts a scenario names, damaged. The first byte
// of an input picks what the rest is (fuzz_inputs.hpp): a CF-NetCDF grid of a current on x and
// y in metres, one on longitude and latitude in a geographic scene, a CSV record of the wind,
// or an ice chart as GeoJSON or as a shapefile (its four files). It is written to a file in a private directory (on /dev/shm where
// there is one: memory, no disk) that a fixed scenario names, and the scenario goes the way
// `floedem check` takes it: loaded (the grid's axes, the record's samples, the chart's polygons
// and the field made from them) and checked as a run's first step would check it (check_scene:
// the grid read where the bodies start). Bad input must end in InputError of one line (exit 2);
// anything else escaping, a crash, a hang or a sanitizer report is a bug.
//
// Records and charts are the input's bytes as they are (a shapefile's split into its files). A grid is a description
// (GridDescription: axes, units, types, packing, fill values, shapes, then the file cut short
// and bytes of its data changed) that netCDF-C writes in classic format; the header it decodes
// itself is kept whole (fuzz_inputs.hpp says why).
//
// The seeds are written by make_input_seeds.cpp (scripts/fuzz.sh runs it).
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "floedem/run/simulation.hpp"
#include "floedem/scenario/scenario.hpp"
#include "floedem/scene/input_error.hpp"
#include "fuzz_inputs.hpp"

namespace {

std::filesystem::path g_dir;
bool g_verbose = false;  // FLOEDEM_FUZZ_VERBOSE set: each input's verdict on stderr (to read seeds)

void remove_dir() {
  std::error_code ignored;
  std::filesystem::remove_all(g_dir, ignored);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const char* base = std::filesystem::is_directory("/dev/shm") && access("/dev/shm", W_OK) == 0 ? "/dev/shm" : nullptr;
  std::string pattern = (base ? std::string(base) : std::filesystem::temp_directory_path().string()) + "/floedem-fuzz-XXXXXX";
  if (!mkdtemp(pattern.data())) std::abort();
  g_dir = pattern;
  g_verbose = std::getenv("FLOEDEM_FUZZ_VERBOSE") != nullptr;
  std::atexit(remove_dir);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1 || size > floedem::fuzz::kMaxInput) return 0;
  const auto kind = static_cast<floedem::fuzz::InputKind>(data[0] % floedem::fuzz::kKinds);
  const std::filesystem::path file = g_dir / floedem::fuzz::file_name(kind);
  if (kind == floedem::fuzz::InputKind::kPlaneGrid || kind == floedem::fuzz::InputKind::kLonLatGrid) {
    if (!floedem::fuzz::write_grid(file, floedem::fuzz::decode(data + 1, size - 1))) return 0;
  } else if (kind == floedem::fuzz::InputKind::kShapefile) {
    const auto parts = floedem::fuzz::split_shapefile(data + 1, size - 1);
    for (std::size_t k = 0; k < parts.size(); ++k) {
      std::filesystem::path part = file;
      part.replace_extension(floedem::fuzz::kShapefileParts[k]);
      if (k == 3 && parts[k].empty()) {
        std::filesystem::remove(part);
        continue;
      }
      std::ofstream(part, std::ios::binary | std::ios::trunc).write(parts[k].data(), static_cast<std::streamsize>(parts[k].size()));
    }
  } else {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
  }
  const std::filesystem::path scenario = g_dir / "scene.toml";
  const std::string text = floedem::fuzz::scene_text(kind, file.string());
  try {
    const floedem::Scene scene = floedem::parse_scenario(text, scenario.string());
    floedem::check_scene(scene);
    if (g_verbose) std::fprintf(stderr, "fuzz_inputs: ok: %zu bodies\n", scene.bodies.size());
  } catch (const floedem::InputError& e) {
    if (g_verbose) std::fprintf(stderr, "fuzz_inputs: refused: %s\n", e.what());
    // The refusal is one line (docs/output.md) whatever a damaged file makes it quote.
    if (std::strchr(e.what(), '\n') != nullptr) {
      std::fprintf(stderr, "fuzz_inputs: a refusal of more than one line: %s\n", e.what());
      std::abort();
    }
  }
  return 0;
}
