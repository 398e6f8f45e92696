#include "floedem/field/ice_chart.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>
#include <numbers>
#include <sstream>

#include <cpl_error.h>
#include <gdal_priv.h>
#include <ogr_geometry.h>
#include <ogr_spatialref.h>
#include <ogrsf_frmts.h>

#include "floedem/field/sigrid3.hpp"
#include "geometry/polygon.hpp"
#include "floedem/scene/input_error.hpp"

namespace floedem {
namespace {

using GeometryPtr = std::unique_ptr<OGRGeometry>;

/// Largest edge, in degrees, of a chart polygon before it is projected (about 1 km of latitude):
/// an edge straight in degrees is a curve on the plane, and its chord's distance from that curve
/// grows as the edge's length squared (metres at 100 km, millimetres at 1 km).
constexpr double kMaxEdgeDeg = 0.01;

void register_drivers() {
  static std::once_flag once;
  std::call_once(once, [] { GDALAllRegister(); });
}

/// OGR's last message, or "" (GDAL reports through CPLError as well as return codes).
std::string ogr_reason() {
  const char* m = CPLGetLastErrorMsg();
  return (m && *m) ? " (" + printable(m, 200) + ")" : std::string();
}

/// A code attribute as an integer ("92", "09", "-9"); false where it is empty or not a number.
bool read_code(OGRFeature& f, int index, int& out, std::string& text) {
  if (index < 0 || !f.IsFieldSetAndNotNull(index)) {
    text = "";
    return false;
  }
  text = f.GetFieldAsString(index);
  const std::size_t a = text.find_first_not_of(" \t");
  const std::size_t b = text.find_last_not_of(" \t");
  text = a == std::string::npos ? std::string() : text.substr(a, b - a + 1);
  if (text.empty()) return false;
  std::size_t used = 0;
  try {
    out = std::stoi(text, &used);
  } catch (...) {
    return false;
  }
  return used == text.size();
}

/// A ring's points without repeated neighbours and without the closing repeat of the first.
std::vector<Vec2> without_repeats(const std::vector<Vec2>& pts) {
  std::vector<Vec2> out;
  out.reserve(pts.size());
  for (const Vec2 p : pts)
    if (out.empty() || p != out.back()) out.push_back(p);
  while (out.size() > 1 && out.front() == out.back()) out.pop_back();
  return out;
}

/// An OGR ring's vertices, without repeats (without_repeats).
std::vector<Vec2> ring_points(const OGRLinearRing& ring) {
  std::vector<Vec2> pts;
  pts.reserve(static_cast<std::size_t>(ring.getNumPoints()));
  for (int i = 0; i < ring.getNumPoints(); ++i) pts.push_back({ring.getX(i), ring.getY(i)});
  return without_repeats(pts);
}

std::unique_ptr<OGRLinearRing> make_ring(const std::vector<Vec2>& pts) {
  auto ring = std::make_unique<OGRLinearRing>();
  for (const Vec2 p : pts) ring->addPoint(p.x, p.y);
  ring->closeRings();
  return ring;
}

std::unique_ptr<OGRPolygon> make_polygon(const std::vector<Vec2>& outer, const std::vector<std::vector<Vec2>>& holes = {}) {
  auto poly = std::make_unique<OGRPolygon>();
  poly->addRingDirectly(make_ring(outer).release());
  for (const auto& h : holes) poly->addRingDirectly(make_ring(h).release());
  return poly;
}

/// The polygons of a geometry (a polygon, a multipolygon, or a collection holding them; the
/// lines and points an intersection can leave are dropped).
void collect_polygons(const OGRGeometry* g, std::vector<const OGRPolygon*>& out) {
  if (!g) return;
  switch (wkbFlatten(g->getGeometryType())) {
    case wkbPolygon:
      out.push_back(g->toPolygon());
      break;
    case wkbMultiPolygon:
    case wkbGeometryCollection:
      for (const OGRGeometry* part : *g->toGeometryCollection()) collect_polygons(part, out);
      break;
    default:
      break;
  }
}

/// The area of a geometry's polygons (an intersection of polygons that touch is a line: 0).
double area_of(const OGRGeometry* g) {
  std::vector<const OGRPolygon*> polys;
  collect_polygons(g, polys);
  double a = 0.0;
  for (const OGRPolygon* p : polys) a += p->get_Area();
  return a;
}

/// A piece of a chart polygon as the generator takes it. Vertices within a nanometre per metre
/// of the piece's bounding box are put on it: a chart's edge along a meridian projects to
/// x = 0 only to round-off, and the box's pockets (box_pockets) need the vertices that touch
/// the box to lie on it exactly.
ChartPart part_of(const OGRPolygon& p) {
  ChartPart part;
  std::vector<Vec2> ring = ring_points(*p.getExteriorRing());
  const auto [lo, hi] = bounds_of(ring);
  const double tol = 1e-9 * std::max(hi.x - lo.x, hi.y - lo.y);
  for (Vec2& v : ring) {
    if (v.x - lo.x <= tol) v.x = lo.x;
    if (hi.x - v.x <= tol) v.x = hi.x;
    if (v.y - lo.y <= tol) v.y = lo.y;
    if (hi.y - v.y <= tol) v.y = hi.y;
  }
  part.outer = without_repeats(ring);  // the snap can make neighbours equal
  if (signed_area(part.outer) < 0.0) std::reverse(part.outer.begin(), part.outer.end());
  for (int k = 0; k < p.getNumInteriorRings(); ++k) part.holes.push_back(ring_points(*p.getInteriorRing(k)));
  return part;
}

/// The SIGRID-3 codes of one feature, checked; the ranges they give.
void read_codes(OGRFeature& f, const int index[3], const std::string& where, ChartPolygon& poly) {
  std::string text;
  if (!read_code(f, index[0], poly.ct, text) || !sigrid3::concentration(poly.ct))
    throw InputError(where + "attribute CT = '" + printable(text) + "' is not a SIGRID-3 total concentration; allowed " +
                     sigrid3::allowed("CT"));
  poly.concentration = *sigrid3::concentration(poly.ct);
  if (poly.concentration == 0.0) return;  // no ice: its stage and form are not read
  std::optional<sigrid3::CodeRange> stage, form;
  if (!read_code(f, index[1], poly.sa, text) || !(stage = sigrid3::thickness(poly.sa)))
    throw InputError(where + "attribute SA = '" + printable(text) + "' is not a SIGRID-3 stage of development with a thickness; allowed " +
                     sigrid3::allowed("SA"));
  if (!read_code(f, index[2], poly.fa, text) || !(form = sigrid3::floe_size(poly.fa)))
    throw InputError(where + "attribute FA = '" + printable(text) + "' is not a SIGRID-3 form of ice of bounded floe size; allowed " +
                     sigrid3::allowed("FA"));
  poly.thickness_min = stage->lo;
  poly.thickness_max = stage->hi;
  poly.d_min = form->lo;
  poly.d_max = form->hi;
}

/// The transformation of the layer's coordinates to WGS 84 longitude and latitude, or none
/// where the layer has no reference system (its coordinates are read as longitude, latitude).
std::unique_ptr<OGRCoordinateTransformation> to_wgs84(OGRLayer& layer, const std::string& file) {
  const OGRSpatialReference* given = layer.GetSpatialRef();
  if (!given) return nullptr;
  OGRSpatialReference source(*given);
  source.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  OGRSpatialReference wgs84;
  wgs84.SetWellKnownGeogCS("WGS84");
  wgs84.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  std::unique_ptr<OGRCoordinateTransformation> ct(OGRCreateCoordinateTransformation(&source, &wgs84));
  if (!ct)
    throw InputError(file + ": its coordinate reference system cannot be transformed to WGS 84" + ogr_reason() +
                     "; allowed a system PROJ knows, or longitude and latitude without one");
  return ct;
}

/// GDAL's default handler prints each CPLError to stderr as it happens ("ERROR 1: Invalid
/// Polygon object ..."), and so does GEOS through it; floedem reports one line of its own, with
/// CPLGetLastErrorMsg as the reason, so the handler is quiet for as long as a chart is handled.
struct QuietGdal {
  QuietGdal() {
    CPLErrorReset();
    CPLPushErrorHandler(CPLQuietErrorHandler);
  }
  ~QuietGdal() { CPLPopErrorHandler(); }
  QuietGdal(const QuietGdal&) = delete;
  QuietGdal& operator=(const QuietGdal&) = delete;
};

}  // namespace

IceChart read_ice_chart(const std::string& path, const std::string& layer_name, const GeoProjection& geo) {
  const QuietGdal quiet;
  register_drivers();
  if (!OGRGeometryFactory::haveGEOS())
    throw InputError(path + ": this build's GDAL has no GEOS, which ice charts need to cut polygons");
  GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY));
  if (!ds) throw InputError(path + ": cannot be opened as a vector file" + ogr_reason() + "; allowed a shapefile, GeoJSON or any file GDAL's OGR reads");
  OGRLayer* layer = layer_name.empty() ? (ds->GetLayerCount() > 0 ? ds->GetLayer(0) : nullptr)
                                       : ds->GetLayerByName(layer_name.c_str());
  if (!layer)
    throw InputError(path + ": " + (layer_name.empty() ? std::string("has no layer") : "has no layer '" + layer_name + "'") +
                     "; allowed a file with a layer of polygons");
  IceChart chart;
  chart.path = path;
  chart.layer = layer->GetName();
  const std::string where_file = path + ": layer '" + chart.layer + "': ";
  OGRFeatureDefn* defn = layer->GetLayerDefn();
  int index[3];
  const char* names[3] = {"CT", "SA", "FA"};
  for (int k = 0; k < 3; ++k) {
    index[k] = defn->GetFieldIndex(names[k]);
    if (index[k] < 0)
      throw InputError(where_file + "has no attribute " + names[k] +
                       "; allowed a SIGRID-3 chart with CT (total concentration), SA (stage of development) and FA (form of ice)");
  }
  const auto transform = to_wgs84(*layer, path);
  layer->ResetReading();
  for (auto& feature : *layer) {
    ChartPolygon poly;
    poly.fid = feature->GetFID();
    const std::string where = where_file + "feature " + std::to_string(poly.fid) + ": ";
    read_codes(*feature, index, where, poly);
    const OGRGeometry* g0 = feature->GetGeometryRef();
    const OGRwkbGeometryType type = g0 ? wkbFlatten(g0->getGeometryType()) : wkbUnknown;
    if (!g0 || (type != wkbPolygon && type != wkbMultiPolygon))
      throw InputError(where + "geometry is " + (g0 ? std::string(g0->getGeometryName()) : std::string("missing")) +
                       "; allowed a polygon or multipolygon");
    GeometryPtr g(g0->clone());
    if (transform && g->transform(transform.get()) != OGRERR_NONE)
      throw InputError(where + "cannot be transformed to longitude and latitude" + ogr_reason());
    CPLErrorReset();
    const bool valid = g->IsValid();
    if (!valid)
      throw InputError(where + "is not a valid polygon" + ogr_reason() +
                       "; allowed rings that do not cross themselves or each other, holes inside their outer ring");
    std::vector<const OGRPolygon*> pieces;
    // The vertices are checked before the edges are cut into kMaxEdgeDeg pieces: a vertex at
    // 1e7 deg would otherwise be cut into some 1e9 points before it could be refused.
    collect_polygons(g.get(), pieces);
    auto check_ring = [&](const OGRLinearRing& ring) {
      for (int k = 0; k < ring.getNumPoints(); ++k)
        if (!(std::abs(ring.getX(k)) <= 180.0 && std::abs(ring.getY(k)) <= 90.0)) {
          std::ostringstream at;
          at << "(" << ring.getX(k) << ", " << ring.getY(k) << ")";
          throw InputError(where + "has a vertex at " + at.str() +
                           ", not a longitude and latitude; allowed lon in [-180, 180], lat in [-90, 90] "
                           "(or a file with its coordinate reference system)");
        }
    };
    for (const OGRPolygon* p : pieces) {
      check_ring(*p->getExteriorRing());
      for (int k = 0; k < p->getNumInteriorRings(); ++k) check_ring(*p->getInteriorRing(k));
    }
    g->segmentize(kMaxEdgeDeg);
    pieces.clear();
    collect_polygons(g.get(), pieces);
    for (const OGRPolygon* p : pieces) {
      ChartPart part;
      auto project = [&](const OGRLinearRing& ring) {
        std::vector<Vec2> out = ring_points(ring);
        for (Vec2& v : out) v = geo.to_plane({v.x, v.y});
        return out;
      };
      part.outer = project(*p->getExteriorRing());
      if (signed_area(part.outer) < 0.0) std::reverse(part.outer.begin(), part.outer.end());
      for (int k = 0; k < p->getNumInteriorRings(); ++k) part.holes.push_back(project(*p->getInteriorRing(k)));
      poly.parts.push_back(std::move(part));
    }
    chart.polygons.push_back(std::move(poly));
  }
  if (chart.polygons.empty()) throw InputError(where_file + "has no features; allowed at least one polygon");

  // Polygons of one chart tile the sea: two that overlap say two things of one place.
  std::vector<std::unique_ptr<OGRPolygon>> plane;
  std::vector<std::size_t> owner;
  for (std::size_t i = 0; i < chart.polygons.size(); ++i)
    for (const ChartPart& part : chart.polygons[i].parts) {
      plane.push_back(make_polygon(part.outer, part.holes));
      owner.push_back(i);
    }
  for (std::size_t a = 0; a < plane.size(); ++a) {
    OGREnvelope ea;
    plane[a]->getEnvelope(&ea);
    for (std::size_t b = a + 1; b < plane.size(); ++b) {
      if (owner[a] == owner[b]) continue;
      OGREnvelope eb;
      plane[b]->getEnvelope(&eb);
      if (!ea.Intersects(eb)) continue;
      GeometryPtr common(plane[a]->Intersection(plane[b].get()));
      const double overlap = area_of(common.get());
      if (overlap > 1e-6 * std::min(area_of(plane[a].get()), area_of(plane[b].get())))
        throw InputError(where_file + "features " + std::to_string(chart.polygons[owner[a]].fid) + " and " +
                         std::to_string(chart.polygons[owner[b]].fid) + " overlap by " + std::to_string(overlap) +
                         " m^2; allowed polygons that do not overlap");
    }
  }
  return chart;
}

