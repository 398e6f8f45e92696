#include "scenario/input_file.hpp"

#include <cerrno>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include "floedem/engine/state_io.hpp"
#include "floedem/scene/input_error.hpp"

namespace floedem {

std::string InputFile::text() const {
  char head[64];
  std::snprintf(head, sizeof head, "fnv1a64 %016" PRIx64 ", %" PRIu64 " bytes, ", digest, bytes);
  return head + path;
}

InputFile read_input_file(const std::string& key, const std::string& path) {
  InputFile f{key, path, 0, kChecksumStart};
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(input_message(path, 0, key, std::string("cannot read it: ") + std::strerror(errno)));
  std::vector<char> block(1 << 20);
  while (in) {
    in.read(block.data(), static_cast<std::streamsize>(block.size()));
    const auto n = static_cast<std::size_t>(in.gcount());
    f.digest = state_checksum(reinterpret_cast<const std::uint8_t*>(block.data()), n, f.digest);
    f.bytes += n;
  }
  if (in.bad()) throw InputError(input_message(path, 0, key, "a read failed part way"));
  return f;
}

void record_input_file(Scene& scene, const std::string& key, const std::string& path) {
  scene.input_files.push_back(read_input_file(key, path));
  std::filesystem::path p(path);
  if (p.extension() != ".shp") return;
  for (const char* ext : {".dbf", ".shx", ".prj", ".cpg"}) {
    std::filesystem::path side = p;
    side.replace_extension(ext);
    if (std::filesystem::is_regular_file(side))
      scene.input_files.push_back(read_input_file(key + " (" + std::string(ext + 1) + ")", side.string()));
  }
}

}  // namespace floedem
