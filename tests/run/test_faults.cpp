// The fault matrix (docs/output.md, "Under faults"): every fault a run meets on a cluster,
// tried at steps and sizes drawn at random (a fixed seed: the same draws on every CI run), on
// native and on a reference engine. Each ends where docs/output.md says: a run killed or
// stopped and continued is the uninterrupted run's file to the bit; a full disk is exit 3 with
// one line and nothing under the final name, and its .partial continues to the same file; a
// second run on the same name is refused and the
// first's file untouched; a reader of a file being written is refused, never handed half of it.
#include <catch2/catch.hpp>

#include <H5Cpp.h>

#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "floedem/io/output.hpp"
#include "floedem/scene/input_error.hpp"
#include "io/output_lock.hpp"
#include "run/file_contents.hpp"
#include "support.hpp"

using namespace floedem;
namespace fs = std::filesystem;

namespace {

// A berg towed by a tug through some 370 floes (python/tests/tug_field.toml), 300 steps with a
// frame each: a checkpoint every 88 frames, so kills fall before, between and after them. The
// tug's line, the open collisions and the warm-started contacts all cross the checkpoints.
const std::string kFaultScene = std::string(FLOEDEM_SOURCE_DIR) + "/python/tests/tug_field.toml";
const std::string kFaultSets = " --set run.duration=75.0 --set run.output_every=1";
constexpr int kSteps = 300;

std::string run_args(const std::string& engine, const fs::path& out) {
  return "run " + kFaultScene + kFaultSets + " -q -e " + engine + " --out " + out.string();
}

/// Steps drawn at random in [1, kSteps - 1].
std::vector<int> draws(std::mt19937& rng, int n) {
  std::uniform_int_distribution<int> step(1, kSteps - 1);
  std::vector<int> out;
  for (int k = 0; k < n; ++k) out.push_back(step(rng));
  return out;
}

int lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

}  // namespace

TEST_CASE("faults: killed, stopped or interrupted at random steps and continued, the same file", "[faults][resume]") {
  std::mt19937 rng(91);
  for (const std::string engine : {"native", "box2d"}) {
    if (engine != "native" && !test::have_engine(engine)) continue;
    const fs::path dir = test::temp_dir("faults-signal-" + engine);
    REQUIRE(test::run_cli(run_args(engine, dir / "whole.h5")).code == 0);
    const test::Contents whole = test::contents(dir / "whole.h5");
    // Native continues from its checkpoint; Box2D cannot save its state and runs again from t = 0.
    const int per = engine == "native" ? 4 : 2;
    struct Fault {
      const char* hook;
      int code;  // the exit status: SIGKILL's from the shell, 128 + the signal after a checkpoint
    };
    for (const Fault f : {Fault{"FLOEDEM_TEST_KILL_AT_STEP", 128 + 9}, Fault{"FLOEDEM_TEST_TERM_AT_STEP", 143},
                          Fault{"FLOEDEM_TEST_INT_AT_STEP", 130}}) {
      for (const int step : draws(rng, per)) {
        INFO(engine << ": " << f.hook << "=" << step);
        const fs::path cut = dir / ("cut-" + std::to_string(step) + ".h5");
        const auto stopped = test::run_cli(run_args(engine, cut), std::string(f.hook) + "=" + std::to_string(step) + " ");
        INFO(stopped.output);
        CHECK(stopped.code == f.code);
        CHECK_FALSE(fs::exists(cut));
        REQUIRE(fs::exists(cut.string() + ".partial"));
        const auto resumed = test::run_cli("run -q --resume " + cut.string());
        INFO(resumed.output);
        REQUIRE(resumed.code == 0);
        test::check_same_contents(whole, cut);
        CHECK_FALSE(fs::exists(cut.string() + ".partial"));
        CHECK_FALSE(fs::exists(cut.string() + ".lock"));
      }
    }
    fs::remove_all(dir);
  }
}

