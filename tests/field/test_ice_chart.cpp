// Ice from an ice chart (docs/ice_charts.md): the SIGRID-3 tables, the field each polygon
// gets (inside its polygon, at its concentration, sizes and thickness, no two floes
// overlapping), the same chart as GeoJSON, as a shapefile and in a polar stereographic
// reference system, and the refusals.
#include <catch2/catch.hpp>

#include <gdal_priv.h>
#include <ogr_spatialref.h>
#include <ogrsf_frmts.h>

#include <cmath>
#include <fstream>
#include <numbers>

#include "field/exact_geometry.hpp"
#include "floedem/field/ice_chart.hpp"
#include "floedem/field/sigrid3.hpp"
#include "floedem/scene/input_error.hpp"
#include "geometry/polygon.hpp"
#include "support.hpp"

using namespace floedem;

namespace {

struct TestFeature {
  std::vector<std::array<double, 2>> ring;  ///< lon, lat; closed by the writer
  std::string ct, sa, fa;
};

/// Three polygons of a chart about (15 E, 76 N), 0.02 deg of longitude (537 m) and 0.02 deg of
/// latitude (2.2 km) each: 4-6/10 thin first-year ice in small floes; 9-10/10 medium first-year
/// ice in small floes, its east side notched (a concave polygon); east of it open water.
std::vector<TestFeature> three_polygons() {
  return {{{{14.98, 75.99}, {15.0, 75.99}, {15.0, 76.01}, {14.98, 76.01}}, "46", "87", "03"},
          {{{15.0, 75.99}, {15.02, 75.99}, {15.02, 76.0}, {15.01, 76.005}, {15.02, 76.01}, {15.0, 76.01}}, "91", "91", "03"},
          {{{15.02, 75.99}, {15.04, 75.99}, {15.04, 76.01}, {15.02, 76.01}, {15.01, 76.005}, {15.02, 76.0}}, "01", "-9", "-9"}};
}

/// Writes the features with GDAL's own driver ("GeoJSON", "ESRI Shapefile"), in longitude and
/// latitude or, with `epsg`, in that reference system; the attributes as strings, as SIGRID-3
/// shapefiles have them.
void write_chart(const std::filesystem::path& path, const std::string& driver_name, const std::vector<TestFeature>& features,
                 int epsg = 0) {
  GDALAllRegister();
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName(driver_name.c_str());
  REQUIRE(driver);
  GDALDatasetUniquePtr ds(driver->Create(path.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
  REQUIRE(ds);
  OGRSpatialReference wgs84, target;
  wgs84.SetWellKnownGeogCS("WGS84");
  wgs84.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  std::unique_ptr<OGRCoordinateTransformation> ct;
  if (epsg) {
    target.importFromEPSG(epsg);
    target.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    ct.reset(OGRCreateCoordinateTransformation(&wgs84, &target));
    REQUIRE(ct);
  }
  OGRLayer* layer = ds->CreateLayer("chart", epsg ? &target : &wgs84, wkbPolygon, nullptr);
  REQUIRE(layer);
  for (const char* name : {"CT", "SA", "FA"}) {
    OGRFieldDefn field(name, OFTString);
    field.SetWidth(2);
    REQUIRE(layer->CreateField(&field) == OGRERR_NONE);
  }
  for (const TestFeature& f : features) {
    OGRFeature feature(layer->GetLayerDefn());
    feature.SetField("CT", f.ct.c_str());
    feature.SetField("SA", f.sa.c_str());
    feature.SetField("FA", f.fa.c_str());
    OGRLinearRing ring;
    for (const auto& p : f.ring) ring.addPoint(p[0], p[1]);
    ring.closeRings();
    OGRPolygon poly;
    poly.addRing(&ring);
    if (ct) REQUIRE(poly.transform(ct.get()) == OGRERR_NONE);
    feature.SetGeometry(&poly);
    REQUIRE(layer->CreateFeature(&feature) == OGRERR_NONE);
  }
}

std::string chart_scene(const std::string& chart, const std::string& extra = "") {
  return "[run]\nduration = 1.0\ndt = 0.5\nseed = 3\n[geo]\norigin = [15.0, 76.0]\n"
         "[[body]]\nname = \"berg\"\nkind = \"iceberg\"\npolygon = [[-60.0, -40.0], [60.0, -40.0], [60.0, 40.0], [-60.0, 40.0]]\n"
         "draft = 50.0\nsail_height = 10.0\n"
         "[field]\nchart = \"" + chart + "\"\norigin = [-1200.0, -1000.0]\nwidth = 2400.0\nheight = 2000.0\nalpha = 2.0\n" + extra;
}

Scene scene_at(const std::filesystem::path& dir, const std::string& text) {
  const std::filesystem::path path = dir / "scene.toml";
  std::ofstream(path) << text;
  return parse_scenario(text, path.string());
}

/// Even-odd point-in-polygon.
bool inside(const std::vector<Vec2>& poly, Vec2 p) {
  bool in = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++)
    if ((poly[i].y > p.y) != (poly[j].y > p.y) &&
        p.x < (poly[j].x - poly[i].x) * (p.y - poly[i].y) / (poly[j].y - poly[i].y) + poly[i].x)
      in = !in;
  return in;
}

}  // namespace

TEST_CASE("SIGRID-3 codes give the generator's concentration, sizes and thickness", "[chart]") {
  CHECK(sigrid3::concentration(46) == Approx(0.5));
  CHECK(sigrid3::concentration(91) == Approx(0.95));
  CHECK(sigrid3::concentration(81) == Approx(0.9));   // 8/10 to 10/10
  CHECK(sigrid3::concentration(92) == 1.0);
  CHECK(sigrid3::concentration(70) == Approx(0.7));
  CHECK(sigrid3::concentration(0) == 0.0);
  CHECK(sigrid3::concentration(2) == 0.0);             // bergy water: no sea ice
  CHECK_FALSE(sigrid3::concentration(99));             // unknown
  CHECK_FALSE(sigrid3::concentration(55));             // no code
  CHECK_FALSE(sigrid3::concentration(-9));             // null
  const auto thin = sigrid3::thickness(87);
  REQUIRE(thin);
  CHECK(thin->lo == 0.3);
  CHECK(thin->hi == 0.7);
  CHECK_FALSE(sigrid3::thickness(98));                 // glacier ice: a [[body]], not a field
  const auto small = sigrid3::floe_size(3);
  REQUIRE(small);
  CHECK(small->lo == 20.0);
  CHECK(small->hi == 100.0);
  CHECK(sigrid3::floe_size(22)->hi == 3.0);            // pancake ice
  for (int code : {7, 8, 9, 10, 21, 99}) CHECK_FALSE(sigrid3::floe_size(code));
  CHECK(sigrid3::allowed("CT").find("91, 92") != std::string::npos);
}

TEST_CASE("A chart's polygons are each filled with their own ice, inside them and apart", "[chart]") {
  const auto dir = test::temp_dir("chart-fill");
  write_chart(dir / "chart.geojson", "GeoJSON", three_polygons());
  const Scene s = scene_at(dir, chart_scene("chart.geojson"));
  GeoSpec g = s.geo;
  const GeoProjection geo(g);
  const IceChart chart = read_ice_chart((dir / "chart.geojson").string(), "", geo);
  REQUIRE(chart.polygons.size() == 3);

  // The scene's floes are the chart's: the iceberg first, then every floe of the field.
  std::vector<std::vector<Vec2>> floes;
  for (std::size_t i = 1; i < s.bodies.size(); ++i) floes.push_back(s.bodies[i].polygon);
  REQUIRE(floes.size() > 1000);
  CHECK_FALSE(test::first_overlap(floes));
  std::vector<std::vector<Vec2>> with_berg = floes;
  with_berg.push_back(s.bodies[0].polygon);
  CHECK_FALSE(test::first_overlap(with_berg));

  // Each floe inside one polygon, with that polygon's thickness; the open water has none.
  std::vector<double> ice(3, 0.0);
  for (std::size_t i = 1; i < s.bodies.size(); ++i) {
    const BodySpec& b = s.bodies[i];
    int owner = -1;
    for (std::size_t k = 0; k < 3; ++k) {
      bool all = true;
      for (const Vec2 v : b.polygon) all = all && inside(chart.polygons[k].parts[0].outer, v);
      if (all) owner = static_cast<int>(k);
    }
    REQUIRE(owner >= 0);
    REQUIRE(owner < 2);
    const ChartPolygon& p = chart.polygons[static_cast<std::size_t>(owner)];
    CHECK(b.thickness >= p.thickness_min);
    CHECK(b.thickness <= p.thickness_max);
    const double d = std::sqrt(4.0 * signed_area(b.polygon) / std::numbers::pi);
    CHECK(d <= p.d_max * (1.0 + 1e-9));
    ice[static_cast<std::size_t>(owner)] += signed_area(b.polygon);
  }
  // At each polygon's concentration of its area in the rectangle, less the iceberg's half in
  // each: 0.5 exactly where the polygon is a rectangle (the generator's cells fill it), and
  // within 2 % of 0.95 in the notched one, whose cells the notch's pockets cut short.
  const double berg_half = 60.0 * 80.0;
  std::vector<ChartPolygonStats> stats;
  FieldSpec base;
  base.origin = {-1200.0, -1000.0};
  base.width = 2400.0;
  base.height = 2000.0;
  base.alpha = 2.0;
  base.seed = 3;
  base.keep_out.push_back(s.bodies[0].polygon);
  const Field again = generate_chart_field(chart, base, stats);
  REQUIRE(stats.size() == 3);
  CHECK(stats[0].free_area == Approx(stats[0].area - berg_half).epsilon(1e-9));
  CHECK(stats[1].free_area == Approx(stats[1].area - berg_half).epsilon(1e-9));
  CHECK(ice[0] / stats[0].free_area == Approx(0.5).epsilon(1e-6));
  CHECK(ice[1] / stats[1].free_area == Approx(0.95).epsilon(0.02));
  CHECK(stats[2].floes == 0);
  // The field the scenario made is the one the library makes from the same chart and seed.
  REQUIRE(again.floes.size() == floes.size());
  for (std::size_t i = 0; i < floes.size(); ++i) REQUIRE(again.floes[i] == floes[i]);
  // A fitted exponent near the asked 2 in each filled polygon (hundreds of floes: +-0.1).
  CHECK(stats[0].fit.alpha == Approx(2.0).margin(0.15));
  CHECK(stats[1].fit.alpha == Approx(2.0).margin(0.15));
}

TEST_CASE("A chart reads the same as a shapefile and in a polar stereographic system", "[chart]") {
  const auto dir = test::temp_dir("chart-formats");
  write_chart(dir / "chart.geojson", "GeoJSON", three_polygons());
  write_chart(dir / "chart.shp", "ESRI Shapefile", three_polygons());
  write_chart(dir / "stereo.geojson", "GeoJSON", three_polygons(), 3413);  // NSIDC sea ice polar stereographic north
  GeoSpec g;
  g.present = true;
  g.origin_lon = 15.0;
  g.origin_lat = 76.0;
  g.projection = GeoSpec::default_projection(15.0, 76.0);
  const GeoProjection geo(g);
  const IceChart a = read_ice_chart((dir / "chart.geojson").string(), "", geo);
  const IceChart b = read_ice_chart((dir / "chart.shp").string(), "", geo);
  const IceChart c = read_ice_chart((dir / "stereo.geojson").string(), "", geo);
  REQUIRE(b.polygons.size() == 3);
  REQUIRE(c.polygons.size() == 3);
  for (std::size_t k = 0; k < 3; ++k) {
    CHECK(b.polygons[k].ct == a.polygons[k].ct);
    CHECK(c.polygons[k].fa == a.polygons[k].fa);
    const double area = signed_area(a.polygons[k].parts[0].outer);
    // The shapefile holds the same doubles; the stereographic chart went through two
    // transformations, and its edges are straight in the stereographic plane, not in degrees:
    // over 0.02 deg the two courses part by millimetres.
    CHECK(signed_area(b.polygons[k].parts[0].outer) == Approx(area).epsilon(1e-12));
    CHECK(signed_area(c.polygons[k].parts[0].outer) == Approx(area).epsilon(1e-5));
  }
}

TEST_CASE("Bad charts are refused with the file, the feature and the attribute", "[chart][input]") {
  const auto dir = test::temp_dir("chart-bad");
  auto refused = [&](const std::vector<TestFeature>& features, const std::string& expect, const std::string& extra = "") {
    write_chart(dir / "bad.geojson", "GeoJSON", features);
    try {
      scene_at(dir, chart_scene("bad.geojson", extra));
      FAIL("accepted; expected " << expect);
    } catch (const InputError& e) {
      const std::string m = e.what();
      INFO(m);
      CHECK(m.find("field.chart") != std::string::npos);
      CHECK(m.find("bad.geojson") != std::string::npos);
      CHECK(m.find(expect) != std::string::npos);
      CHECK(m.find('\n') == std::string::npos);
    }
    std::filesystem::remove(dir / "bad.geojson");
  };
  auto with = [](std::string ct, std::string sa, std::string fa) {
    auto f = three_polygons();
    f[0].ct = std::move(ct);
    f[0].sa = std::move(sa);
    f[0].fa = std::move(fa);
    return f;
  };
  refused(with("55", "87", "03"), "feature 0: attribute CT = '55' is not a SIGRID-3 total concentration; allowed 00, 01, 02, 10");
  refused(with("99", "87", "03"), "attribute CT = '99'");
  refused(with("", "87", "03"), "attribute CT = ''");
  refused(with("46", "98", "03"), "attribute SA = '98' is not a SIGRID-3 stage of development with a thickness");
  refused(with("46", "87", "10"), "attribute FA = '10' is not a SIGRID-3 form of ice of bounded floe size");
  refused(with("46", "87", "x3"), "attribute FA = 'x3'");
  auto bowtie = three_polygons();
  bowtie[0].ring = {{14.98, 75.99}, {15.0, 76.01}, {15.0, 75.99}, {14.98, 76.01}};
  refused(bowtie, "feature 0: is not a valid polygon");
  // A vertex far off the globe (a mangled coordinate) is refused before the edges are cut into
  // short pieces for the projection, which would make some 1e9 points of it.
  auto far = three_polygons();
  far[0].ring = {{14.98, 75.99}, {1.5e7, 75.99}, {14.98, 76.01}};
  refused(far, "feature 0: has a vertex at (1.5e+07, 75.99), not a longitude and latitude; allowed lon in [-180, 180]");
  auto overlapping = three_polygons();
  overlapping[1].ring = {{14.99, 75.99}, {15.02, 75.99}, {15.02, 76.01}, {14.99, 76.01}};
  refused(overlapping, "features 0 and 1 overlap");

  // Keys the chart sets, a chart without [geo], a file that is not there.
  write_chart(dir / "good.geojson", "GeoJSON", three_polygons());
  CHECK_THROWS_WITH(scene_at(dir, chart_scene("good.geojson", "concentration = 0.5\n")),
                    Catch::Contains("field 'field.concentration': is set by the chart's codes"));
  std::string no_geo = chart_scene("good.geojson");
  const std::string geo_table = "[geo]\norigin = [15.0, 76.0]\n";
  no_geo.replace(no_geo.find(geo_table), geo_table.size(), "");
  CHECK_THROWS_WITH(scene_at(dir, no_geo), Catch::Contains("needs a [geo] table"));
  CHECK_THROWS_WITH(scene_at(dir, chart_scene("missing.geojson")),
                    Catch::Contains("missing.geojson: cannot be opened as a vector file"));
  CHECK_THROWS_WITH(scene_at(dir, chart_scene("good.geojson", "layer = \"ice\"\n")), Catch::Contains("has no layer 'ice'"));

  // Through the command line: exit 2, one line, nothing written.
  write_chart(dir / "bad.geojson", "GeoJSON", with("55", "87", "03"));
  std::ofstream(dir / "scene.toml") << chart_scene("bad.geojson");
  const auto r = test::run_cli("run " + (dir / "scene.toml").string() + " --out " + (dir / "out.h5").string() + " --quiet");
  CHECK(r.code == 2);
  CHECK(std::count(r.output.begin(), r.output.end(), '\n') == 1);
  CHECK_FALSE(std::filesystem::exists(dir / "out.h5"));
  CHECK_FALSE(std::filesystem::exists(dir / "out.h5.partial"));
}
