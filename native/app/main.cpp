// floedem command line. Exit codes: 0 done; 1 unexpected error; 2 bad input (scenario,
// options, engine settings); 3 output could not be written; 4 the solver failed (report: a run
// failed); 5 report: the engines disagree beyond the documented tolerances; 128 + N a run
// stopped by signal N (143 SIGTERM, 130 SIGINT) after writing a checkpoint of its last step.
#include <CLI/CLI.hpp>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <algorithm>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <iostream>

#include "app/bench_command.hpp"
#include "app/field_command.hpp"
#include "app/python_script.hpp"
#include "floedem/engine/registry.hpp"
#include "floedem/engine/step_stages.hpp"
#include "io/recorder.hpp"
#include "floedem/run/resume.hpp"
#include "floedem/run/simulation.hpp"
#include "floedem/scenario/scenario.hpp"
#include "floedem/scene/input_error.hpp"
#include "floedem/version.hpp"

namespace {

// A run stops at the end of its step on SIGTERM (the notice a batch system gives before it
// kills a job: Slurm's at the time limit or on preemption) or SIGINT (Ctrl-C) and writes a
// checkpoint of that step first (RunOptions::stop). The handler only sets the flag; it resets
// itself, so a second signal kills at once.
std::atomic<bool> stop_requested{false};
volatile std::sig_atomic_t stop_signal = 0;
static_assert(std::atomic<bool>::is_always_lock_free, "set from a signal handler");

extern "C" void request_stop(int signal) {
  stop_signal = signal;
  stop_requested.store(true, std::memory_order_relaxed);
}

void stop_on_signals() {
  struct sigaction action {};
  action.sa_handler = request_stop;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND;
  sigaction(SIGTERM, &action, nullptr);
  sigaction(SIGINT, &action, nullptr);
}

std::string default_output(const std::string& scenario, const std::string& engine) {
  return std::filesystem::path(scenario).stem().string() + "." + engine + ".h5";
}

int run_command(const std::string& scenario_path, const std::string& engine, std::string output,
                const std::vector<std::string>& overrides, bool quiet) {
  using namespace floedem;
  const Scene scene = load_scenario(scenario_path, overrides);
  if (output.empty()) output = default_output(scenario_path, engine);
  RunOptions options;
  options.engine = engine;
  options.output = output;
  options.progress = !quiet;
  options.stop = &stop_requested;
  stop_on_signals();
  const RunSummary summary = run_scene(scene, options);
  if (!quiet) std::cout << format_summary(scene, summary, output);
  return 0;
}

int resume_command(const std::string& path, const std::vector<std::string>& overrides, bool quiet) {
  using namespace floedem;
  stop_on_signals();
  const ResumeResult r = resume_run(path, overrides, !quiet, &stop_requested);
  if (!r.ran) {
    if (!quiet) std::cout << r.message << "\n";
    return 0;
  }
  if (!quiet) std::cout << "floedem run --resume: " << r.message << "\n" << format_summary(r.scene, r.summary, r.summary_output);
  return 0;
}

// `floedem run`: a scenario on one engine, or a killed run resumed.
struct RunCommand {
  std::string scenario, engine = "native", output, resume;
  std::vector<std::string> overrides;
  bool quiet = false;
  CLI::App* app = nullptr;

