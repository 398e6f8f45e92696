// floedem command line. Exit codes: 0 done; 1 unexpected error; 2 bad input (scenario,
// options, engine settings); 3 output could not be written; 4 the solver failed (report: a run
// failed); 5 report: the engines disagree beyond the documented tolerances.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <cstdlib>
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
  const RunSummary summary = run_scene(scene, options);
  if (!quiet) std::cout << format_summary(scene, summary, output);
  return 0;
}

int resume_command(const std::string& path, const std::vector<std::string>& overrides, bool quiet) {
  using namespace floedem;
  const ResumeResult r = resume_run(path, overrides, !quiet);
  if (!r.ran) {
    if (!quiet) std::cout << r.message << "\n";
    return 0;
  }
  if (!quiet) std::cout << "floedem run --resume: " << r.message << "\n" << format_summary(r.scene, r.summary, r.summary_output);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"floedem: planar non-smooth DEM of icebergs drifting or towed through broken sea ice"};
  // The library's version and the output layout it writes and reads, as a run's file stores them
  // (root attributes floedem_version and format_version).
  app.set_version_flag("--version", "floedem " + std::string(floedem::version()) + " (output format_version " +
                                        std::to_string(floedem::kOutputFormatVersion) + ")");
  app.require_subcommand(1);

  std::string scenario, engine = "native", output;
  std::vector<std::string> overrides;
  bool quiet = false;
  CLI::App* run = app.add_subcommand("run", "run a scenario on one engine and write its HDF5 output");
  std::string resume;
  CLI::Option* scenario_option =
      run->add_option("scenario", scenario, "scenario file (TOML), see scenarios/README.md");
  std::string engine_names;
  for (const auto& e : floedem::engines()) engine_names += (engine_names.empty() ? "" : "|") + e.name;
  run->add_option("--engine,-e", engine, "engine: " + engine_names)->capture_default_str();
  run->add_option("--out,-o", output, "output file (default: SCENARIO_STEM.ENGINE.h5 in the current directory)");
  run->add_option("--set,-s", overrides,
                  "override a scalar of the scenario, KEY=VALUE (e.g. run.duration=60, body[2].density=917); repeatable")
      ->allow_extra_args(false);
  run->add_flag("--quiet,-q", quiet, "no progress line and no summary");
  CLI::Option* resume_option = run->add_option(
      "--resume", resume,
      "continue the run in RESULT.h5 (or RESULT.h5.partial, a run killed) from its last checkpoint, to the end of "
      "its run.duration or of a longer one given with --set run.duration=T; the file ends as an uninterrupted "
      "run's would (native engine; other engines run again from t = 0)");
  resume_option->excludes(scenario_option);
  run->get_option("--out")->excludes(resume_option);
  run->get_option("--engine")->excludes(resume_option);
  scenario_option->excludes(resume_option);
  run->callback([&] {
    if (scenario.empty() && resume.empty())
      throw CLI::RequiredError("a scenario file, or --resume RESULT.h5,");
  });
  CLI::App* list = app.add_subcommand("engines", "list the engines this build has");
  CLI::App* stage_list = app.add_subcommand(
      "stages", "list the stages of a step on the native engine, in order, as `floedem bench --stages` names them");

  std::string report_out = "results/report";
  bool report_quick = false;
  int report_jobs = 0;
  std::string report_only;
  CLI::App* report = app.add_subcommand(
      "report", "run the scenario suite on every engine and write DIR/REPORT.md with its figures (reports/report.py)");
  report->add_option("--out,-o", report_out, "report directory (its fig/ and runs/ are replaced)")->capture_default_str();
  report->add_flag("--quick", report_quick,
                   "the same sections on smaller, shorter cases (the CI cross-check; a few minutes on 2 cores)");
  report->add_option("--only", report_only, "a partial report of these sections alone, comma-separated (report.py names them; an unknown one is refused with the list)");
  report->add_option("--jobs,-j", report_jobs, "runs at a time (default: the number of cores)")
      ->check(CLI::PositiveNumber);

  // floedem check: the scenario loaded, overrides applied and each engine built, as a run would,
  // and nothing run (a sweep checks every point with it before it starts).
  std::string check_scenario;
  std::vector<std::string> check_overrides, check_engines;
  CLI::App* check = app.add_subcommand(
      "check", "check a scenario with its overrides on engines, as a run would, without running it (exit 2 and one line when it is refused)");
  check->add_option("scenario", check_scenario, "scenario file (TOML)")->required();
  check->add_option("--set,-s", check_overrides, "override a scalar of the scenario, KEY=VALUE; repeatable")
      ->allow_extra_args(false);
  check->add_option("--engine,-e", check_engines, "an engine to build the scene on; repeatable (default native)")
      ->allow_extra_args(false);

  // The Python package's commands (python/floedem): the command parses, the package does the work.
  std::string sweep_spec, sweep_out, sweep_profile;
  int sweep_jobs = 0;
  bool sweep_dry = false;
  CLI::App* sweep = app.add_subcommand(
      "sweep", "run a sweep file's parameter points, seeds and engines through Snakemake, then reduce them to one table "
               "(docs/sweeps.md)");
  sweep->add_option("spec", sweep_spec, "sweep file (TOML)")->required();
  sweep->add_option("--out,-o", sweep_out, "the sweep's directory (its runs, their summaries, the reduced table)")
      ->required();
  sweep->add_option("--jobs,-j", sweep_jobs, "cores for the runs at a time (default: the CPUs this process may use)")
      ->check(CLI::PositiveNumber);
  sweep->add_option("--profile", sweep_profile, "a Snakemake profile (a cluster: the repository's profiles/slurm)");
  sweep->add_flag("--dry-run,-n", sweep_dry, "check and plan, print what would run, run nothing");
  std::string export_run, export_out;
  bool export_xdmf = false;
  CLI::App* export_cmd = app.add_subcommand(
      "export", "write a run as XDMF for ParaView, beside it: RESULT.xdmf and RESULT.xdmf.h5 (the run's file is only read)");
  export_cmd->add_option("run", export_run, "a run's output, RESULT.h5")->required();
  export_cmd->add_flag("--xdmf", export_xdmf, "XDMF (the one format for now)")->required();
  export_cmd->add_option("--out,-o", export_out, "the XDMF file (default: RESULT.xdmf beside the run)");
  std::string animate_run, animate_out, animate_colour = "speed";
  int animate_fps = 12, animate_dpi = 100;
  bool animate_quiet = false;
  CLI::App* animate_cmd = app.add_subcommand("animate", "write a film of a run (matplotlib and ffmpeg), with a progress line");
  animate_cmd->add_option("run", animate_run, "a run's output, RESULT.h5")->required();
  animate_cmd->add_option("--out,-o", animate_out, "the film (default: RESULT.mp4 beside the run; .gif also works)");
  animate_cmd->add_option("--colour", animate_colour, "colour floes by their speed, or by the contact force they carry")
      ->check(CLI::IsMember({"speed", "force"}))
      ->capture_default_str();
  animate_cmd->add_option("--fps", animate_fps, "frames a second of film")->check(CLI::PositiveNumber)->capture_default_str();
  animate_cmd->add_option("--dpi", animate_dpi, "resolution")->check(CLI::Range(10, 1000))->capture_default_str();
  animate_cmd->add_flag("--quiet,-q", animate_quiet, "no progress line");

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
    if (check->parsed()) {
      const floedem::Scene scene = floedem::load_scenario(check_scenario, check_overrides);
      if (check_engines.empty()) check_engines.emplace_back("native");
      for (const std::string& e : check_engines) (void)floedem::make_engine(e, scene);
      std::cout << check_scenario << ": ok (" << scene.bodies.size() << " bodies, " << scene.run.steps() << " steps)\n";
      return 0;
    }
    if (sweep->parsed()) {
      std::vector<std::string> args{"sweep", sweep_spec, "--out", sweep_out, "--floedem", floedem::own_executable()};
      if (sweep_jobs > 0) args.insert(args.end(), {"--jobs", std::to_string(sweep_jobs)});
      if (!sweep_profile.empty()) args.insert(args.end(), {"--profile", sweep_profile});
      if (sweep_dry) args.emplace_back("--dry-run");
      const int status = floedem::run_python_module(args);
      return status < 0 ? 1 : status;
    }
    if (export_cmd->parsed()) {
      std::vector<std::string> args{"export", export_run, "--xdmf"};
      if (!export_out.empty()) args.insert(args.end(), {"--out", export_out});
      const int status = floedem::run_python_module(args);
      return status < 0 ? 1 : status;
    }
    if (animate_cmd->parsed()) {
      std::vector<std::string> args{"animate", animate_run, "--colour", animate_colour, "--fps",
                                    std::to_string(animate_fps), "--dpi", std::to_string(animate_dpi)};
      if (!animate_out.empty()) args.insert(args.end(), {"--out", animate_out});
      if (animate_quiet) args.emplace_back("--quiet");
      const int status = floedem::run_python_module(args);
      return status < 0 ? 1 : status;
    }
    if (bench->parsed()) return floedem::run_bench_command(bench_options);
    if (report->parsed()) {
      // Exit status as the script's: 0 agreement, 5 disagreement, 4 a run failed.
      std::vector<std::string> args{"--floedem", floedem::own_executable(), "--out", report_out};
      if (report_quick) args.emplace_back("--quick");
      if (report_jobs > 0) args.insert(args.end(), {"--jobs", std::to_string(report_jobs)});
      if (!report_only.empty()) args.insert(args.end(), {"--only", report_only});
      const int status = floedem::run_python_script("report.py", args);
      return status < 0 ? 1 : status;
    }
    if (!resume.empty()) return resume_command(resume, overrides, quiet);
    return run_command(scenario, engine, output, overrides, quiet);
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
  } catch (const std::exception& e) {
    std::cerr << "floedem: unexpected error: " << e.what() << "\n";
    return 1;
  }
}
