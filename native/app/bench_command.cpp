#include "app/bench_command.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "app/allocation_count.hpp"
#include "io/recorder.hpp"
#include "parallel/threads.hpp"
#include "floedem/run/simulation.hpp"
#include "floedem/run/bench.hpp"
#include "floedem/scenario/scenario.hpp"
#include "floedem/scene/input_error.hpp"
#include "floedem/version.hpp"

namespace floedem {

namespace {

constexpr const char* kHeader =
    "host,cpu,threads,floedem_version,scenario,overrides,engine,engine_version,bodies,moving_bodies,dt,steps,"
    "timed_steps,median_ms,mean_ms,p10_ms,p90_ms,setup_s,total_s,contact_fraction,max_penetration_m,"
    "mean_penetration_m,allocations_per_step,peak_rss_mb,stage_ms,work";

/// The processor as far as this machine tells: its model name, and its family, model and cache
/// sizes, since a virtual machine's model name alone ("AMD EPYC") names processors generations
/// apart, and the speed ratios of a report belong to the machine it ran on.
std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line, name = "unknown", family, model;
  auto value = [&] {
    const auto colon = line.find(':');
    std::string v = colon == std::string::npos ? line : line.substr(colon + 1);
    v.erase(0, v.find_first_not_of(" \t"));
    return v;
  };
  while (std::getline(in, line) && !line.empty()) {  // the first processor's block
    if (line.rfind("model name", 0) == 0) name = value();
    else if (line.rfind("cpu family", 0) == 0) family = value();
    else if (line.rfind("model", 0) == 0 && line.find("model name") == std::string::npos) model = value();
  }
  std::string detail;
  if (!family.empty()) detail += "; family " + family + " model " + model;
  for (int index = 0; index < 8; ++index) {  // the caches of processor 0, as sysfs lists them
    const std::string dir = "/sys/devices/system/cpu/cpu0/cache/index" + std::to_string(index) + "/";
    std::ifstream level_in(dir + "level"), type_in(dir + "type"), size_in(dir + "size");
    std::string level, type, size;
    if (!(level_in >> level) || !(type_in >> type) || !(size_in >> size)) break;
    if (type != "Instruction") detail += "; L" + level + (type == "Data" ? "d " : " ") + size;
  }
  return name + detail;
}

std::string host_name() {
  char b[256] = {};
  if (gethostname(b, sizeof b - 1) != 0) return "unknown";
  return b;
}

/// A CSV field: quoted when it holds a comma or a quote.
std::string field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (const char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

/// Peak resident memory of this process image, MB: VmHWM of /proc/self/status. Not getrusage's
/// ru_maxrss, which Linux carries over an exec from the parent (a Python harness's 70 MB would
/// show as this run's peak).
double peak_resident_mb() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::strtod(line.c_str() + 6, nullptr) / 1024.0;  // kB
  return std::nan("");
}

}  // namespace

CLI::App* add_bench_command(CLI::App& app, BenchCommand& c) {
  CLI::App* b = app.add_subcommand(
      "bench", "time a scenario on one engine (no output file) and print one CSV row: ms per step, "
               "allocations per step, peak memory, contact fraction, penetration");
  b->add_option("scenario", c.scenario, "scenario file (TOML)")->required();
  b->add_option("--engine,-e", c.engine, "engine")->capture_default_str();
  b->add_option("--set,-s", c.overrides, "override a scalar of the scenario, KEY=VALUE; repeatable")
      ->allow_extra_args(false);
  b->add_option("--window,-w", c.window,
                "seconds of model time at the end of the run that are timed (default: the whole run)")
      ->check(CLI::NonNegativeNumber);
  b->add_option("--csv", c.csv, "append the row to this file (its header first when the file is new)");
  b->add_flag("--stages", c.stages,
              "also time each stage of the timed steps (the stage_ms column; two clock reads a stage, "
              "about 0.3 us a step, which a scene of a few bodies would feel: off unless asked for)");
  b->add_flag("--quiet,-q", c.quiet, "no progress line");
  return b;
}

int run_bench_command(const BenchCommand& c) {
  // setup_s and total_s count the scenario's loading too (a generated field's making).
  const auto start = std::chrono::steady_clock::now();
  const Scene scene = load_scenario(c.scenario, c.overrides);
  const double loading = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  BenchOptions options;
  options.engine = c.engine;
  options.window = c.window;
  options.stages = c.stages;
  options.allocations = allocations_so_far;
  if (!c.quiet)
    options.progress = [&](std::int64_t k, std::int64_t steps) {
      std::fprintf(stderr, "bench: %s on %s: step %lld/%lld\n", c.scenario.c_str(), c.engine.c_str(),
                   static_cast<long long>(k), static_cast<long long>(steps));
    };
  const BenchResult r = bench_scene(scene, options);
  // With --stages, the mean ms a timed step per stage, "name=ms" separated by spaces (one CSV
  // field); the forcing and towing alone for an engine that does not time its own stages.
  std::ostringstream stages;
  stages.precision(4);
  for (const StageTime& t : r.stages) stages << (stages.tellp() > 0 ? " " : "") << t.name << '=' << 1e3 * t.seconds;
  // The engine's work a timed step, "name=count" separated by spaces (native: its sweeps, islands
  // and redetections; empty for an engine that counts none).
  std::ostringstream work;
  work.precision(4);
  for (const WorkCount& w : r.work) work << (work.tellp() > 0 ? " " : "") << w.name << '=' << w.count;
  const double peak_mb = peak_resident_mb();

  std::string overrides;
  for (const std::string& o : c.overrides) overrides += (overrides.empty() ? "" : " ") + o;
  std::ostringstream row;
  row.precision(6);
  row << field(host_name()) << ',' << field(cpu_model()) << ',' << worker_threads() << ',' << field(version()) << ','
      << field(std::filesystem::path(c.scenario).filename().string()) << ',' << field(overrides) << ',' << c.engine << ','
      << field(r.engine_version) << ',' << scene.bodies.size() << ',' << r.moving_bodies << ',' << scene.run.dt << ','
      << r.steps << ',' << r.timed_steps << ',' << r.median_ms << ',' << r.mean_ms << ',' << r.p10_ms << ',' << r.p90_ms
      << ',' << loading + r.setup_seconds << ',' << loading + r.total_seconds << ',' << r.contact_fraction << ',' << r.max_penetration << ','
      << r.mean_penetration << ',' << r.allocations_per_step << ',' << peak_mb << ',' << field(stages.str()) << ','
      << field(work.str());
  std::cout << kHeader << '\n' << row.str() << '\n';
  if (!c.csv.empty()) {
    const std::filesystem::path dir = std::filesystem::path(c.csv).parent_path();
    if (!dir.empty() && !std::filesystem::is_directory(dir))
      throw OutputError("cannot append to " + c.csv + ": no directory " + dir.string());
    const bool fresh = !std::filesystem::exists(c.csv) || std::filesystem::file_size(c.csv) == 0;
    if (!fresh) {  // rows go under a header of the same columns, or not at all
      std::ifstream in(c.csv);
      std::string header;
      std::getline(in, header);
      if (header != kHeader)
        throw OutputError("cannot append to " + c.csv + ": its header is not this bench's columns (" + kHeader +
                          "); write to a new file");
    }
    std::ofstream out(c.csv, std::ios::app);
    if (fresh) out << kHeader << '\n';
    out << row.str() << '\n';
    out.flush();
    if (!out) throw OutputError("cannot append to " + c.csv);
  }
  return 0;
}

}  // namespace floedem