TEST_CASE("faults: a file-size limit reached at a random write is exit 3, one line, and continued, the same file",
          "[faults][output]") {
  // RLIMIT_FSIZE (`ulimit -f`, passed on by Slurm from the submitting shell) stands in for a
  // disk that fills: the same failed write(2). A limit below what the frames alone need is
  // refused before the run (below); with every contact recorded (some 4.7 of 13.8 MB, which
  // that check cannot foresee) the limits drawn between 0.7 and 0.97 of the whole file are
  // reached mid-run, at checkpoints, frames and contact rows. In the 512-byte blocks of dash's
  // ulimit. The .partial is continued without the limit (as on a disk with room again, or
  // moved elsewhere) to the uninterrupted file.
  std::mt19937 rng(92);
  for (const std::string engine : {"native", "box2d"}) {
    if (engine != "native" && !test::have_engine(engine)) continue;
    const fs::path dir = test::temp_dir("faults-disk-" + engine);
    auto args = [&](const fs::path& out) { return run_args(engine, out) + " --set output.contacts=all"; };
    REQUIRE(test::run_cli(args(dir / "whole.h5")).code == 0);
    const test::Contents whole = test::contents(dir / "whole.h5");
    const auto size = static_cast<double>(fs::file_size(dir / "whole.h5"));
    std::uniform_real_distribution<double> share(0.7, 0.97);
    for (int k = 0; k < (engine == "native" ? 4 : 2); ++k) {
      const long blocks = static_cast<long>(share(rng) * size / 512.0);
      INFO(engine << ": ulimit -f " << blocks);
      const fs::path cut = dir / ("full-" + std::to_string(k) + ".h5");
      const auto r = test::run_cli(args(cut), "ulimit -f " + std::to_string(blocks) + "; ");
      INFO(r.output);
      CHECK(r.code == 3);
      CHECK(lines(r.output) == 1);
      CHECK(r.output.find(cut.string() + ".partial") != std::string::npos);
      CHECK_FALSE(fs::exists(cut));                      // nothing looks complete
      REQUIRE(fs::exists(cut.string() + ".partial"));    // what was written stays
      CHECK_FALSE(fs::exists(cut.string() + ".lock"));   // and the name is free for the next run
      const auto resumed = test::run_cli("run -q --resume " + cut.string());
      INFO(resumed.output);
      REQUIRE(resumed.code == 0);
      test::check_same_contents(whole, cut);
    }
    // A limit below what the frames alone need: refused before anything is written.
    const fs::path none = dir / "none.h5";
    const auto r = test::run_cli(args(none), "ulimit -f 8; ");
    INFO(r.output);
    CHECK(r.code == 3);
    CHECK(lines(r.output) == 1);
    CHECK(r.output.find("file-size limit (ulimit -f)") != std::string::npos);
    CHECK_FALSE(fs::exists(none));
    CHECK_FALSE(fs::exists(none.string() + ".partial"));
    fs::remove_all(dir);
  }
}

TEST_CASE("faults: a second run on a name another run is writing is refused, the first file untouched",
          "[faults][output]") {
  // The first run stands as this process holding the name's lock (as a running floedem does)
  // over a partial file left by a kill: the second, fresh or --resume, must leave both alone.
  const fs::path dir = test::temp_dir("faults-twice");
  const fs::path out = dir / "r.h5";
  REQUIRE(test::run_cli(run_args("native", out), "FLOEDEM_TEST_KILL_AT_STEP=150 ").code != 0);
  const test::Contents before = test::contents(out.string() + ".partial");
  {
    const OutputLock held(out.string());
    for (const std::string& args : {run_args("native", out), std::string("run -q --resume ") + out.string()}) {
      INFO(args);
      const auto r = test::run_cli(args);
      INFO(r.output);
      CHECK(r.code == 3);
      CHECK(lines(r.output) == 1);
      CHECK(r.output.find("another floedem run is writing it") != std::string::npos);
      test::check_same_contents(before, out.string() + ".partial");
      CHECK_FALSE(fs::exists(out));
    }
    // Two locks on one name in one process conflict too: the second is refused.
    CHECK_THROWS_AS(OutputLock(out.string()), OutputError);
  }
  CHECK_FALSE(fs::exists(out.string() + ".lock"));  // given up with its holder
  REQUIRE(test::run_cli("run -q --resume " + out.string()).code == 0);
  fs::remove_all(dir);
}

TEST_CASE("faults: a reader of a file that a run has open for writing is refused, never handed half of it",
          "[faults][output]") {
  const fs::path dir = test::temp_dir("faults-reader");
  const fs::path out = dir / "r.h5";
  REQUIRE(test::run_cli(run_args("native", out), "FLOEDEM_TEST_KILL_AT_STEP=200 ").code != 0);
  const std::string partial = out.string() + ".partial";
  const StoredRun whole = read_stored_run(partial);  // a killed run's file: a consistent prefix
  CHECK(whole.status == "running");
  {
    // Opened for writing, as a running recorder holds it: HDF5's file lock refuses a reader in
    // another process (this one's own opens share the file, so the reader is the command's).
    H5::H5File writing(partial, H5F_ACC_RDWR);
    const auto r = test::run_cli("export " + partial + " --xdmf --out " + (dir / "r.xdmf").string());
    INFO(r.output);
    CHECK(r.code == 2);
    CHECK(lines(r.output) == 1);
    CHECK(r.output.find("a run is writing it") != std::string::npos);
    CHECK_FALSE(fs::exists(dir / "r.xdmf"));
  }
  CHECK(read_stored_run(partial).status == "running");
  fs::remove_all(dir);
}