  void add(CLI::App& parent) {
    app = parent.add_subcommand("run", "run a scenario on one engine and write its HDF5 output");
    CLI::Option* scenario_option =
        app->add_option("scenario", scenario, "scenario file (TOML), see scenarios/README.md");
    std::string engine_names;
    for (const auto& e : floedem::engines()) engine_names += (engine_names.empty() ? "" : "|") + e.name;
    app->add_option("--engine,-e", engine, "engine: " + engine_names)->capture_default_str();
    app->add_option("--out,-o", output, "output file (default: SCENARIO_STEM.ENGINE.h5 in the current directory)");
    app->add_option("--set,-s", overrides,
                    "override a scalar of the scenario, KEY=VALUE (e.g. run.duration=60, body[2].density=917); repeatable")
        ->allow_extra_args(false);
    app->add_flag("--quiet,-q", quiet, "no progress line and no summary");
    CLI::Option* resume_option = app->add_option(
        "--resume", resume,
        "continue the run in RESULT.h5 (or RESULT.h5.partial, a run killed) from its last checkpoint, to the end of "
        "its run.duration or of a longer one given with --set run.duration=T; the file ends as an uninterrupted "
        "run's would (native engine; other engines run again from t = 0)");
    resume_option->excludes(scenario_option);
    app->get_option("--out")->excludes(resume_option);
    app->get_option("--engine")->excludes(resume_option);
    scenario_option->excludes(resume_option);
    app->callback([this] {
      if (scenario.empty() && resume.empty()) throw CLI::RequiredError("a scenario file, or --resume RESULT.h5,");
    });
  }
  int run() const {
    if (!resume.empty()) return resume_command(resume, overrides, quiet);
    return run_command(scenario, engine, output, overrides, quiet);
  }
};

// `floedem report`: the cross-engine report (reports/report.py).
struct ReportCommand {
  std::string out = "results/report", only;
  bool quick = false, resume = false;
  int jobs = 0;
  CLI::App* app = nullptr;

  void add(CLI::App& parent) {
    app = parent.add_subcommand(
        "report", "run the scenario suite on every engine and write DIR/REPORT.md with its figures (reports/report.py)");
    app->add_option("--out,-o", out, "report directory (its fig/ and runs/ are replaced)")->capture_default_str();
    app->add_flag("--quick", quick,
                  "the same sections on smaller, shorter cases (the CI cross-check; a few minutes on 2 cores)");
    app->add_option("--only", only,
                    "a partial report of these sections alone, comma-separated (report.py names them; an unknown one "
                    "is refused with the list)");
    app->add_option("--jobs,-j", jobs, "runs at a time (default: the number of cores)")->check(CLI::PositiveNumber);
    app->add_flag("--resume", resume,
                  "keep the runs an interrupted report into the same --out finished with the same program, command "
                  "and scenario inputs; make the rest");
  }
  int run() const {
    // Exit status as the script's: 0 agreement, 5 disagreement, 4 a run failed.
    std::vector<std::string> args{"--floedem", floedem::own_executable(), "--out", out};
    if (quick) args.emplace_back("--quick");
    if (resume) args.emplace_back("--resume");
    if (jobs > 0) args.insert(args.end(), {"--jobs", std::to_string(jobs)});
    if (!only.empty()) args.insert(args.end(), {"--only", only});
    const int status = floedem::run_python_script("report.py", args);
    return status < 0 ? 1 : status;
  }
};

/// `floedem check`'s lines for a field from an ice chart: each polygon's codes, what they gave
/// the generator and what it made (the /field provenance the output will hold).
void print_chart(const floedem::Scene& scene) {
  auto number = [](const floedem::Provenance& p, const std::string& key) {
    for (const auto& [k, v] : p.numbers)
      if (k == key) return v;
    return 0.0;
  };
  auto text = [](const floedem::Provenance& p, const std::string& key) {
    for (const auto& [k, v] : p.text)
      if (k == key) return v;
    return std::string();
  };
  for (const floedem::Provenance& p : scene.provenance) {
    if (p.group == "/field" && !text(p, "chart").empty())
      std::cout << "  chart " << text(p, "chart") << ", layer '" << text(p, "layer") << "': " << number(p, "polygons")
                << " polygons, " << number(p, "floes") << " floes, concentration " << number(p, "concentration_achieved")
                << " of the free area in the field's rectangle\n";
    if (!p.group.starts_with("/field/chart_feature_")) continue;
    std::cout << "    feature " << number(p, "fid") << ": CT " << number(p, "CT") << " (C " << number(p, "concentration") << ")";
    if (number(p, "floes") > 0.0 || number(p, "concentration") > 0.0)
      std::cout << ", SA " << number(p, "SA") << " (" << number(p, "thickness_min") << " to " << number(p, "thickness_max")
                << " m), FA " << number(p, "FA") << " (" << number(p, "d_min") << " to " << number(p, "d_max_used") << " m)";
    std::cout << "; " << number(p, "area") << " m^2 in the rectangle, " << number(p, "floes") << " floes, C "
              << number(p, "concentration_achieved") << " of its free area";
    if (number(p, "pieces_too_small") > 0.0) std::cout << ", " << number(p, "pieces_too_small") << " pieces too small for a floe";
    std::cout << "\n";
  }
}

// `floedem check`: the scenario loaded, overrides applied and each engine built, as a run would,
// and nothing run (a sweep checks every point with it before it starts).
struct CheckCommand {
  std::string scenario;
  std::vector<std::string> overrides, engines;
  CLI::App* app = nullptr;

