#pragma once
// floedem run --resume RESULT.h5: continues a run, killed or finished, from its last
// checkpoint, so that the file ends as the file of a run never interrupted would (every
// dataset and attribute the same, to the bit; the HDF5 file's own layout may differ).
#include <string>
#include <vector>

#include "floedem/run/simulation.hpp"

namespace floedem {

struct ResumeResult {
  bool ran = false;     ///< false: the run was complete and not lengthened; nothing was done
  std::string message;  ///< what was done, for the user
  RunSummary summary;
  Scene scene;          ///< the scene as rebuilt from the file
  std::string summary_output;  ///< the run's file (its final name)
};

/// `path`: the run's output (RESULT.h5, or RESULT.h5.partial for a run that did not finish).
/// `overrides`: only run.duration=T (a longer run; anything else would not continue the same
/// run). The scene is rebuilt from the scenario text stored in the file. Throws InputError
/// (no such run, not a floedem file, another scene, a damaged checkpoint), OutputError,
/// SolverFailure and RunStopped as run_scene; `stop` as RunOptions::stop.
ResumeResult resume_run(const std::string& path, const std::vector<std::string>& overrides, bool progress,
                        const std::atomic<bool>* stop = nullptr);

}  // namespace floedem
