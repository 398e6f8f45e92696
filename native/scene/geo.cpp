// The scene's plane on the earth through PROJ (Debian's libproj; PROJ's C API, proj.h).
#include "floedem/scene/geo.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

#include <proj.h>

#include "floedem/scene/input_error.hpp"

namespace floedem {

double coriolis_parameter(double latitude_deg) { return 2.0 * kEarthRotation * std::sin(latitude_deg * M_PI / 180.0); }

std::string GeoSpec::default_projection(double lon, double lat) {
  // %.17g: the origin to the bit, so that the plane's (0, 0) is the origin given.
  char text[160];
  std::snprintf(text, sizeof text, "+proj=aeqd +lat_0=%.17g +lon_0=%.17g +datum=WGS84 +units=m +type=crs", lat, lon);
  return text;
}

struct GeoProjection::Impl {
  PJ_CONTEXT* context = nullptr;
  PJ* transform = nullptr;  // longitude, latitude (deg) -> easting, northing (m) of the projection
  Vec2 offset;              // the origin's easting and northing: the plane is shifted by it
  ~Impl() {
    if (transform) proj_destroy(transform);
    if (context) proj_context_destroy(context);
  }
  std::string last_error() const { return proj_context_errno_string(context, proj_context_errno(context)); }
};

GeoProjection::GeoProjection(const GeoSpec& geo) : impl_(std::make_unique<Impl>()) {
  Impl& d = *impl_;
  d.context = proj_context_create();
  proj_log_level(d.context, PJ_LOG_NONE);  // errors come back as exceptions, not on stderr
  const std::string& definition = geo.projection.empty() ? GeoSpec::default_projection(geo.origin_lon, geo.origin_lat)
                                                         : geo.projection;
  PJ* crs = proj_create(d.context, definition.c_str());
  if (!crs) throw InputError("\"" + definition + "\" is not a PROJ definition PROJ can read (" + d.last_error() + ")");
  const PJ_TYPE type = proj_get_type(crs);
  bool metres = false;
  if (type == PJ_TYPE_PROJECTED_CRS) {
    if (PJ* cs = proj_crs_get_coordinate_system(d.context, crs)) {
      metres = true;
      for (int axis = 0; axis < proj_cs_get_axis_count(d.context, cs); ++axis) {
        double factor = 0.0;
        proj_cs_get_axis_info(d.context, cs, axis, nullptr, nullptr, nullptr, &factor, nullptr, nullptr, nullptr);
        metres = metres && factor == 1.0;
      }
      proj_destroy(cs);
    }
  }
  if (!metres) {
    proj_destroy(crs);
    throw InputError("\"" + definition + "\" is not a projected coordinate reference system in metres; allowed e.g. "
                     "\"+proj=stere +lat_0=90 +lat_ts=70 +lon_0=-45 +datum=WGS84 +units=m +type=crs\" or \"EPSG:3413\"");
  }
  PJ* lonlat = proj_create(d.context, "+proj=longlat +datum=WGS84 +no_defs +type=crs");
  PJ* raw = proj_create_crs_to_crs_from_pj(d.context, lonlat, crs, nullptr, nullptr);
  proj_destroy(lonlat);
  proj_destroy(crs);
  if (!raw) throw InputError("no transformation from longitude and latitude to \"" + definition + "\" (" + d.last_error() + ")");
  // In the order a map is read: longitude, latitude in; easting, northing out.
  d.transform = proj_normalize_for_visualization(d.context, raw);
  proj_destroy(raw);
  if (!d.transform) throw InputError("cannot order the axes of \"" + definition + "\" (" + d.last_error() + ")");
  d.offset = {};
  try {
    d.offset = to_plane({geo.origin_lon, geo.origin_lat});
  } catch (const InputError&) {
    throw InputError("the origin (" + std::to_string(geo.origin_lon) + ", " + std::to_string(geo.origin_lat) +
                     ") is outside the domain of \"" + definition + "\"");
  }
}

GeoProjection::~GeoProjection() = default;

Vec2 GeoProjection::to_plane(LonLat p) const {
  const PJ_COORD out = proj_trans(impl_->transform, PJ_FWD, proj_coord(p.lon, p.lat, 0.0, 0.0));
  if (!std::isfinite(out.xy.x) || !std::isfinite(out.xy.y) || out.xy.x == HUGE_VAL)
    throw InputError("longitude " + std::to_string(p.lon) + ", latitude " + std::to_string(p.lat) +
                     " is outside the projection's domain");
  return Vec2{out.xy.x, out.xy.y} - impl_->offset;
}

LonLat GeoProjection::to_lonlat(Vec2 p) const {
  const Vec2 q = p + impl_->offset;
  const PJ_COORD out = proj_trans(impl_->transform, PJ_INV, proj_coord(q.x, q.y, 0.0, 0.0));
  if (!std::isfinite(out.lp.lam) || !std::isfinite(out.lp.phi) || out.lp.lam == HUGE_VAL) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return {nan, nan};
  }
  return {out.lp.lam, out.lp.phi};
}

}  // namespace floedem
