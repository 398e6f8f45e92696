#include "app/field_command.hpp"
#include "app/python_script.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "floedem/field/field_file.hpp"
#include "floedem/scene/input_error.hpp"
#include "floedem/version.hpp"

namespace floedem {
namespace {

/// The command-line flag for a FieldSpec parameter named in a FieldSpecError.
std::string flag_of(const std::string& parameter) {
  if (parameter == "d_min") return "--dmin";
  if (parameter == "d_max") return "--dmax";
  if (parameter.starts_with("thickness")) return "--thickness";
  if (parameter.starts_with("keep_out")) return "--keep-out";
  return "--" + parameter;
}

std::vector<Vec2> parse_polygon(const std::string& text) {
  std::vector<Vec2> out;
  std::istringstream in(text);
  std::string pair;
  while (in >> pair) {
    const auto comma = pair.find(',');
    try {
      if (comma == std::string::npos) throw std::invalid_argument("no comma");
      std::size_t used = 0;
      const double x = std::stod(pair.substr(0, comma), &used);
      if (used != comma) throw std::invalid_argument("x");
      const std::string ys = pair.substr(comma + 1);
      const double y = std::stod(ys, &used);
      if (used != ys.size()) throw std::invalid_argument("y");
      out.push_back({x, y});
    } catch (const std::exception&) {
      throw InputError("--keep-out: '" + pair + "' is not a vertex; allowed \"x,y x,y x,y ...\" (at least 3)");
    }
  }
  return out;
}

/// Runs the figure script: FIELD.png (the floes) and FIELD-sizes.png (size survival, fit).
int draw(const std::string& field_file, const std::string& png) {
  const int status = run_python_script("plot_field.py", {field_file, "--out", png});
  if (status == 0) return 0;
  if (status > 0)
    std::cerr << "floedem: error: reports/plot_field.py failed; the field file " << field_file << " is complete\n";
  return 1;
}

}  // namespace

CLI::App* add_field_command(CLI::App& app, FieldCommand& c) {
  CLI::App* f = app.add_subcommand(
      "field", "generate a broken-ice field (power-law floe sizes at a given concentration) into a field file");
  f->add_option("--width", c.spec.width, "domain width, m")->required();
  f->add_option("--height", c.spec.height, "domain height, m")->required();
  f->add_option("--concentration", c.spec.concentration, "ice area / free area, in (0, 0.99]")->required();
  f->add_option("--alpha", c.spec.alpha, "exponent of the size survival function N(>d) ~ d^-alpha, in (0, 10]")
      ->required();
  f->add_option("--dmin", c.spec.d_min, "smallest floe (equal-area diameter), m")->required();
  f->add_option("--dmax", c.spec.d_max, "largest floe (equal-area diameter), m")->required();
  f->add_option("--thickness", c.spec.thickness.value, "floe thickness, m (the mean with --thickness-std)")
      ->required();
  f->add_option("--thickness-std", c.thickness_std, "standard deviation of a lognormal thickness, m (default 0: constant)");
  f->add_option("--irregularity", c.spec.irregularity, "floe shape irregularity in [0, 1]")->capture_default_str();
  f->add_option("--seed", c.spec.seed, "random seed")->capture_default_str();
  f->add_option("--origin", c.origin, "lower-left corner of the domain, X Y in m")->expected(2);
  f->add_option("--keep-out", c.keep_out, "a polygon kept free of ice, \"x,y x,y x,y ...\"; repeatable");
  f->add_option("--density", c.density, "ice density, kg/m^3")->capture_default_str();
  f->add_option("--out,-o", c.out, "field file to write (HDF5, the /bodies layout of a run's output)")->required();
  f->add_option("--plot", c.plot, "also draw the field to this PNG, and the size distribution beside it (-sizes.png)");
  f->add_flag("--quiet,-q", c.quiet, "print nothing but errors");
  return f;
}

int run_field_command(FieldCommand& c) {
  if (!c.origin.empty()) c.spec.origin = {c.origin[0], c.origin[1]};
  if (c.thickness_std > 0.0) {
    c.spec.thickness.kind = ThicknessDistribution::Kind::lognormal;
    c.spec.thickness.mean = c.spec.thickness.value;
    c.spec.thickness.std = c.thickness_std;
  } else if (!(c.thickness_std == 0.0)) {
    throw InputError("--thickness-std: is " + std::to_string(c.thickness_std) + "; allowed [0, inf)");
  }
  if (!(c.density > 0.0) || !std::isfinite(c.density))
    throw InputError("--density: is " + std::to_string(c.density) + "; allowed (0, inf)");
  for (std::size_t k = 0; k < c.keep_out.size(); ++k) {
    c.spec.keep_out.push_back(parse_polygon(c.keep_out[k]));
    c.spec.keep_out_names.push_back("--keep-out #" + std::to_string(k + 1));
  }
  const auto t0 = std::chrono::steady_clock::now();
  Field field;
  try {
    field = generate_field(c.spec);
  } catch (const FieldSpecError& e) {
    throw InputError(flag_of(e.parameter()) + ": " + e.what());
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  write_field_file(c.out, field, c.spec, c.density, std::string(version()));
  if (!c.quiet) {
    const FieldStats& s = field.stats;
    std::printf("%s: %zu floes, concentration %.6f (target %.6f), alpha fitted %.4f +- %.4f (target %.4f), %.2f s\n",
                c.out.c_str(), s.floes, s.concentration, c.spec.concentration, s.fit.alpha, s.fit.stderr_alpha,
                c.spec.alpha, seconds);
  }
  if (!c.plot.empty()) return draw(c.out, c.plot);
  return 0;
}

}  // namespace floedem
