#pragma once
// Geographic scenes (docs/geography.md): where the scene's plane lies on the earth. The plane
// is a map projection of the WGS 84 ellipsoid (by default the azimuthal equidistant projection
// about the scene's origin, which keeps distances from the origin true), shifted so that the
// origin is at (0, 0) m. Positions given in longitude and latitude are projected once, when
// the scenario is read; the Coriolis parameter follows each body's latitude; the output adds
// each body's longitude and latitude per frame.
#include <memory>
#include <string>

#include "floedem/geometry/vec2.hpp"

namespace floedem {

/// Earth's sidereal rotation rate, rad/s (docs/model.md 2).
inline constexpr double kEarthRotation = 7.2921e-5;
/// The Coriolis parameter f = 2 Omega sin(latitude) (1/s) at a latitude in degrees.
double coriolis_parameter(double latitude_deg);

/// [geo]: the scene's origin on the earth and its projection.
struct GeoSpec {
  bool present = false;
  double origin_lon = 0.0;  ///< deg east, [-180, 180]
  double origin_lat = 0.0;  ///< deg north, (-90, 90)
  /// The projection as given ("" for the default), and as used: a PROJ definition of a
  /// projected coordinate reference system in metres ("+proj=... +type=crs", "EPSG:3413", ...).
  std::string projection_given;
  std::string projection;
  /// The default: "+proj=aeqd +lat_0=LAT +lon_0=LON +datum=WGS84 +units=m +type=crs".
  static std::string default_projection(double lon, double lat);
};

/// Longitude and latitude, degrees (WGS 84).
struct LonLat {
  double lon = 0.0;
  double lat = 0.0;
};

/// The map between longitude and latitude and the scene's plane, through PROJ. Not safe to use
/// from two threads at once (each object owns its own PROJ context): give each thread its own.
class GeoProjection {
 public:
  /// Throws InputError (without a file name: the caller adds where the definition came from)
  /// for a definition PROJ cannot read, one that is not a projected CRS in metres, or an origin
  /// the projection cannot map.
  explicit GeoProjection(const GeoSpec& geo);
  ~GeoProjection();
  GeoProjection(const GeoProjection&) = delete;
  GeoProjection& operator=(const GeoProjection&) = delete;

  /// The point of the plane (m, origin at (0, 0)) at a longitude and latitude; throws
  /// InputError where the projection is not defined.
  Vec2 to_plane(LonLat p) const;
  /// The longitude and latitude of a point of the plane; NaN where the projection is not
  /// defined (a point beyond its domain).
  LonLat to_lonlat(Vec2 p) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace floedem
