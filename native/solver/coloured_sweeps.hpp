#pragma once
// Gauss-Seidel sweeps in colour order, four manifolds side by side: the order the native engine
// gives an island of `coloured_from` manifolds or more (contact_solver.cpp sweeps smaller ones
// in pair order; docs/architecture.md says why both are kept).
//
// The sweeps in pair order update point after point, each reading the velocities the one before
// it wrote. A pair list sorted by part puts a floe's contacts one after another, so each update
// waits for the last one's stores, and the local solve's branches (separating, stick, slide
// either way) are taken at random: most of a point's time is waiting. Greedy graph colouring of the manifolds (Box2D v3's constraint graph colouring;
// greedy colouring: Welsh and Powell 1967) gives each manifold the lowest colour that no other
// manifold of either of its moving bodies took. Within a colour no two manifolds share a moving
// body, so their updates commute: four of them (a bundle) are solved at once, lane by lane in
// SIMD vectors, the local solve's cases all computed and the right one selected (no branch).
// A manifold's two points are solved one after the other (a near block solve; solving every
// first point before every second point cost convergence). Fixed and towed bodies are
// only read (as apply_impulse) and take no colour. A body with more than 63 manifolds sends the
// rest to a last group, one manifold a bundle, swept in order.
//
// It is another Gauss-Seidel order of the same points with the same local law (local_law.hpp,
// the pair order's, lane by lane: the same bits for the same inputs), so it converges to the
// same solution; after a given number of sweeps its impulses differ from the pair order's (a
// different order, not a faster way to the pair order's bits).
// Each lane's arithmetic is IEEE double, no fused multiply-add (CMakeLists), so the result is
// the same on any x86-64, with or without AVX2 or AVX-512, and on any number of threads (a
// large island's colours are swept in fixed blocks on the pool's threads). docs/performance.md
// has how it compares with the pair order.
#include <cstdint>
#include <span>
#include <vector>

#include "solver/solver_types.hpp"

namespace floedem {

/// A coloured solve of at least this many manifolds is worth the pool's threads: its packing
/// into bundles runs on them (on one thread it is a serial part of a packed field's step that
/// the threads could not shorten), and the native engine solves such an island
/// alone on every thread rather than as one task among the islands.
constexpr std::size_t kColouredOnThreads = 4096;

/// The coloured solve of the manifolds `island` (indices into `manifolds`, in order; empty: all
/// of them): solve_velocities with SweepOptions::colour. `space` needs bundles and slots for
/// the manifolds, the scene's body_colours (all zero, and left so) and, with `accelerate`,
/// bundle_change/direction, moving_bodies and body_steps (SweepWork::reserve with colour_bodies).
/// `options` as SweepOptions says (its `colour` is implied): with `threads`, each colour's
/// bundles are swept on the pool's threads (not from inside a loop of the pool), and a solve of
/// 4 096 manifolds or more is packed into its bundles there too: the same impulses to the bit
/// as without. Without `accelerate`, each colour's manifolds of two points take its first
/// bundles unless `given_order` (the same impulses to the bit, in fewer bundle-points:
/// coloured_sweeps.cpp).
int solve_coloured(std::span<Manifold> manifolds, std::span<const std::int32_t> island, BodyArrays& bodies,
                   const SweepLimits& limits, const SweepSpace& space, const SweepOptions& options);

/// The colours solve_coloured gives the manifolds `island` (its first pass, made apart): each
/// manifold's colour into colours[i] (with a flag for a manifold of two points: values for
/// solve_coloured to read), body_colours all zero again on return. Returns the
/// bundles they take, so that a caller can give each island's solve the room it needs, and the
/// solve the colours (SweepSpace::colours_given).
std::size_t colour_manifolds(std::span<Manifold> manifolds, std::span<const std::int32_t> island,
                             const BodyArrays& bodies, std::span<std::int32_t> colours,
                             std::span<std::uint64_t> body_colours);

// The sweep is built for each LaneIsa (geometry/lane_isa.hpp): the same impulses to the bit.

}  // namespace floedem
