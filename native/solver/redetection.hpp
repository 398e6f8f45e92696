#pragma once
// The redetect stage. A body the impulses sent further than its reach may meet one the pairs
// did not include (a floe struck at 5 m/s crosses a 5 cm gap to the next in one 0.01 s step),
// or reach a point of a pair that was beyond the margin (a floe spun by a collision swings its
// far corner into its neighbour): where the widened reach shows such a contact, the step's
// contacts are found again, and the islands that the widened reaches can touch solved again;
// the rest keep their solution to the bit.
#include <cstdint>
#include <vector>

#include "solver/contact_pipeline.hpp"
#include "solver/island_stage.hpp"
#include "solver/sleep_sets.hpp"
#include "solver/step_context.hpp"

namespace floedem {

class Redetection {
 public:
  explicit Redetection(const StepContext& ctx);

  /// After the contact solve: as many passes as bodies keep outrunning their reach into unseen
  /// contacts, up to kMaxPasses.
  void run(StepContext& ctx, ContactPipeline& pipeline, IslandStage& islands, SleepSets& sleep);
  std::int64_t count() const { return redetections_; }  ///< steps whose contacts were found again
  void restore_count(std::int64_t count) { redetections_ = count; }

 private:
  static constexpr int kMaxPasses = 4;  // a struck floe striking the next, and so on

  bool outran_reach(StepContext& ctx, const ContactPipeline& pipeline, const ContactIslands& islands);
  // Each part of a body of outran_list_ against each part whose box at the present reaches
  // overlaps its own (the pairs that a broad phase at those reaches finds), until visit(k, j),
  // k the outrun part, returns true; whether one did.
  template <class Visit>
  bool visit_parts_near_outrun(const StepContext& ctx, const ContactPipeline& pipeline, Visit&& visit);
  bool meets_unseen_contact(const StepContext& ctx, const ContactPipeline& pipeline);
  // The step's contacts found and solved again where outran_list_'s bodies widened their reach:
  // only the islands they can touch are solved again, the rest keep their solution.
  void redetect(StepContext& ctx, ContactPipeline& pipeline, IslandStage& islands, SleepSets& sleep);
  void mark_for_resolve(const StepContext& ctx, const ContactIslands& islands, std::int32_t body);
  bool unmarked_contacts_held(const StepContext& ctx, const ContactPipeline& pipeline) const;
  void keep_solved_contacts(ContactPipeline& pipeline);

  std::vector<std::uint8_t> outran_;       // per body: its impulses sent it beyond its reach this step
  std::vector<std::int32_t> outran_list_;  // ... those bodies
  std::vector<std::int32_t> near_;         // parts near an outrun part's widened box
  // A redetection's reach: per body, its island at the last solve (-1: none) and whether it is
  // in an island solved again (those bodies listed); per island of the last solve, whether it
  // is; the contact list as last solved, kept for the islands not solved again and for the
  // classification of the points it held.
  std::vector<std::int32_t> body_island_;
  std::vector<std::uint8_t> resolve_;
  std::vector<std::int32_t> resolve_list_;
  std::vector<std::uint8_t> island_resolved_;
  LineVector<Manifold> solved_;
  std::int64_t redetections_ = 0;
};

}  // namespace floedem