  void add(CLI::App& parent) {
    app = parent.add_subcommand("check",
                                "check a scenario with its overrides on engines, as a run would, without running it "
                                "(exit 2 and one line when it is refused)");
    app->add_option("scenario", scenario, "scenario file (TOML)")->required();
    app->add_option("--set,-s", overrides, "override a scalar of the scenario, KEY=VALUE; repeatable")
        ->allow_extra_args(false);
    app->add_option("--engine,-e", engines, "an engine to build the scene on; repeatable (default native)")
        ->allow_extra_args(false);
  }
  int run() {
    const floedem::Scene scene = floedem::load_scenario(scenario, overrides);
    if (engines.empty()) engines.emplace_back("native");
    // Each engine built, and the forcing read where the bodies start, as a run's first step
    // reads it: a grid's fill value or edge under a body is refused here too.
    floedem::check_scene(scene, engines);
    std::cout << scenario << ": ok (" << scene.bodies.size() << " bodies, " << scene.run.steps() << " steps)\n";
    // The forcing that changes in time, and how much of the run each record covers (a record
    // that did not cover it was refused above).
    const floedem::EnvironmentSpec& env = scene.environment;
    for (const auto& [what, series] : {std::pair{"current", &env.current_series}, std::pair{"wind", &env.wind_series}})
      if (!series->empty())
        std::cout << "  " << what << " record " << series->file << ": " << series->time.size() << " samples over ["
                  << series->time.front() << ", " << series->time.back() << "] s, the run [0, " << scene.run.duration
                  << "] s\n";
    for (const auto& [what, grid] : {std::pair{"current", &env.current_grid}, std::pair{"wind", &env.wind_grid}})
      if (!grid->empty())
        std::cout << "  " << what << " grid " << grid->file << ": " << grid->u << ", " << grid->v << " on x ["
                  << grid->x.front() << ", " << grid->x.back() << "] m (" << grid->x.size() << "), y [" << grid->y.front()
                  << ", " << grid->y.back() << "] m (" << grid->y.size() << ")"
                  << (grid->lonlat() ? " of the plane, resampled every " + std::to_string(grid->spacing) +
                                           " m from longitude [" + std::to_string(grid->lon.front()) + ", " +
                                           std::to_string(grid->lon.back()) + "], latitude [" +
                                           std::to_string(grid->lat.front()) + ", " + std::to_string(grid->lat.back()) + "]"
                                     : std::string())
                  << (grid->depth.empty() ? std::string() : ", " + std::to_string(grid->depth.size()) + " depths")
                  << ", " << grid->time.size() << " times over [" << grid->time.front() << ", " << grid->time.back()
                  << "] s, the run [0, " << scene.run.duration << "] s\n";
    if (scene.geo.present) {
      // Where the bodies lie on the earth: their centroids' extent in longitude and latitude.
      const floedem::GeoProjection projection(scene.geo);
      double lon[2] = {1e9, -1e9}, lat[2] = {1e9, -1e9};
      for (const floedem::BodySpec& b : scene.bodies) {
        const floedem::LonLat g = projection.to_lonlat(b.centroid);
        lon[0] = std::min(lon[0], g.lon), lon[1] = std::max(lon[1], g.lon);
        lat[0] = std::min(lat[0], g.lat), lat[1] = std::max(lat[1], g.lat);
      }
      std::cout << "  geo: origin " << scene.geo.origin_lon << " E, " << scene.geo.origin_lat << " N; projection \""
                << scene.geo.projection << "\"; bodies over longitude [" << lon[0] << ", " << lon[1] << "], latitude ["
                << lat[0] << ", " << lat[1] << "]" << (env.coriolis ? "; Coriolis at each body's latitude" : "") << "\n";
    }
    print_chart(scene);
    for (const floedem::TidalConstituent& c : env.tides)
      std::cout << "  tide " << (c.name.empty() ? "period " + std::to_string(c.period) + " s" : c.name) << ": major "
                << c.major << " m/s, minor " << c.minor << " m/s\n";
    return 0;
  }
};

// The Python package's commands (python/floedem): the command parses, the package does the work.
int python_status(const std::vector<std::string>& args) {
  const int status = floedem::run_python_module(args);
  return status < 0 ? 1 : status;
}

struct SweepCommand {
  std::string spec, out, profile;
  int jobs = 0;
  bool dry = false;
  CLI::App* app = nullptr;

