#pragma once
// Reading the scenario's forcing that changes in time (docs/forcing.md): [run] start,
// [[environment.tide]], [environment.current_file] and [environment.wind_file].
#include <string>

#include "floedem/scene/scene.hpp"
#include "scenario/table_reader.hpp"

namespace floedem {

/// "YYYY-MM-DDTHH:MM:SS[.fff]Z" (or "+00:00") as s since 1970-01-01T00:00:00Z; an InputError
/// through r for anything else (UTC only: a forecast's CF time axis is read against it).
double read_utc_instant(TableReader& r, std::string_view key);

/// The [[environment.tide]] tables of `env_reader` into scene.environment.tides.
void read_tides(TableReader& env_reader, Scene& scene);

/// The table `key` ("current_file" or "wind_file") of `env_reader`, when present, read into
/// `series`: a CSV file with a column `time` (s from the run's start) and the velocity's x and
/// y columns (named by the table's u and v, default "u" and "v"), covering [0, run.duration];
/// or into `grid`, a CF-NetCDF file's axes (io/netcdf_grid.hpp). Returns whether the table
/// was there; the file read is added to scene.input_files.
bool read_velocity_file(TableReader& env_reader, std::string_view key, Scene& scene, VelocitySeries& series,
                        FlowGridSpec& grid);

/// The plane's lattice of each grid on longitude and latitude (FlowGridSpec::lonlat): InputError
/// when the grid does not hold every moving body's outline at t = 0; otherwise x and y become
/// a lattice over the part of the grid within 200 km of the bodies, at half the grid's finest
/// spacing (at most a million nodes a level), which each time slice is resampled onto.
void place_lonlat_grids(Scene& scene);

/// InputError when a grid of the scene does not hold every body's outline at t = 0.
void check_grid_coverage(const Scene& scene);

}  // namespace floedem
