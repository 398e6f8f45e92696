// Files a user gives floedem (a field file or a run's output read as a field, a run to resume)
// are checked as a scenario's text is: each damaged one below is refused by `floedem run` with
// exit 2 and one line naming the file and the dataset, and nothing is written or changed.
#include <catch2/catch.hpp>

#include <H5Cpp.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>

#include "floedem/io/output.hpp"
#include "floedem/run/simulation.hpp"
#include "floedem/scene/input_error.hpp"
#include "floedem/version.hpp"
#include "support.hpp"

using namespace floedem;
namespace fs = std::filesystem;

namespace {

/// Two moving floes, a square and a triangle, 1 s at dt 0.01 s: a complete run's output.
const std::string kTwoFloes = test::header_toml(1.0, 0.01, 0.3, 0.3) +
                           test::body_toml({"a", test::box({5, 5}, 10, 10), {0.2, 0.0}}) +
                           test::body_toml({"b", {{20.5, 0}, {30.5, 0}, {20.5, 12}}, {}, 0.1});

std::vector<double> read_doubles(H5::H5File& f, const std::string& name) {
  H5::DataSet ds = f.openDataSet(name);
  std::vector<double> v(static_cast<std::size_t>(ds.getSpace().getSimpleExtentNpoints()));
  ds.read(v.data(), H5::PredType::NATIVE_DOUBLE);
  return v;
}

void write_doubles(H5::H5File& f, const std::string& name, const std::vector<double>& v) {
  f.openDataSet(name).write(v.data(), H5::PredType::NATIVE_DOUBLE);
}

void set_offset(H5::H5File& f, std::size_t at, std::int64_t value) {
  H5::DataSet ds = f.openDataSet("/bodies/polygon_offsets");
  std::vector<std::int64_t> v(static_cast<std::size_t>(ds.getSpace().getSimpleExtentNpoints()));
  ds.read(v.data(), H5::PredType::NATIVE_INT64);
  v.at(at) = value;
  ds.write(v.data(), H5::PredType::NATIVE_INT64);
}

/// Replaces a dataset by one of doubles of another shape (the same values, as far as they go).
void reshape(H5::H5File& f, const std::string& name, const std::vector<hsize_t>& dims) {
  std::vector<double> v = read_doubles(f, name);
  f.unlink(name);
  hsize_t n = 1;
  for (const hsize_t d : dims) n *= d;
  v.resize(n, 0.0);
  H5::DataSpace space(static_cast<int>(dims.size()), dims.data());
  f.createDataSet(name, H5::PredType::NATIVE_DOUBLE, space).write(v.data(), H5::PredType::NATIVE_DOUBLE);
}

void set_root_text(H5::H5File& f, const std::string& name, const std::string& value) {
  H5::Group root = f.openGroup("/");
  root.removeAttr(name);
  H5::StrType type(H5::PredType::C_S1, H5T_VARIABLE);
  root.createAttribute(name, type, H5::DataSpace(H5S_SCALAR)).write(type, value);
}

struct Damage {
  const char* what;
  const char* dataset;  ///< expected in the message
  std::function<void(H5::H5File&)> apply;
};

const Damage kFieldDamage[] = {
    {"a negative offset", "/bodies/polygon_offsets", [](H5::H5File& f) { set_offset(f, 1, -5); }},
    {"offsets not starting at 0", "/bodies/polygon_offsets", [](H5::H5File& f) { set_offset(f, 0, 1); }},
    {"offsets beyond the vertices", "/bodies/polygon_offsets", [](H5::H5File& f) { set_offset(f, 2, 1000); }},
    {"one-dimensional vertices", "/bodies/polygon_vertices",
     [](H5::H5File& f) { reshape(f, "/bodies/polygon_vertices", {14}); }},
    {"a negative thickness", "/bodies/thickness",
     [](H5::H5File& f) { write_doubles(f, "/bodies/thickness", {-1.0, 1.0}); }},
    {"a zero density", "/bodies/density", [](H5::H5File& f) { write_doubles(f, "/bodies/density", {900.0, 0.0}); }},
    {"a NaN velocity", "/bodies/velocity",
     [](H5::H5File& f) {
       std::vector<double> v = read_doubles(f, "/bodies/velocity");
       v.back() = std::nan("");
       write_doubles(f, "/bodies/velocity", v);
     }},
    {"an infinite vertex", "/bodies/polygon_vertices",
     [](H5::H5File& f) {
       std::vector<double> v = read_doubles(f, "/bodies/polygon_vertices");
       v[3] = INFINITY;
       write_doubles(f, "/bodies/polygon_vertices", v);
     }},
    {"a self-intersecting outline", "/bodies/polygon_vertices",
     [](H5::H5File& f) {
       std::vector<double> v = read_doubles(f, "/bodies/polygon_vertices");
       std::swap(v[0], v[2]);  // the square's first two vertices swapped: a bow tie
       std::swap(v[1], v[3]);
       write_doubles(f, "/bodies/polygon_vertices", v);
     }},
    {"a missing dataset", "/bodies/density", [](H5::H5File& f) { f.unlink("/bodies/density"); }},
    {"fixed as floating point", "/bodies/fixed",
     [](H5::H5File& f) {
       f.unlink("/bodies/fixed");
       const hsize_t n = 2;
       const double v[2] = {0.0, 0.0};
       f.createDataSet("/bodies/fixed", H5::PredType::NATIVE_DOUBLE, H5::DataSpace(1, &n))
           .write(v, H5::PredType::NATIVE_DOUBLE);
     }},
    {"positions of another shape", "/bodies/position",
     [](H5::H5File& f) { reshape(f, "/bodies/position", {2, 3, 2}); }},
    {"a newer format", "/@format_version",
     [](H5::H5File& f) {
       const std::int64_t newer = kOutputFormatVersion + 1;
       f.openAttribute("format_version").write(H5::PredType::NATIVE_INT64, &newer);
     }},
    {"format_version as text", "/@format_version", [](H5::H5File& f) { set_root_text(f, "format_version", "1"); }},
    {"an unfinished run", "/@status", [](H5::H5File& f) { set_root_text(f, "status", "running"); }},
};

const Damage kResumeDamage[] = {
    {"a negative mass", "/bodies/mass", [](H5::H5File& f) { write_doubles(f, "/bodies/mass", {-1.0, 1.0}); }},
    {"angles of another shape", "/bodies/angle", [](H5::H5File& f) { reshape(f, "/bodies/angle", {3}); }},
    {"a missing contact table", "/contacts/normal", [](H5::H5File& f) { f.unlink("/contacts/normal"); }},
    {"the duration as an array", "/@duration",
     [](H5::H5File& f) {
       H5::Group root = f.openGroup("/");
       root.removeAttr("duration");
       const hsize_t n = 3;
       const double v[3] = {1.0, 2.0, 3.0};
       root.createAttribute("duration", H5::PredType::NATIVE_DOUBLE, H5::DataSpace(1, &n))
           .write(H5::PredType::NATIVE_DOUBLE, v);
     }},
    {"a newer format", "/@format_version",
     [](H5::H5File& f) {
       const std::int64_t newer = kOutputFormatVersion + 1;
       f.openAttribute("format_version").write(H5::PredType::NATIVE_INT64, &newer);
     }},
};

/// The output of kTwoFloes, complete, at `path`; `duration` 50 s records 5000 frames, past the
/// first checkpoint (a full chunk of 4096 frames for two bodies).
void write_run(const fs::path& dir, const std::string& path, double duration = 1.0) {
  std::ofstream(dir / "run.toml") << kTwoFloes;
  REQUIRE(test::run_cli("run -q " + (dir / "run.toml").string() + " -o " + path + " --set run.duration=" +
                        std::to_string(duration)).code == 0);
}

void damage(const std::string& path, const Damage& d) {
  H5::H5File f(path, H5F_ACC_RDWR);
  d.apply(f);
}

/// One line, exit 2, naming the file and the dataset.
void check_refusal(const test::CliResult& r, const std::string& file, const Damage& d) {
  INFO(r.output);
  CHECK(r.code == 2);
  CHECK(std::count(r.output.begin(), r.output.end(), '\n') == 1);
  CHECK(r.output.find(file) != std::string::npos);
  CHECK(r.output.find(d.dataset) != std::string::npos);
}

}  // namespace

