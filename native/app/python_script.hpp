#pragma once
// The figure and report scripts of reports/, run with the Python the build found
// (Debian's python3 with numpy, h5py and matplotlib).
#include <string>
#include <vector>

namespace floedem {

/// Runs share/floedem/reports/SCRIPT with the arguments, waits for it; its output goes to ours. Returns its
/// exit status, or -1 with a message on stderr when Python is missing or cannot start.
int run_python_script(const std::string& script, const std::vector<std::string>& args);

/// Runs `python3 -m floedem ARGS` (export, animate) with share/floedem/python on the module
/// path, waits for it; its exit status, or -1 with a message.
int run_python_module(const std::vector<std::string>& args);

/// share/floedem (the report's scripts and the scenarios), found from this executable's path:
/// BIN/share/floedem in the build tree, BIN/../share/floedem installed; empty when neither is.
std::string data_dir();

/// This executable's own path (for scripts that call floedem back).
std::string own_executable();

}  // namespace floedem
