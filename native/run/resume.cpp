#include "floedem/run/resume.hpp"

#include <cstdio>
#include <cstring>
#include <filesystem>

#include "io/output_lock.hpp"
#include "io/recorder.hpp"
#include "floedem/scenario/scenario.hpp"
#include "floedem/scene/input_error.hpp"
#include "floedem/version.hpp"

namespace floedem {

namespace {

constexpr const char* kPartial = ".partial";

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t");
  const auto b = s.find_last_not_of(" \t");
  return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

std::string override_key(const std::string& o) { return trim(o.substr(0, o.find('='))); }

}  // namespace

ResumeResult resume_run(const std::string& path, const std::vector<std::string>& overrides, bool progress,
                        const std::atomic<bool>* stop) {
  namespace fs = std::filesystem;
  // The run's final name, and the file that holds it now: a run under way or killed is
  // RESULT.h5.partial (the newer one when both are there), a finished run RESULT.h5.
  std::string final_path = path;
  if (final_path.size() > std::strlen(kPartial) &&
      final_path.compare(final_path.size() - std::strlen(kPartial), std::string::npos, kPartial) == 0)
    final_path.resize(final_path.size() - std::strlen(kPartial));
  const std::string partial = final_path + kPartial;
  const std::string stored = fs::exists(partial) ? partial : final_path;
  if (!fs::exists(stored)) throw InputError(path + ": no such run output (nor " + partial + ")");

  for (const std::string& o : overrides)
    if (override_key(o) != "run.duration")
      throw InputError("--resume " + path + ": --set " + o +
                       ": only run.duration may be set when a run is continued (anything else would make another run)");
  // A run still writing the file holds its lock (io/output_lock.hpp): say so, rather than that
  // the file cannot be read (HDF5 refuses to open a file another process has open for writing).
  { const OutputLock probe(final_path); }
  const StoredRun run = read_stored_run(stored);
  std::vector<std::string> merged;
  for (const std::string& o : run.overrides)
    if (overrides.empty() || override_key(o) != "run.duration") merged.push_back(o);
  merged.insert(merged.end(), overrides.begin(), overrides.end());
  // The scene as the run had it, from the text in the file; files it reads (a field) are
  // found from the scenario's path as written, and must not have changed.
  ResumeResult result;
  result.scene = parse_scenario(run.scenario, run.scenario_path, merged);
  const Scene& scene = result.scene;
  bool same_bodies = scene.bodies.size() == run.mass.size();
  for (std::size_t i = 0; same_bodies && i < run.mass.size(); ++i) same_bodies = scene.bodies[i].mass == run.mass[i];
  if (!same_bodies)
    throw InputError(stored + ": its scenario (" + run.scenario_path +
                     ") no longer gives the run's bodies: has a file it reads (a field) changed?");
  // Every file the run read (forcing files, a field, a chart) must be as it was: a changed one
  // would continue another run under this one's name. (A file written before floedem recorded
  // its inputs has no /inputs: nothing to hold it to.)
  for (const InputFile& f : scene.input_files) {
    if (run.inputs.empty()) break;
    const auto it = run.inputs.find(f.key);
    if (it == run.inputs.end())
      throw InputError(stored + ": " + f.key + " (" + f.path + ") was not read by the run; the scenario has changed");
    if (it->second != f.text())
      throw InputError(input_message(f.path, 0, f.key,
                                     "has changed since the run read it (the run recorded " + it->second + "; now " +
                                         f.text() + "): restore it, or start the run afresh"));
  }

  if (run.status == "complete" && stored == final_path && scene.run.duration == run.duration) {
    result.message = final_path + ": the run is complete (" + setting_text(run.duration) +
                     " s); nothing to continue (a longer run: --set run.duration=T)";
    return result;
  }
  if (run.floedem_version != version())
    std::fprintf(stderr,
                 "floedem: warning: %s was written by floedem %s, this is %s: the continuation is exact only with "
                 "the same build\n",
                 stored.c_str(), run.floedem_version.c_str(), version());

  RunOptions options;
  options.engine = run.engine;
  options.output = final_path;
  result.summary_output = final_path;
  options.progress = progress;
  options.stop = stop;
  if (run.checkpoint) {
    options.resume_state = &run.checkpoint->state;
    result.message =
        "continued from the checkpoint at t = " + setting_text(static_cast<double>(run.checkpoint->step) * scene.run.dt) + " s";
  } else {
    // No checkpoint: the run is made again from the start, which gives the same file.
    std::string why = run.damaged_slots > 0 ? "its checkpoint was cut short"
                      : run.engine != "native" ? "the " + run.engine + " engine cannot save its state"
                                               : "it stopped before its first checkpoint";
    result.message = "no checkpoint to continue from (" + why + "): run again from t = 0";
  }
  try {
    result.summary = run_scene(scene, options);
  } catch (const StateError& e) {
    throw InputError(stored + ": " + e.what());
  }
  result.ran = true;
  return result;
}

}  // namespace floedem
