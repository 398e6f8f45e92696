#pragma once
// The files a scenario reads, recorded with their digest (Scene::input_files): what an archived
// run was made from, and what a continued run checks has not changed.
#include <string>

#include "floedem/scene/scene.hpp"

namespace floedem {

/// `path` read through, its size and FNV-1a digest; `key` the scenario key that names it.
/// InputError naming the key when it cannot be read.
InputFile read_input_file(const std::string& key, const std::string& path);

/// Records `path` (and, for an ESRI shapefile, the sidecar files beside it that GDAL reads:
/// .dbf, .shx, .prj, .cpg) in scene.input_files under `key`.
void record_input_file(Scene& scene, const std::string& key, const std::string& path);

}  // namespace floedem