namespace {

/// Where a point of a rectangle's outline lies along it, counter-clockwise from the lower-left
/// corner (the bottom edge first), in [0, 2 (w + h)).
double perimeter_position(Vec2 p, Vec2 lo, Vec2 hi) {
  const double w = hi.x - lo.x, h = hi.y - lo.y;
  if (p.y == lo.y && p.x < hi.x) return p.x - lo.x;
  if (p.x == hi.x && p.y < hi.y) return w + (p.y - lo.y);
  if (p.y == hi.y && p.x > lo.x) return w + h + (hi.x - p.x);
  return 2.0 * w + h + (hi.y - p.y);  // left edge, going down
}

/// The pockets of a simple counter-clockwise polygon's bounding box: the regions of the box
/// outside the polygon. The polygon touches its box at vertices only (at least one on each
/// side); between two touching vertices next to each other along the polygon, its chain and
/// the box's outline between them (clockwise, the short way: the touching vertices come in the
/// same order along both) enclose one pocket, which is simple because the chain meets the
/// outline only at its ends. Together the pockets are the box less the polygon.
std::vector<std::vector<Vec2>> box_pockets(const std::vector<Vec2>& ring) {
  const auto [lo, hi] = bounds_of(ring);
  const std::size_t n = ring.size();
  std::vector<std::size_t> touch;
  for (std::size_t i = 0; i < n; ++i)
    if (ring[i].x == lo.x || ring[i].x == hi.x || ring[i].y == lo.y || ring[i].y == hi.y) touch.push_back(i);
  const double w = hi.x - lo.x, h = hi.y - lo.y, perimeter = 2.0 * (w + h);
  const Vec2 corners[4] = {lo, {hi.x, lo.y}, hi, {lo.x, hi.y}};
  const double corner_at[4] = {0.0, w, w + h, 2.0 * w + h};
  const double box_area = w * h;
  std::vector<std::vector<Vec2>> pockets;
  for (std::size_t t = 0; t < touch.size(); ++t) {
    const std::size_t a = touch[t], b = touch[(t + 1) % touch.size()];
    std::vector<Vec2> pocket;
    for (std::size_t i = a;; i = (i + 1) % n) {
      pocket.push_back(ring[i]);
      if (i == b) break;
    }
    // From b back to a, clockwise: the corners strictly between their positions.
    const double sa = perimeter_position(ring[a], lo, hi);
    double sb = perimeter_position(ring[b], lo, hi);
    if (sb < sa) sb += perimeter;
    std::vector<Vec2> between;
    for (int k = 0; k < 8; ++k) {
      const double s = corner_at[k % 4] + (k >= 4 ? perimeter : 0.0);
      if (s > sa && s < sb) between.push_back(corners[k % 4]);
    }
    for (auto it = between.rbegin(); it != between.rend(); ++it) pocket.push_back(*it);
    if (pocket.size() >= 3 && std::abs(signed_area(pocket)) > 1e-12 * box_area) pockets.push_back(std::move(pocket));
  }
  return pockets;
}

/// splitmix64: a piece's seed from the field's, the polygon's index and the piece's.
std::uint64_t piece_seed(std::uint64_t seed, std::size_t polygon, std::size_t piece) {
  std::uint64_t z = seed + 0x9e3779b97f4a7c15ULL * (1 + polygon * 1000003ULL + piece);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

}  // namespace

Field generate_chart_field(const IceChart& chart, const FieldSpec& base, std::vector<ChartPolygonStats>& stats) {
  const QuietGdal quiet;
  const Vec2 lo = base.origin, hi = base.origin + Vec2{base.width, base.height};
  const auto rect = make_polygon({lo, {hi.x, lo.y}, hi, {lo.x, hi.y}});
  std::vector<std::unique_ptr<OGRPolygon>> zones;
  for (const auto& z : base.keep_out) {
    std::vector<Vec2> ccw = z;
    if (signed_area(ccw) < 0.0) std::reverse(ccw.begin(), ccw.end());
    zones.push_back(make_polygon(ccw));
  }
  Field field;
  stats.clear();
  for (std::size_t i = 0; i < chart.polygons.size(); ++i) {
    const ChartPolygon& poly = chart.polygons[i];
    ChartPolygonStats st;
    st.fid = poly.fid;
    st.d_max_used = poly.d_max;
    // The polygon's free region: inside the rectangle, outside every body and keep-out zone.
    std::vector<GeometryPtr> region;
    for (const ChartPart& part : poly.parts) {
      const auto p = make_polygon(part.outer, part.holes);
      GeometryPtr cut(p->Intersection(rect.get()));
      if (!cut) throw FieldSpecError("chart", chart.path + ": feature " + std::to_string(poly.fid) + ": cannot be cut to the field" + ogr_reason());
      st.area += area_of(cut.get());
      OGREnvelope e;
      cut->getEnvelope(&e);
      for (const auto& z : zones) {
        OGREnvelope ez;
        z->getEnvelope(&ez);
        if (!e.Intersects(ez)) continue;
        GeometryPtr rest(cut->Difference(z.get()));
        if (!rest) throw FieldSpecError("chart", chart.path + ": feature " + std::to_string(poly.fid) + ": cannot be cut free of a body" + ogr_reason());
        cut = std::move(rest);
      }
      region.push_back(std::move(cut));
    }
    std::vector<const OGRPolygon*> pieces;
    for (const GeometryPtr& g : region) collect_polygons(g.get(), pieces);
    std::vector<double> piece_area;
    for (const OGRPolygon* p : pieces) {
      piece_area.push_back(p->get_Area());
      st.free_area += piece_area.back();
    }
    if (poly.concentration > 0.0) {
      const double c = std::min(poly.concentration, FieldSpec::max_concentration);
      std::vector<double> d_poly;
      for (std::size_t k = 0; k < pieces.size(); ++k) {
        // The generator needs the free area to hold the cell of its largest floe, pi d_max^2 / (4 C).
        const double d_fit = std::sqrt(4.0 * c * piece_area[k] / std::numbers::pi);
        if (!(d_fit >= poly.d_min)) {
          ++st.pieces_too_small;
          continue;
        }
        const ChartPart part = part_of(*pieces[k]);
        FieldSpec spec;
        const auto [plo, phi] = bounds_of(part.outer);
        spec.origin = plo;
        spec.width = phi.x - plo.x;
        spec.height = phi.y - plo.y;
        spec.concentration = c;
        spec.alpha = base.alpha;
        spec.d_min = poly.d_min;
        // Slightly below the fit: the generator compares the cell with the free area it
        // measures itself, which round-off can leave a hair short of OGR's.
        spec.d_max = std::min(poly.d_max, d_fit * (1.0 - 1e-9));
        st.d_max_used = std::min(st.d_max_used, spec.d_max);
        if (poly.thickness_min == poly.thickness_max) {
          spec.thickness.value = poly.thickness_min;
        } else {
          spec.thickness.kind = ThicknessDistribution::Kind::uniform;
          spec.thickness.min = poly.thickness_min;
          spec.thickness.max = poly.thickness_max;
        }
        spec.irregularity = base.irregularity;
        spec.seed = piece_seed(base.seed, i, k);
        const std::string name = "the outside of chart feature " + std::to_string(poly.fid);
        for (auto& pocket : box_pockets(part.outer)) {
          spec.keep_out.push_back(std::move(pocket));
          spec.keep_out_names.push_back(name);
        }
        for (std::size_t h = 0; h < part.holes.size(); ++h) {
          spec.keep_out.push_back(part.holes[h]);
          spec.keep_out_names.push_back("hole " + std::to_string(h) + " of chart feature " + std::to_string(poly.fid));
        }
        Field piece;
        try {
          piece = generate_field(spec);
        } catch (const FieldSpecError& e) {
          throw FieldSpecError("chart", chart.path + ": feature " + std::to_string(poly.fid) + ", piece " +
                                            std::to_string(k) + ": " + e.what());
        }
        ++st.pieces;
        st.floes += piece.floes.size();
        st.ice_area += piece.stats.ice_area;
        for (std::size_t f = 0; f < piece.floes.size(); ++f) {
          d_poly.push_back(std::sqrt(4.0 * signed_area(piece.floes[f]) / std::numbers::pi));
          field.floes.push_back(std::move(piece.floes[f]));
          field.thickness.push_back(piece.thickness[f]);
        }
        field.stats.newton_iterations += piece.stats.newton_iterations;
        field.stats.lloyd_steps += piece.stats.lloyd_steps;
        field.stats.max_cell_area_error = std::max(field.stats.max_cell_area_error, piece.stats.max_cell_area_error);
        field.stats.floes_short_of_area += piece.stats.floes_short_of_area;
        field.stats.floes_dropped_below_d_min += piece.stats.floes_dropped_below_d_min;
      }
      if (!d_poly.empty()) st.fit = fit_truncated_power_law(d_poly, poly.d_min, st.d_max_used);
    }
    field.stats.free_area += st.free_area;
    field.stats.ice_area += st.ice_area;
    stats.push_back(st);
  }
  field.stats.floes = field.floes.size();
  field.stats.concentration = field.stats.free_area > 0.0 ? field.stats.ice_area / field.stats.free_area : 0.0;
  return field;
}

}  // namespace floedem
