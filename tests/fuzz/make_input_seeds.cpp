// Writes the seed corpus of fuzz_inputs into a directory: inputs (each led by its kind's byte)
// that the scenario of fuzz_inputs.hpp accepts, and a few it refuses for one reason each, so
// that the search starts at every check. A grid's seed is its description (GridDescription).
//   make_input_seeds DIR
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gdal_priv.h>
#include <ogrsf_frmts.h>

#include "fuzz_inputs.hpp"

namespace fs = std::filesystem;
using floedem::fuzz::GridDescription;
using floedem::fuzz::InputKind;

namespace {

void seed(const fs::path& dir, const std::string& name, InputKind kind, const std::string& content) {
  std::ofstream(dir / name, std::ios::binary) << static_cast<char>(kind) << content;
}

/// A current of 0.1 to 0.2 m/s east and -0.05 to 0.05 north, over (t, [depth], y, x).
GridDescription with_values(GridDescription g) {
  for (int k = 0; k < 12; ++k) {
    g.u.push_back(0.1 + 0.01 * k);
    g.v.push_back(-0.05 + 0.01 * (k % 10));
  }
  if (g.flags & GridDescription::kPacked) {  // stored as shorts: (value - offset) / scale
    g.fill = -32767.0;
    for (std::vector<double>* values : {&g.u, &g.v})
      for (double& d : *values) d = std::round((d - g.offset) / g.scale);
  }
  return g;
}

GridDescription plane(std::uint16_t flags = 0) {
  GridDescription g;
  g.flags = flags;
  g.x = {-200.0, 0.0, 200.0};
  g.y = {-150.0, 0.0, 150.0};
  g.time = {-1.0, 0.5, 2.0};
  if (flags & GridDescription::kDepth) g.depth = {0.0, 5.0, 20.0};
  return with_values(g);
}

GridDescription lonlat(std::uint16_t flags = 0) {
  GridDescription g;
  g.flags = flags;
  g.x = {19.9, 20.0, 20.1};
  g.y = {69.95, 70.0, 70.05};
  g.time = {0.0, 1.0};
  g.x_units = "degrees_east";
  g.y_units = "degrees_north";
  return with_values(g);
}

/// A chart of GeoJSON features: each a ring of (lon, lat) and its CT, SA, FA codes.
struct Feature {
  std::vector<std::pair<double, double>> ring;
  std::string ct, sa, fa;
  std::vector<std::pair<double, double>> hole;
};

std::string geojson(const std::vector<Feature>& features, bool numeric_codes = false) {
  std::ostringstream o;
  o.precision(10);
  o << "{\"type\": \"FeatureCollection\", \"name\": \"chart\", \"features\": [\n";
  for (std::size_t f = 0; f < features.size(); ++f) {
    const Feature& ft = features[f];
    auto code = [&](const std::string& c) { return numeric_codes ? c : "\"" + c + "\""; };
    o << "{\"type\": \"Feature\", \"properties\": {\"CT\": " << code(ft.ct) << ", \"SA\": " << code(ft.sa)
      << ", \"FA\": " << code(ft.fa) << "}, \"geometry\": {\"type\": \"Polygon\", \"coordinates\": [";
    auto ring = [&](const std::vector<std::pair<double, double>>& r) {
      o << "[";
      for (std::size_t k = 0; k <= r.size(); ++k) {
        const auto& p = r[k % r.size()];
        o << (k ? ", " : "") << "[" << p.first << ", " << p.second << "]";
      }
      o << "]";
    };
    ring(ft.ring);
    if (!ft.hole.empty()) {
      o << ", ";
      ring(ft.hole);
    }
    o << "]}}" << (f + 1 < features.size() ? ",\n" : "\n");
  }
  o << "]}\n";
  return o.str();
}

/// The GeoJSON chart as a shapefile, translated by GDAL as a chart maker's tools would: its
/// four files joined as a kShapefile input holds them.
std::string shapefile(const fs::path& dir, const std::string& geojson_text) {
  const fs::path work = dir / "shapefile.tmp";
  fs::create_directories(work);
  std::ofstream(work / "in.geojson") << geojson_text;
  GDALAllRegister();
  GDALDatasetUniquePtr in(GDALDataset::Open((work / "in.geojson").c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY));
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName("ESRI Shapefile");
  if (!in || !driver) {
    std::fprintf(stderr, "make_input_seeds: GDAL cannot translate a chart to a shapefile\n");
    std::exit(1);
  }
  {
    GDALDatasetUniquePtr out(driver->Create((work / "chart.shp").c_str(), 0, 0, 0, GDT_Unknown, nullptr));
    if (!out || !out->CopyLayer(in->GetLayer(0), "chart")) {
      std::fprintf(stderr, "make_input_seeds: GDAL cannot write a shapefile\n");
      std::exit(1);
    }
  }
  std::vector<std::string> parts;
  for (const char* ext : floedem::fuzz::kShapefileParts) {
    std::ifstream f(work / (std::string("chart") + ext), std::ios::binary);
    std::ostringstream bytes;
    bytes << f.rdbuf();
    parts.push_back(bytes.str());
  }
  fs::remove_all(work);
  return floedem::fuzz::join_shapefile(parts);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_input_seeds DIR\n");
    return 2;
  }
  const fs::path dir = argv[1];
  fs::create_directories(dir);
  // Grids on x and y: plain, CDF-2, packed shorts, doubles with a missing value and a
  // calendar, a depth axis; refused: a fill value under the floe (found by check_scene's read
  // at t = 0), velocities in cm/s, a coordinate variable over another dimension, the file cut
  // short, bytes of the data changed.
  using G = GridDescription;
  seed(dir, "grid-plane", InputKind::kPlaneGrid, encode(plane()));
  seed(dir, "grid-cdf2", InputKind::kPlaneGrid, encode(plane(G::kCdf2)));
  seed(dir, "grid-packed", InputKind::kPlaneGrid, encode(plane(G::kPacked)));
  seed(dir, "grid-double", InputKind::kPlaneGrid, encode(plane(G::kDouble | G::kMissingValue | G::kCalendar)));
  seed(dir, "grid-depth", InputKind::kPlaneGrid, encode(plane(G::kDepth | G::kCdf2)));
  GridDescription g = plane();
  g.u.assign(27, 0.1);
  g.u[13] = g.fill;  // (t = 0.5 h, y = 0, x = 0): under the floe
  seed(dir, "grid-hole", InputKind::kPlaneGrid, encode(g));
  g = plane();
  g.velocity_units = "cm/s";
  g.time_units = "seconds since 2024-02-29T23:00:00Z";
  g.time = {0.0, 3600.0, 9000.0};
  seed(dir, "grid-units", InputKind::kPlaneGrid, encode(g));
  seed(dir, "grid-x-on-time", InputKind::kPlaneGrid, encode(plane(G::kXOnOtherDim)));
  g = plane();
  g.keep = 700;
  seed(dir, "grid-cut", InputKind::kPlaneGrid, encode(g));
  g = plane();
  g.flips = {{3, 0x40}, {57, 0xff}, {200, 0x7f}};
  seed(dir, "grid-flipped", InputKind::kPlaneGrid, encode(g));
  // On longitude and latitude, and on 0 to 360 degrees east.
  seed(dir, "grid-lonlat", InputKind::kLonLatGrid, encode(lonlat()));
  g = lonlat(G::kPacked);
  g.x = {379.9, 380.0, 380.1};
  seed(dir, "grid-lonlat-360", InputKind::kLonLatGrid, encode(g));

