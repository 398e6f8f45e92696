#pragma once
// `floedem bench`: the wall time per step of a scenario on one engine, with what the step costs
// besides (allocations, peak memory) and what it achieved (contact fraction, penetration), as
// one CSV row per run. No output file is written: the recorder's work is not timed. The report's
// speed section and reports/bench.py run it, one run at a time, one process per run (so that
// the peak memory is the run's own).
#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace floedem {

struct BenchCommand {
  std::string scenario;
  std::string engine = "native";
  std::vector<std::string> overrides;
  double window = 0.0;   ///< s of model time at the end of the run that are timed; 0: all of it
  std::string csv;       ///< append the row here (header first when the file is new); empty: stdout only
  bool quiet = false;
  bool stages = false;   ///< time each stage of the timed steps (the stage_ms column)
};

CLI::App* add_bench_command(CLI::App& app, BenchCommand& c);
/// Throws InputError (exit 2), OutputError (exit 3), SolverFailure (exit 4); returns the exit code.
int run_bench_command(const BenchCommand& c);

}  // namespace floedem
