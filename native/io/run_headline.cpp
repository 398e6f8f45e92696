#include "floedem/io/run_headline.hpp"

#include <H5Cpp.h>

#include <cmath>
#include <cstdio>

#include "io/h5_read.hpp"
#include "floedem/scene/input_error.hpp"

namespace floedem {
namespace {

std::string name_of(const std::vector<std::string>& names, std::int64_t k) {
  return k >= 0 && static_cast<std::size_t>(k) < names.size() ? names[static_cast<std::size_t>(k)]
                                                               : "body " + std::to_string(k);
}

/// Row weights of a table whose row i holds the mean over (time[i-1], time[i]] (row -1 at
/// `first_start`): each row's span when it starts at or after `from`, else 0. Their sum is 0 when
/// no row lies wholly in the window (a run shorter than two rows).
std::vector<double> window_weights(const std::vector<double>& time, double first_start, double from) {
  std::vector<double> w(time.size(), 0.0);
  for (std::size_t i = 0; i < time.size(); ++i) {
    const double start = i == 0 ? first_start : time[i - 1];
    if (start >= from && time[i] > start) w[i] = time[i] - start;
  }
  return w;
}

/// The weighted mean of the rows of a [rows, columns, 2] table, column `c`; NaN rows skipped.
Vec2 weighted_mean(const std::vector<double>& values, std::size_t columns, std::size_t c, const std::vector<double>& w) {
  Vec2 sum;
  double total = 0.0;
  for (std::size_t i = 0; i < w.size(); ++i) {
    const double x = values[2 * (i * columns + c)], y = values[2 * (i * columns + c) + 1];
    if (w[i] <= 0.0 || !std::isfinite(x) || !std::isfinite(y)) continue;
    sum += w[i] * Vec2{x, y};
    total += w[i];
  }
  return total > 0.0 ? (1.0 / total) * sum : Vec2{std::nan(""), std::nan("")};
}

std::string force_text(Vec2 f) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "%.4g N (x %.4g, y %.4g)", length(f), f.x, f.y);
  return buf;
}

/// The root's attribute `name` (NaN when absent).
double root_number(H5::H5File& f, const std::string& name) {
  if (!f.attrExists(name)) return std::nan("");
  double v = 0.0;
  H5::Attribute a = f.openAttribute(name);
  a.read(H5::PredType::NATIVE_DOUBLE, &v);
  return v;
}

}  // namespace

std::vector<std::pair<std::string, double>> TowOutcome::attributes() const {
  return {{"tow_direction_x", direction.x},
          {"tow_direction_y", direction.y},
          {"tow_distance", distance},
          {"tow_cross_track", cross_track},
          {"tow_speed_made_good", speed_made_good},
          {"tow_stall_speed", stall_speed},
          {"tow_stalled_time", stalled_time},
          {"tow_parted", parted ? 1.0 : 0.0},
          {"tow_parted_at", parted_at},
          {"tow_tension_max", tension_max},
          {"tow_tension_p99", tension_p99}};
}