  // Records: plain, with comments and blank lines and more columns, and refused ones.
  seed(dir, "record", InputKind::kRecord, "time,u,v\n-60,5.0,1.0\n1800,6.5,-0.5\n3600,7.0,0.0\n");
  seed(dir, "record-comments", InputKind::kRecord,
       "# station 1, 10 m wind\n\ntime, speed, u, v\n0, 5.1, 5.0, 1.0\n# gap\n1200.5, 2, 1e0, -2.5e-1\n4000, 3, 3, 3\n");
  seed(dir, "record-short", InputKind::kRecord, "time,u,v\n0,1,1\n1000,1,1\n");
  seed(dir, "record-back", InputKind::kRecord, "time,u,v\n0,1,1\n3600,1,1\n1800,1,1\n");

  // Charts: two polygons of small floes over the domain (the east one notched, so concave)
  // and one of open water beyond it, one with a hole and numeric codes, and one refused for
  // an unknown code. Small floes (FA 03, 20 to 100 m): a few dozen in the domain.
  const double w = 19.994, e = 20.006, s = 69.998, n = 70.002, m = 20.0;
  seed(dir, "chart", InputKind::kChart,
       geojson({{{{w, s}, {m, s}, {m, n}, {w, n}}, "46", "87", "03", {}},
                {{{m, s}, {e, s}, {e, 70.0}, {e - 0.0005, 70.0005}, {e, n}, {m, n}}, "91", "91", "03", {}},
                {{{e, s}, {e + 0.01, s}, {e + 0.01, n}, {e, n}, {e - 0.0005, 70.0005}, {e, 70.0}}, "01", "-9", "-9", {}}}));
  seed(dir, "chart-hole", InputKind::kChart,
       geojson({{{{w, s}, {e, s}, {e, n}, {w, n}}, "57", "85", "03", {{m - 0.001, 69.9995}, {m + 0.001, 69.9995}, {m + 0.001, 70.0005}}}},
               true));
  seed(dir, "chart-bad-code", InputKind::kChart, geojson({{{{w, s}, {e, s}, {e, n}, {w, n}}, "77", "87", "03", {}}}));
  // The same charts as shapefiles (with their .prj; the one with a hole without).
  seed(dir, "shapefile", InputKind::kShapefile,
       shapefile(dir, geojson({{{{w, s}, {m, s}, {m, n}, {w, n}}, "46", "87", "03", {}},
                               {{{m, s}, {e, s}, {e, n}, {m, n}}, "91", "91", "03", {}}})));
  std::string holed = shapefile(dir, geojson({{{{w, s}, {e, s}, {e, n}, {w, n}}, "57", "85", "03",
                                               {{m - 0.001, 69.9995}, {m + 0.001, 69.9995}, {m + 0.001, 70.0005}}}}));
  auto holed_parts = floedem::fuzz::split_shapefile(reinterpret_cast<const std::uint8_t*>(holed.data()), holed.size());
  holed_parts[3].clear();
  seed(dir, "shapefile-hole", InputKind::kShapefile, floedem::fuzz::join_shapefile(holed_parts));

  return 0;
}
