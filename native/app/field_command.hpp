#pragma once
// `floedem field`: generate a broken-ice field into a field file (and optionally draw it).
#include <CLI/CLI.hpp>

#include <string>
#include <vector>

#include "floedem/field/field_generator.hpp"

namespace floedem {

struct FieldCommand {
  FieldSpec spec;
  double thickness_std = 0.0;          ///< > 0: lognormal thickness with this standard deviation
  std::vector<std::string> keep_out;   ///< polygons as "x,y x,y x,y ..."
  std::vector<double> origin;
  double density = 900.0;
  std::string out, plot;
  bool quiet = false;
};

CLI::App* add_field_command(CLI::App& app, FieldCommand& c);
/// Throws InputError (exit 2) naming the flag, OutputError (exit 3); returns the exit code.
int run_field_command(FieldCommand& c);

}  // namespace floedem