RunHeadline read_run_headline(const std::string& path) {
  H5::Exception::dontPrint();
  std::string step = "open the file";
  try {
    H5::H5File f(path, H5F_ACC_RDONLY);
    RunHeadline h;
    std::vector<hsize_t> dims;
    step = "read /time";
    const auto frames = read_all<double>(f, "/time", H5::PredType::NATIVE_DOUBLE, dims);
    h.window_end = frames.empty() ? 0.0 : frames.back();
    h.window_start = 0.5 * h.window_end;
    step = "read /bodies/name";
    const std::vector<std::string> names = read_strings(f, "/bodies/name");

    if (f.nameExists("/tow")) {
      step = "read /tow";
      const auto time = read_all<double>(f, "/tow/time", H5::PredType::NATIVE_DOUBLE, dims);
      const auto force = read_all<double>(f, "/tow/force_mean", H5::PredType::NATIVE_DOUBLE, dims);
      const auto ice = read_all<double>(f, "/tow/ice_force_mean", H5::PredType::NATIVE_DOUBLE, dims);
      if (force.size() != 2 * time.size() || ice.size() != 2 * time.size())
        throw InputError(path + ": /tow/force_mean and /tow/ice_force_mean must be [" + std::to_string(time.size()) +
                         ", 2], as /tow/time has " + std::to_string(time.size()) + " rows");
      // Row 0 is t = 0 (no step yet): every later row is the mean since the row before.
      const std::vector<double> w = window_weights(time, time.empty() ? 0.0 : time[0], h.window_start);
      std::string body;
      H5::Group tow = f.openGroup("/tow");
      if (tow.attrExists("body")) {
        H5::Attribute a = tow.openAttribute("body");
        a.read(a.getStrType(), body);
      }
      h.tow = RunHeadline::Tow{body, weighted_mean(force, 1, 0, w), weighted_mean(ice, 1, 0, w)};
      step = "read the summary's tow outcome";
      if (f.attrExists("summary_tow_distance")) {
        TowOutcome o;
        o.direction = {root_number(f, "summary_tow_direction_x"), root_number(f, "summary_tow_direction_y")};
        o.distance = root_number(f, "summary_tow_distance");
        o.cross_track = root_number(f, "summary_tow_cross_track");
        o.speed_made_good = root_number(f, "summary_tow_speed_made_good");
        o.stall_speed = root_number(f, "summary_tow_stall_speed");
        o.stalled_time = root_number(f, "summary_tow_stalled_time");
        o.parted = root_number(f, "summary_tow_parted") == 1.0;
        o.parted_at = root_number(f, "summary_tow_parted_at");
        o.tension_max = root_number(f, "summary_tow_tension_max");
        o.tension_p99 = root_number(f, "summary_tow_tension_p99");
        h.tow_outcome = o;
      }
    }
    if (f.nameExists("/loads")) {
      step = "read /loads";
      const auto bodies = read_all<std::int64_t>(f, "/loads/body", H5::PredType::NATIVE_INT64, dims);
      const auto time = read_all<double>(f, "/loads/time", H5::PredType::NATIVE_DOUBLE, dims);
      const auto force = read_all<double>(f, "/loads/force", H5::PredType::NATIVE_DOUBLE, dims);
      if (force.size() != 2 * time.size() * bodies.size())
        throw InputError(path + ": /loads/force must be [" + std::to_string(time.size()) + ", " +
                         std::to_string(bodies.size()) + ", 2], as /loads/time and /loads/body have");
      const std::vector<double> w = window_weights(time, 0.0, h.window_start);  // row 0: since t = 0
      for (std::size_t c = 0; c < bodies.size(); ++c)
        h.loads.push_back({name_of(names, bodies[c]), weighted_mean(force, bodies.size(), c, w)});
    }
    step = "read /contacts/collisions";
    if (f.nameExists("/contacts/collisions")) {
      const auto peak = read_all<double>(f, "/contacts/collisions/peak_force", H5::PredType::NATIVE_DOUBLE, dims);
      const auto time = read_all<double>(f, "/contacts/collisions/time", H5::PredType::NATIVE_DOUBLE, dims);
      const auto a = read_all<std::int64_t>(f, "/contacts/collisions/body_a", H5::PredType::NATIVE_INT64, dims);
      const auto b = read_all<std::int64_t>(f, "/contacts/collisions/body_b", H5::PredType::NATIVE_INT64, dims);
      if (time.size() != peak.size() || a.size() != peak.size() || b.size() != peak.size())
        throw InputError(path + ": /contacts/collisions: peak_force, time, body_a and body_b differ in length");
      std::size_t best = peak.size();
      for (std::size_t i = 0; i < peak.size(); ++i)
        if (std::isfinite(peak[i]) && (best == peak.size() || peak[i] > peak[best])) best = i;
      if (best < peak.size())
        h.largest_collision = RunHeadline::Collision{peak[best], time[best], name_of(names, a[best]), name_of(names, b[best])};
    }
    return h;
  } catch (const H5::Exception& e) {
    throw InputError(path + ": cannot " + step + " (" + e.getDetailMsg() + "); not a floedem HDF5 file?");
  }
}

std::string format_run_headline(const RunHeadline& h) {
  std::string out;
  char window[96];
  std::snprintf(window, sizeof window, "mean over t = %.6g to %.6g s", h.window_start, h.window_end);
  if (h.tow) {
    out += "  towing      " + std::string(window) + " (" + h.tow->body + "): force " + force_text(h.tow->force) + "\n";
    out += "              of which ice " + force_text(h.tow->ice_force) + "\n";
  }
  if (h.tow_outcome) {
    const TowOutcome& o = *h.tow_outcome;
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "  made good   %.4g m/s: %.6g m along (%.3g, %.3g), %.6g m across; stalled %.6g s (below %.3g m/s)\n",
                  o.speed_made_good, o.distance, o.direction.x, o.direction.y, o.cross_track, o.stalled_time,
                  o.stall_speed);
    out += buf;
    if (o.tension_max > 0.0 || o.parted) {
      std::snprintf(buf, sizeof buf, "  rope        tension %.4g N largest, %.4g N p99; %s\n", o.tension_max,
                    o.tension_p99, o.parted ? "parted" : "held");
      out += buf;
      if (o.parted) {
        out.pop_back();
        std::snprintf(buf, sizeof buf, " at t = %.6g s\n", o.parted_at);
        out += buf;
      }
    }
  }
  for (const RunHeadline::Load& l : h.loads)
    out += "  load        " + l.body + ", " + window + ": " + force_text(l.force) + "\n";
  if (h.largest_collision) {
    char buf[256];
    std::snprintf(buf, sizeof buf, "  peak force  %.4g N, the largest of any collision: %s and %s at t = %.6g s\n",
                  h.largest_collision->peak_force, h.largest_collision->body_a.c_str(),
                  h.largest_collision->body_b.c_str(), h.largest_collision->time);
    out += buf;
  }
  return out;
}

}  // namespace floedem
