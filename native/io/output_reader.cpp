#include "io/output_reader.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "floedem/scene/input_error.hpp"
#include "geometry/polygon.hpp"
#include "io/h5_read.hpp"
#include "io/recorder.hpp"

namespace floedem {

namespace {

/// Opens a file given by the user; InputError when it is missing or not HDF5.
H5::H5File open_input(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path + ": cannot open: no such file");
  if (H5Fis_hdf5(path.c_str()) <= 0) throw InputError(path + ": not an HDF5 file (floedem's runs and fields are)");
  return H5::H5File(path, H5F_ACC_RDONLY);
}

/// Runs a reader, turning what HDF5 throws into an InputError naming the file and the step.
template <class F>
auto guarded(const std::string& label, F&& read) {
  H5::Exception::dontPrint();
  try {
    return read();
  } catch (const H5::Exception& e) {
    throw InputError(label + ": cannot read it (" + e.getFuncName() + ": " + e.getDetailMsg() +
                     "); damaged, or not a floedem file?");
  }
}

}  // namespace

BodyFrame read_body_frame(H5::H5File& file, const std::string& label, std::int64_t frame) {
  return guarded(label, [&] {
    const CheckedFile f(file, label);
    f.check_format_version();
    const std::string status = f.text_attribute("status", true);
    if (status != "complete")
      f.fail("/@status", "is '" + status + "'; allowed only 'complete' (the run that wrote it did not finish)");
    std::vector<hsize_t> dims;
    const auto offsets = f.integers("/bodies/polygon_offsets", {-1}, dims);
    if (offsets.empty()) f.fail("/bodies/polygon_offsets", "is empty; expected one entry per body and one more");
    const std::size_t n = offsets.size() - 1;
    const auto vertices = f.reals("/bodies/polygon_vertices", {-1, 2}, dims);
    const auto vertex_count = static_cast<std::int64_t>(dims[0]);
    if (offsets[0] != 0) f.fail("/bodies/polygon_offsets", "starts at " + std::to_string(offsets[0]) + "; expected 0");
    for (std::size_t i = 0; i < n; ++i)
      if (!(offsets[i + 1] >= offsets[i] + 3 && offsets[i + 1] <= vertex_count))
        f.fail("/bodies/polygon_offsets", "entry " + std::to_string(i + 1) + " is " + std::to_string(offsets[i + 1]) +
                                              " after " + std::to_string(offsets[i]) +
                                              "; expected offsets rising by at least 3 (vertices of a polygon) up to " +
                                              std::to_string(vertex_count) + " (the rows of /bodies/polygon_vertices)");
    if (offsets[n] != vertex_count)
      f.fail("/bodies/polygon_offsets", "ends at " + std::to_string(offsets[n]) + "; expected " +
                                            std::to_string(vertex_count) + " (the rows of /bodies/polygon_vertices)");
    const auto nn = static_cast<std::int64_t>(n);
    BodyFrame out;
    out.names = f.strings("/bodies/name", nn);
    out.thickness = f.reals("/bodies/thickness", {nn}, dims);
    out.density = f.reals("/bodies/density", {nn}, dims);
    for (std::size_t i = 0; i < n; ++i) {
      // The ranges of a [[body]]'s thickness and density keys: both > 0.
      if (!(out.thickness[i] > 0.0))
        f.fail("/bodies/thickness", "body " + std::to_string(i) + " has " + setting_text(out.thickness[i]) + " m; allowed > 0");
      if (!(out.density[i] > 0.0))
        f.fail("/bodies/density", "body " + std::to_string(i) + " has " + setting_text(out.density[i]) + " kg/m^3; allowed > 0");
    }
    const auto fixed = f.integers("/bodies/fixed", {nn}, dims);
    for (std::size_t i = 0; i < n; ++i) {
      if (fixed[i] != 0 && fixed[i] != 1)
        f.fail("/bodies/fixed", "body " + std::to_string(i) + " has " + std::to_string(fixed[i]) + "; allowed 0 or 1");
      out.fixed.push_back(static_cast<std::uint8_t>(fixed[i]));
    }
    const auto times = f.reals("/time", {-1}, dims);
    const auto frames = static_cast<std::int64_t>(times.size());
    if (frames == 0) f.fail("/time", "has no frames; expected at least one");
    const std::int64_t k = frame < 0 ? frames + frame : frame;
    if (k < 0 || k >= frames)
      throw InputError(label + ": frame " + std::to_string(frame) + " is out of range; the file has " +
                       std::to_string(frames) + " frames (allowed 0 to " + std::to_string(frames - 1) + ", or -1 to -" +
                       std::to_string(frames) + " from the end)");
    out.frame = k;
    out.time = times[static_cast<std::size_t>(k)];
    const auto row = static_cast<hsize_t>(k);
    const auto pos = f.real_row("/bodies/position", {frames, nn, 2}, row);
    const auto ang = f.real_row("/bodies/angle", {frames, nn}, row);
    const auto vel = f.real_row("/bodies/velocity", {frames, nn, 2}, row);
    out.angular_velocity = f.real_row("/bodies/angular_velocity", {frames, nn}, row);
    for (std::size_t i = 0; i < n; ++i) {
      const Transform x{{pos[2 * i], pos[2 * i + 1]}, Rot::from_angle(ang[i])};
      std::vector<Vec2> poly;
      for (auto v = offsets[i]; v < offsets[i + 1]; ++v)
        poly.push_back(x.apply({vertices[2 * static_cast<std::size_t>(v)], vertices[2 * static_cast<std::size_t>(v) + 1]}));
      // The outline at the frame passes the checks of a scenario's polygon; the recorder writes
      // it counter-clockwise, and a clockwise one is turned round as the scenario loader does.
      if (const auto problem = polygon_problem(poly))
        f.fail("/bodies/polygon_vertices", "body " + std::to_string(i) + " at frame " + std::to_string(k) + " " + *problem);
      if (signed_area(poly) < 0.0) std::reverse(poly.begin(), poly.end());
      out.polygons.push_back(std::move(poly));
      out.velocity.push_back({vel[2 * i], vel[2 * i + 1]});
    }
    return out;
  });
}

