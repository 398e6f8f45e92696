#pragma once
// Forcing that changes in time: tidal current ellipses and wind or current time series
// (docs/forcing.md). Part of the engine-neutral scene: every engine is driven by the same
// values, evaluated here once (one implementation of each law).
#include <string>
#include <vector>

#include "floedem/geometry/vec2.hpp"
#include "floedem/scene/geo.hpp"

namespace floedem {

/// One tidal constituent as a current ellipse. With psi = 2 pi t / period - phase, the current
/// as a complex number u + i v is
///   U(t) = e^{i inclination} (major cos psi + i minor sin psi),
/// the standard ellipse parameters of tidal current analysis (semi-major and semi-minor axis,
/// the minor's sign giving the sense of rotation, inclination of the major axis from east, and
/// phase; Foreman 1978, Pugh 1987 ch. 4), t counted from the run's start.
struct TidalConstituent {
  std::string name;          ///< "M2", ..., or empty where the period was given
  double period = 0.0;       ///< s
  double major = 0.0;        ///< m/s
  double minor = 0.0;        ///< m/s, > 0 counter-clockwise
  double inclination = 0.0;  ///< rad, of the major axis from +x, counter-clockwise
  double phase = 0.0;        ///< rad
  Vec2 velocity(double t) const;
  Vec2 acceleration(double t) const;  ///< dU/dt
};

/// The period (s) of a standard constituent (M2, S2, N2, K2, K1, O1, P1, Q1), or 0 for a name
/// that is not one.
double tidal_period(const std::string& name);
/// The standard names, in the order tidal_period knows them.
const std::vector<std::string>& tidal_constituent_names();

/// The largest wind or current component (m/s) a record or grid may hold: far above any
/// sustained surface wind or ocean current on record, so that a misread value (a flipped byte,
/// a unit slip such as cm/s written as m/s) is refused rather than driven into a run.
inline constexpr double kMaxFlowComponent = 100.0;

/// A velocity (m/s) against time (s from the run's start), linear between its samples: a wind
/// or current record read from a CSV file (scenario.cpp checks that it covers the run).
struct VelocitySeries {
  std::string file;             ///< where it was read from, for messages and the output
  std::vector<double> time;     ///< s, increasing
  std::vector<Vec2> velocity;   ///< m/s
  bool empty() const { return time.empty(); }
  Vec2 at(double t) const;      ///< linear between samples; the end values past either end
  Vec2 slope(double t) const;   ///< dV/dt of the segment holding t (the later one at a sample)
};

/// A velocity field on a grid that varies in space and time, as a CF-NetCDF file holds it
/// (docs/forcing.md): its axes, read and checked when the scenario is loaded; the run reads
/// the values a time slice at a time.
struct FlowGridSpec {
  std::string file;            ///< the file, as found from the scenario's folder
  std::string u, v;            ///< its variables of the x (east) and y (north) components
  std::vector<double> x, y;    ///< m, the scene's axes, increasing
  std::vector<double> depth;   ///< m below the surface, increasing; empty: no depth axis
  std::vector<double> time;    ///< s from the run's start, increasing
  /// A grid on longitude and latitude (a geographic scene's; docs/geography.md): the file's own
  /// axes, deg, increasing. x and y are then a lattice of the scene's plane, `spacing` apart,
  /// onto which each time slice is resampled as it is read (its east and north components
  /// turned into the plane's axes), and `geo` the scene's projection.
  std::vector<double> lon, lat;
  double spacing = 0.0;  ///< m
  GeoSpec geo;
  bool empty() const { return file.empty(); }
  bool lonlat() const { return !lon.empty(); }
};

}  // namespace floedem