  void add(CLI::App& parent) {
    app = parent.add_subcommand("sweep",
                                "run a sweep file's parameter points, seeds and engines through Snakemake, then reduce "
                                "them to one table (docs/sweeps.md)");
    app->add_option("spec", spec, "sweep file (TOML)")->required();
    app->add_option("--out,-o", out, "the sweep's directory (its runs, their summaries, the reduced table)")
        ->required();
    app->add_option("--jobs,-j", jobs, "cores for the runs at a time (default: the CPUs this process may use)")
        ->check(CLI::PositiveNumber);
    app->add_option("--profile", profile, "a Snakemake profile (a cluster: the repository's profiles/slurm)");
    app->add_flag("--dry-run,-n", dry, "check and plan, print what would run, run nothing");
  }
  int run() const {
    std::vector<std::string> args{"sweep", spec, "--out", out, "--floedem", floedem::own_executable()};
    if (jobs > 0) args.insert(args.end(), {"--jobs", std::to_string(jobs)});
    if (!profile.empty()) args.insert(args.end(), {"--profile", profile});
    if (dry) args.emplace_back("--dry-run");
    return python_status(args);
  }
};

struct ExportCommand {
  std::string run_file, out;
  bool xdmf = false, geojson = false;
  CLI::App* app = nullptr;

  void add(CLI::App& parent) {
    app = parent.add_subcommand("export",
                                "write a run beside it as XDMF for ParaView (RESULT.xdmf and RESULT.xdmf.h5) or, a "
                                "geographic scene's, as GeoJSON for QGIS (RESULT.geojson); the run's file is only read");
    app->add_option("run", run_file, "a run's output, RESULT.h5")->required();
    CLI::Option* x = app->add_flag("--xdmf", xdmf, "XDMF for ParaView");
    CLI::Option* g = app->add_flag("--geojson", geojson,
                                   "GeoJSON: each body's track and its last frame's polygon in longitude and latitude");
    x->excludes(g);
    app->require_option(1, 0);
    app->add_option("--out,-o", out, "the file (default: RESULT.xdmf or RESULT.geojson beside the run)");
  }
  int run() const {
    if (!xdmf && !geojson) throw CLI::RequiredError("--xdmf or --geojson");
    std::vector<std::string> args{"export", run_file, geojson ? "--geojson" : "--xdmf"};
    if (!out.empty()) args.insert(args.end(), {"--out", out});
    return python_status(args);
  }
};

struct AnimateCommand {
  std::string run_file, out, colour = "speed";
  int fps = 12, dpi = 100;
  bool quiet = false;
  CLI::App* app = nullptr;

