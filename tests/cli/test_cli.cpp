// The command line: exit codes, one-line errors, no output left behind on bad input.
#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>

#include "app/sanitizer.hpp"
#include "support.hpp"

namespace fs = std::filesystem;

namespace {

using Result = floedem::test::CliResult;
Result run(const std::string& args) { return floedem::test::run_cli(args); }

fs::path dir_for(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("floedem-cli-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

}  // namespace

TEST_CASE("cli: a good run exits 0 and writes the output", "[cli]") {
  const fs::path d = dir_for("good");
  const std::string scenario = std::string(FLOEDEM_SOURCE_DIR) + "/scenarios/head_on.toml";
  const Result r = run("run " + scenario + " --out " + (d / "r.h5").string() + " --set run.duration=1");
  CHECK(r.code == 0);
  CHECK(r.output.find("impulses") != std::string::npos);
  CHECK(fs::exists(d / "r.h5"));
  fs::remove_all(d);
}

TEST_CASE("cli: bad input exits 2 with one line naming file and field, and leaves no file", "[cli]") {
  const fs::path d = dir_for("bad");
  const fs::path bad = d / "bad.toml";
  std::ofstream(bad) << "[run]\nduration = 1.0\ndt = 0.01\n[contact]\nrestitution = 1.2\n"
                        "[[body]]\npolygon = [[0,0],[1,0],[1,1]]\nthickness = 1\n";
  const fs::path out = d / "r.h5";
  Result r = run("run " + bad.string() + " --out " + out.string());
  CHECK(r.code == 2);
  CHECK(r.output.find(bad.string() + ":5") != std::string::npos);
  CHECK(r.output.find("contact.restitution") != std::string::npos);
  CHECK(r.output.find("[0, 1]") != std::string::npos);
  CHECK(std::count(r.output.begin(), r.output.end(), '\n') == 1);
  CHECK_FALSE(fs::exists(out));
  CHECK_FALSE(fs::exists(out.string() + ".partial"));

  r = run("run " + (d / "missing.toml").string() + " --out " + out.string());
  CHECK(r.code == 2);
  CHECK(r.output.find("missing.toml") != std::string::npos);
  CHECK_FALSE(fs::exists(out.string() + ".partial"));

  const std::string good = std::string(FLOEDEM_SOURCE_DIR) + "/scenarios/head_on.toml";
  r = run("run " + good + " --engine havok --out " + out.string());
  CHECK(r.code == 2);
  CHECK(r.output.find("unknown engine") != std::string::npos);
  CHECK_FALSE(fs::exists(out.string() + ".partial"));

  r = run("run " + good + " --set contact.friction=-1 --out " + out.string());
  CHECK(r.code == 2);
  CHECK(r.output.find("contact.friction") != std::string::npos);

  r = run("run " + good + " --no-such-option");
  CHECK(r.code == 2);
  fs::remove_all(d);
}

TEST_CASE("cli: an unwritable output exits 3", "[cli]") {
  const std::string good = std::string(FLOEDEM_SOURCE_DIR) + "/scenarios/head_on.toml";
  const Result r = run("run " + good + " --out /nonexistent-dir/r.h5");
  CHECK(r.code == 3);
  CHECK(r.output.find("/nonexistent-dir/r.h5") != std::string::npos);
}

TEST_CASE("cli: a disk that fills during the run exits 3, and nothing lies under the final name", "[cli]") {
  // A file-size limit (ulimit -f, which a batch system passes on from the submitting shell)
  // stands in for a full disk: floedem ignores the SIGXFSZ it sends, which would otherwise kill
  // the run without a word (exit 153), so write() fails (EFBIG) as it would with ENOSPC. 1.5 MB
  // (3000 of dash's 512-byte blocks) is more than its frames alone need (1.05 MB, below which
  // the run is refused before it starts) and holds the start of drift_in_floes (2.2 MB with its
  // collision rows). One line is all it prints: HDF5's destructors, closing the datasets the
  // failed write left, said so a line each.
  const fs::path d = fs::temp_directory_path() / ("floedem-full-" + std::to_string(::getpid()));
  fs::create_directories(d);
  const std::string scenario = std::string(FLOEDEM_SOURCE_DIR) + "/scenarios/drift_in_floes.toml";
  const fs::path out = d / "r.h5";
  const Result r = floedem::test::run_cli("run " + scenario + " -q --out " + out.string(), "ulimit -f 3000; ");
  INFO(r.output);
  CHECK(r.code == 3);
  CHECK(r.output.find("disk full?") != std::string::npos);
  CHECK(r.output.find(out.string() + ".partial") != std::string::npos);
  CHECK(std::count(r.output.begin(), r.output.end(), '\n') == 1);
  CHECK_FALSE(fs::exists(out));
  CHECK(fs::exists(out.string() + ".partial"));
  fs::remove_all(d);
}

TEST_CASE("cli: a disk too small for the frames is told before the run, exit 3", "[cli]") {
  // /dev/shm or /tmp cannot hold 1e12 frames of a 36-floe scene: refused at once, nothing made.
  const fs::path d = fs::temp_directory_path() / ("floedem-small-" + std::to_string(::getpid()));
  fs::create_directories(d);
  const std::string scenario = std::string(FLOEDEM_SOURCE_DIR) + "/scenarios/default.toml";
  const fs::path out = d / "r.h5";
  const Result r = run("run " + scenario + " -q --set run.duration=1e9 --set run.dt=0.001 --out " + out.string());
  INFO(r.output);
  CHECK(r.code == 3);
  CHECK(r.output.find("frames alone need") != std::string::npos);
  CHECK(fs::is_empty(d));
  fs::remove_all(d);
}

TEST_CASE("cli: help lists the commands and options", "[cli]") {
  Result r = run("--help");
  CHECK(r.code == 0);
  CHECK(r.output.find("run") != std::string::npos);
  r = run("run --help");
  CHECK(r.code == 0);
  for (const char* opt : {"--engine", "--out", "--set"}) CHECK(r.output.find(opt) != std::string::npos);
}

TEST_CASE("cli: floedem bench prints and appends one CSV row, bad input exits 2", "[cli]") {
  // Not a timing test: what the row holds (its columns and the achieved figures), not how fast.
  const fs::path d = dir_for("bench");
  const std::string scenario = std::string(FLOEDEM_SOURCE_DIR) + "/scenarios/head_on.toml";
  const fs::path csv = d / "b.csv";
  for (int k = 0; k < 2; ++k) {
    const Result r = run("bench " + scenario + " --window 0.5 --set run.duration=2 --csv " + csv.string() + " -q" +
                         (k == 0 ? " --stages" : ""));
    CHECK(r.code == 0);
    CHECK(r.output.find("median_ms") != std::string::npos);
  }
  std::ifstream in(csv);
  std::string header, first, row, line;
  std::getline(in, header);
  int rows = 0;
  while (std::getline(in, line)) {
    if (rows == 0) first = line;
    row = line;
    ++rows;
  }
  CHECK(rows == 2);  // appended, the header once
  auto columns = [](const std::string& s) { return std::count(s.begin(), s.end(), ',') + 1; };
  CHECK(columns(header) == columns(row));
  CHECK(header.rfind("host,cpu,threads,", 0) == 0);
  CHECK(row.find(",native,floedem,2,2,") != std::string::npos);  // engine, version, bodies, moving
  CHECK(first.find("contact_solve=") != std::string::npos);  // --stages: native times its own stages
  CHECK(row.find(",,sweeps=") != std::string::npos);          // without: stage_ms is left empty
  CHECK(header.ends_with(",stage_ms,work"));  // the work column last
  CHECK(row.find(" islands=") != std::string::npos);
  CHECK(row.find(" redetections=") != std::string::npos);
  // A file of other columns (an older bench's) is not appended to: the row would not fit.
  const fs::path old_csv = d / "old.csv";
  const std::string old_rows = "host,cpu,threads,median_ms\nvm,x,1,1.0\n";
  std::ofstream(old_csv) << old_rows;
  const Result refused = run("bench " + scenario + " --set run.duration=2 --csv " + old_csv.string() + " -q");
  CHECK(refused.code != 0);
  CHECK(refused.output.find("header") != std::string::npos);
  CHECK(fs::file_size(old_csv) == old_rows.size());
  CHECK(fs::exists(csv));
  CHECK(run("bench " + scenario + " --engine nosuch").code == 2);
  CHECK(run("bench " + (d / "missing.toml").string()).code == 2);
  fs::remove_all(d);
}

namespace {
/// `floedem bench ARGS` under ENV (its CSV header and one row): the row's cells by column name.
std::map<std::string, std::string> bench_row(const std::string& args, const std::string& env) {
  const Result r = floedem::test::run_cli("bench " + args, env);
  REQUIRE(r.code == 0);
  const std::size_t eol = r.output.find('\n');
  REQUIRE(eol != std::string::npos);
  auto cells = [](const std::string& line) {
    std::vector<std::string> out(1);
    for (const char ch : line) {
      if (ch == ',')
        out.emplace_back();
      else
        out.back().push_back(ch);
    }
    return out;
  };
  const std::vector<std::string> header = cells(r.output.substr(0, eol));
  const std::vector<std::string> row = cells(r.output.substr(eol + 1, r.output.find('\n', eol + 1) - eol - 1));
  REQUIRE(header.size() == row.size());
  std::map<std::string, std::string> by_name;
  for (std::size_t k = 0; k < header.size(); ++k) by_name[header[k]] = row[k];
  return by_name;
}

/// A bench row's number in column `name` (which must be there).
double number(const std::map<std::string, std::string>& row, const std::string& name) {
  INFO("column " << name);
  REQUIRE(row.count(name) == 1);
  return std::stod(row.at(name));
}
}  // namespace

TEST_CASE("cli: no heap allocation in the steady state of a packed field", "[cli][allocations]") {
  // "no allocation per step in the steady state (checked)". The 1k field of the speed
  // benchmark is packed on its wall after about 100 s; over the last 50 s of 200, every list a
  // step uses has reached its size, so `floedem bench` (which counts malloc and its kin, and
  // operator new under a sanitizer) must count none, on one thread and on two (the pool's
  // per-block work lists). A list that is rebuilt each step, or one that grows without headroom
  // as the pack breathes, shows here. The direct solve of heavy-light islands (Eigen's sparse
  // LDLT), which still allocates, is not taken by this field of floes alone.
  const std::string scenario = std::string(FLOEDEM_SOURCE_DIR) + "/scenarios/bench/field_wall_1k.toml";
  // Under a sanitizer (which counts operator new alone, not malloc) the run is five times slower
  // and adds memory checks, not another count: the threaded path only, which has the pool's
  // lists besides the one-thread path's. The plain build checks both.
  const std::vector<const char*> thread_counts =
      floedem::kSanitizerAllocator ? std::vector<const char*>{"2"} : std::vector<const char*>{"1", "2"};
  for (const char* threads : thread_counts) {
    INFO("FLOEDEM_THREADS=" << threads);
    const auto row = bench_row(scenario + " --window 50 -q", std::string("FLOEDEM_THREADS=") + threads + " ");
    CHECK(number(row, "contact_fraction") > 0.95);  // packed: the state the check is about
    CHECK(number(row, "timed_steps") == 1000);
    CHECK(number(row, "allocations_per_step") == 0.0);
  }
  // The counter counts: timed from the first step, the lists' first growth shows.
  const auto first_steps = bench_row(scenario + " --set run.duration=5 -q", "FLOEDEM_THREADS=1 ");
  CHECK(number(first_steps, "allocations_per_step") > 0.0);
}
