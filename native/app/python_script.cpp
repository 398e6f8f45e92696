#include "app/python_script.hpp"

#include <spawn.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <iostream>

extern char** environ;

namespace floedem {

namespace {

/// Runs Python with `args` after the interpreter (`script(dir)`, the first of them, made from
/// the share/floedem found), share/floedem/python first on its module path: the package the
/// scripts and `python3 -m floedem` use is the one beside this command.
template <class First>
int run_python(const std::string& what, First script, const std::vector<std::string>& args) {
  const std::string python = FLOEDEM_PYTHON_EXE;
  if (python.empty()) {
    std::cerr << "floedem: error: " << what
              << " needs Python 3 with numpy, h5py and matplotlib, which the build did not find\n";
    return -1;
  }
  const std::string dir = data_dir();
  if (dir.empty()) {
    std::cerr << "floedem: error: cannot find share/floedem (the report's scripts, the Python package) beside "
              << own_executable() << " or above it; install with `cmake --install` or run the command from its "
              << "build directory\n";
    return -1;
  }
  const char* old = std::getenv("PYTHONPATH");
  const std::string path = dir + "/python" + (old && *old ? ":" + std::string(old) : std::string());
  setenv("PYTHONPATH", path.c_str(), 1);
  std::vector<std::string> all{python};
  const std::vector<std::string> first = script(dir);
  all.insert(all.end(), first.begin(), first.end());
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawn(&pid, python.c_str(), nullptr, nullptr, argv.data(), environ) != 0) {
    std::cerr << "floedem: error: cannot start " << python << "\n";
    return -1;
  }
  int status = 0;
  waitpid(pid, &status, 0);
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  return 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

}  // namespace

int run_python_script(const std::string& script, const std::vector<std::string>& args) {
  return run_python(
      script, [&](const std::string& dir) { return std::vector<std::string>{dir + "/reports/" + script}; }, args);
}

int run_python_module(const std::vector<std::string>& args) {
  return run_python(
      "the floedem Python package", [](const std::string&) { return std::vector<std::string>{"-m", "floedem"}; },
      args);
}

std::string data_dir() {
  namespace fs = std::filesystem;
  const fs::path bin = fs::path(own_executable()).parent_path();
  std::error_code ec;
  for (const fs::path& d : {bin / "share" / "floedem", bin.parent_path() / "share" / "floedem"})
    if (fs::is_directory(d / "reports", ec)) return d.string();
  return {};
}

std::string own_executable() {
  std::error_code ec;
  const auto p = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("floedem") : p.string();
}

}  // namespace floedem