  void add(CLI::App& parent) {
    app = parent.add_subcommand("animate", "write a film of a run (matplotlib and ffmpeg), with a progress line");
    app->add_option("run", run_file, "a run's output, RESULT.h5")->required();
    app->add_option("--out,-o", out, "the film (default: RESULT.mp4 beside the run; .gif also works)");
    app->add_option("--colour", colour, "colour floes by their speed, or by the contact force they carry")
        ->check(CLI::IsMember({"speed", "force"}))
        ->capture_default_str();
    app->add_option("--fps", fps, "frames a second of film")->check(CLI::PositiveNumber)->capture_default_str();
    app->add_option("--dpi", dpi, "resolution")->check(CLI::Range(10, 1000))->capture_default_str();
    app->add_flag("--quiet,-q", quiet, "no progress line");
  }
  int run() const {
    std::vector<std::string> args{"animate", run_file, "--colour", colour, "--fps", std::to_string(fps), "--dpi",
                                  std::to_string(dpi)};
    if (!out.empty()) args.insert(args.end(), {"--out", out});
    if (quiet) args.emplace_back("--quiet");
    return python_status(args);
  }
};

// The exit codes of the opening comment, from what the command threw.
int failure_status(const std::exception_ptr& error) {
  try {
    std::rethrow_exception(error);
  } catch (const floedem::StateError& e) {
    std::cerr << "floedem: error: " << e.what() << "\n";
    return 2;
  } catch (const floedem::InputError& e) {
    std::cerr << "floedem: error: " << e.what() << "\n";
    return 2;
  } catch (const floedem::OutputError& e) {
    std::cerr << "floedem: output error: " << e.what() << "\n";
    // After a failed write (disk full) HDF5 still holds the file open in an inconsistent state,
    // and its exit handler would crash closing it: leave without running the exit handlers.
    std::cout.flush();
    std::cerr.flush();
    std::_Exit(3);
  } catch (const floedem::SolverFailure& e) {
    std::cerr << "floedem: solver failure: " << e.what() << "\n";
    return 4;
  } catch (const floedem::RunStopped& e) {
    std::cerr << "floedem: " << (stop_signal == SIGINT ? "SIGINT" : "SIGTERM") << ": " << e.what() << "\n";
    return 128 + (stop_signal != 0 ? static_cast<int>(stop_signal) : SIGTERM);
  } catch (const std::exception& e) {
    std::cerr << "floedem: unexpected error: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  // A file-size limit on the process (ulimit -f, RLIMIT_FSIZE: a batch system passes on the
  // submitting shell's) sends SIGXFSZ on the write that crosses it, whose default action kills
  // the run without a word. Ignored, the write fails with EFBIG instead, which the recorder
  // reports as any failed write: one line, exit 3, the .partial kept for --resume.
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App app{"floedem: planar non-smooth DEM of icebergs drifting or towed through broken sea ice"};
  // The library's version and the output layout it writes and reads, as a run's file stores them
  // (root attributes floedem_version and format_version).
  app.set_version_flag("--version", "floedem " + std::string(floedem::version()) + " (output format_version " +
                                        std::to_string(floedem::kOutputFormatVersion) + ")");
  app.require_subcommand(1);

  RunCommand run;
  run.add(app);
  CLI::App* list = app.add_subcommand("engines", "list the engines this build has");
  CLI::App* stage_list = app.add_subcommand(
      "stages", "list the stages of a step on the native engine, in order, as `floedem bench --stages` names them");
  ReportCommand report;
  report.add(app);
  CheckCommand check;
  check.add(app);
  SweepCommand sweep;
  sweep.add(app);
  ExportCommand export_command;
  export_command.add(app);
  AnimateCommand animate;
  animate.add(app);
  floedem::BenchCommand bench_options;
  CLI::App* bench = floedem::add_bench_command(app, bench_options);
  floedem::FieldCommand field_options;
  CLI::App* field = floedem::add_field_command(app, field_options);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }

  try {
    if (list->parsed()) {
      for (const auto& e : floedem::engines()) std::cout << e.name << "\t" << e.description << "\n";
      return 0;
    }
    if (stage_list->parsed()) {
      for (const auto& s : floedem::kStepStages) std::cout << s.name << "\t" << s.label << "\t" << s.what << "\n";
      return 0;
    }
    if (field->parsed()) return floedem::run_field_command(field_options);
    if (check.app->parsed()) return check.run();
    if (sweep.app->parsed()) return sweep.run();
    if (export_command.app->parsed()) return export_command.run();
    if (animate.app->parsed()) return animate.run();
    if (bench->parsed()) return floedem::run_bench_command(bench_options);
    if (report.app->parsed()) return report.run();
    return run.run();
  } catch (...) {
    return failure_status(std::current_exception());
  }
}
