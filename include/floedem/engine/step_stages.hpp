#pragma once
// The stages of one step of a run on the native engine, in the order a step makes them: the one
// list that the stage clocks (Stepper, NativeEngine), `floedem bench --stages` (the stage_ms
// column), `floedem stages`, the report's speed section and docs/architecture.md
// all name. A new stage is one line here and one StageClock::time call where it runs; the test
// `docs: the stages of architecture.md are the code's` holds the document to this list.
#include <array>
#include <cstddef>

namespace floedem {

struct StepStage {
  const char* name;   ///< the stage_ms key
  const char* label;  ///< how the report's tables name it
  const char* what;   ///< what it does, in one line
};

inline constexpr std::array<StepStage, 12> kStepStages{{
    {"forcing", "forcing (environment terms)",
     "every force term evaluated on the state at the start of the step (run/stepper.cpp, forcing/)"},
    {"broad_phase", "broad phase",
     "bounds fattened by each body's reach this step; candidate pairs of parts from the coherent pair cache"},
    {"narrow_phase", "narrow phase",
     "each pair's contact manifold by separating axes and clipping, up to two points with feature ids"},
    {"contact_list", "contact list (warm start, classify)",
     "manifolds with contacts, last step's impulses carried by feature id, each point a collision or resting"},
    {"loads", "loads", "the forcing's loads change the velocities"},
    {"contact_solve", "contact solve (islands, sweeps)",
     "impulses island by island: Gauss-Seidel with the exact local law, NNCG, direct solve of heavy-light islands"},
    {"redetect", "redetect",
     "a body sent beyond its reach by the impulses: the step's contacts found and solved again"},
    {"integrate", "integrate", "positions and angles advanced with the velocities after the impulses"},
    {"position_projection", "position projection",
     "overlap beyond the allowed penetration removed on positions only (no velocity, no energy)"},
    {"record", "record", "the step's impulses as contact records; what the next contact list carries"},
    {"sleep", "sleep", "islands at rest for the sleep time fall asleep (held, not stepped) until touched or their loads change"},
    {"towing", "towing", "the tow's force and its ice part, before and after the engine's step (towing/tow.cpp)"},
}};

/// Index of a stage in kStepStages by name (a compile-time lookup; an unknown name fails to compile).
constexpr std::size_t step_stage(const char* name) {
  for (std::size_t k = 0; k < kStepStages.size(); ++k) {
    const char* a = kStepStages[k].name;
    const char* b = name;
    while (*a != '\0' && *a == *b) ++a, ++b;
    if (*a == *b) return k;
  }
  throw "no such stage";
}

/// The names of the N stages from `first` on, as a StageClock takes them.
template <std::size_t N>
constexpr std::array<const char*, N> step_stage_names(std::size_t first) {
  std::array<const char*, N> out{};
  for (std::size_t k = 0; k < N; ++k) out[k] = kStepStages[first + k].name;
  return out;
}

}  // namespace floedem