TEST_CASE("damaged field files are refused with file, dataset and what was expected, and nothing written",
          "[io][bad-input]") {
  const fs::path dir = test::temp_dir("damaged-field");
  const std::string good = (dir / "good.h5").string();
  write_run(dir, good);
  std::ofstream(dir / "field.toml") << "[run]\nduration = 1.0\ndt = 0.01\n[field]\nfile = \"field.h5\"\n";
  const std::string field = (dir / "field.h5").string();
  const std::string out = (dir / "out.h5").string();
  // The undamaged file is read as a field.
  fs::copy_file(good, field);
  REQUIRE(test::run_cli("run -q " + (dir / "field.toml").string() + " -o " + out).code == 0);
  fs::remove(out);
  for (const Damage& d : kFieldDamage) {
    INFO(d.what);
    fs::remove(field);
    fs::copy_file(good, field);
    damage(field, d);
    check_refusal(test::run_cli("run -q " + (dir / "field.toml").string() + " -o " + out), field, d);
    CHECK_FALSE(fs::exists(out));
    CHECK_FALSE(fs::exists(out + ".partial"));
    // The library says the same (InputError, with the dataset).
    try {
      read_body_frame(field);
      FAIL("read");
    } catch (const InputError& e) {
      CHECK(std::string(e.what()).find(d.dataset) != std::string::npos);
    }
  }
  // Not HDF5 at all, and an HDF5 file cut short.
  std::ofstream(field, std::ios::trunc) << "not a field\n";
  const auto text = test::run_cli("run -q " + (dir / "field.toml").string() + " -o " + out);
  CHECK(text.code == 2);
  CHECK(text.output.find("not an HDF5 file") != std::string::npos);
  fs::remove(field);
  fs::copy_file(good, field);
  fs::resize_file(field, fs::file_size(field) / 2);
  const auto cut = test::run_cli("run -q " + (dir / "field.toml").string() + " -o " + out);
  INFO(cut.output);
  CHECK(cut.code == 2);
  CHECK(std::count(cut.output.begin(), cut.output.end(), '\n') == 1);
  CHECK(cut.output.find(field) != std::string::npos);
  CHECK_FALSE(fs::exists(out));
  fs::remove_all(dir);
}

TEST_CASE("damaged runs given to --resume are refused with file and dataset, the file left as it was",
          "[io][resume][bad-input]") {
  const fs::path dir = test::temp_dir("damaged-resume");
  const std::string good = (dir / "good.h5").string();
  write_run(dir, good, 50.0);
  REQUIRE(read_stored_run(good).checkpoint);
  const std::string run = (dir / "r.h5").string();
  for (const Damage& d : kResumeDamage) {
    INFO(d.what);
    fs::remove(run);
    fs::copy_file(good, run);
    damage(run, d);
    const auto before = fs::last_write_time(run);
    check_refusal(test::run_cli("run -q --resume " + run + " --set run.duration=60"), run, d);
    CHECK(fs::exists(run));
    CHECK_FALSE(fs::exists(run + ".partial"));
    CHECK(fs::last_write_time(run) == before);
  }
  fs::remove_all(dir);
}