BodyFrame read_body_frame(const std::string& path, std::int64_t frame) {
  return guarded(path, [&] {
    H5::H5File file = open_input(path);
    return read_body_frame(file, path, frame);
  });
}

StoredRun read_stored_run(H5::H5File& file, const std::string& label) {
  return guarded(label, [&] {
    const CheckedFile f(file, label);
    StoredRun run;
    run.engine = f.text_attribute("engine", false);
    run.scenario = f.text_attribute("scenario", false);
    if (run.engine.empty() || run.scenario.empty() || !f.exists("/bodies/mass"))
      throw InputError(label + ": not a floedem run's output (no engine, scenario or /bodies/mass)");
    f.check_format_version();
    run.status = f.text_attribute("status", true);
    if (run.status != "running" && run.status != "complete")
      f.fail("/@status", "is '" + run.status + "'; expected 'running' or 'complete'");
    run.floedem_version = f.text_attribute("floedem_version", false);
    run.scenario_path = f.text_attribute("scenario_path", false);
    run.duration = f.real_attribute("/", "duration");
    if (!(run.duration > 0.0)) f.fail("/@duration", "is " + setting_text(run.duration) + " s; allowed > 0 (run.duration)");
    const std::string overrides = f.text_attribute("overrides", false);
    for (std::size_t at = 0; at < overrides.size();) {
      const std::size_t end = std::min(overrides.find('\n', at), overrides.size());
      if (end > at) run.overrides.push_back(overrides.substr(at, end - at));
      at = end + 1;
    }
    if (f.exists("/inputs")) {
      H5::Group inputs = file.openGroup("/inputs");
      for (int k = 0; k < inputs.getNumAttrs(); ++k) {
        const std::string name = inputs.openAttribute(static_cast<unsigned>(k)).getName();
        run.inputs[name] = f.text_attribute("/inputs", name);
      }
    }
    std::vector<hsize_t> dims;
    run.mass = f.reals("/bodies/mass", {-1}, dims);
    for (std::size_t i = 0; i < run.mass.size(); ++i)
      if (!(run.mass[i] > 0.0))
        f.fail("/bodies/mass", "body " + std::to_string(i) + " has " + setting_text(run.mass[i]) + " kg; allowed > 0");
    for (const char* name : kCheckpointSlots) {
      if (!f.exists(name)) continue;
      StoredCheckpoint c;
      // A slot cut short by a kill (attributes missing, bytes or step not matching the checksum)
      // is counted, not refused: the other slot, or a run from the start, continues the run.
      H5::DataSet slot = file.openDataSet(name);
      if (!slot.attrExists("step") || !slot.attrExists("checksum")) {
        ++run.damaged_slots;
        continue;
      }
      c.step = f.integer_attribute(name, "step");
      const std::uint64_t checksum = f.unsigned_attribute(name, "checksum");
      c.state = f.bytes(name, {-1});
      if (c.step < 0 || slot_checksum(c.step, c.state) != checksum) {
        ++run.damaged_slots;
        continue;
      }
      if (!run.checkpoint || c.step > run.checkpoint->step) run.checkpoint = std::move(c);
    }
    return run;
  });
}

StoredRun read_stored_run(const std::string& path) {
  return guarded(path, [&] {
    if (!std::filesystem::exists(path)) throw InputError(path + ": no such file");
    H5::H5File file = open_input(path);
    return read_stored_run(file, path);
  });
}

}  // namespace floedem
