#pragma once
// Broken-ice field generator (docs/model.md section 5): a rectangular domain filled with
// non-overlapping, randomly shaped convex floes at a given concentration, whose equal-area
// diameters follow a truncated power law.
//
// Method (a capacity-constrained power diagram):
//  1. sizes d_i by stratified quantiles of the law, their areas A_i adding up to C F exactly
//     (F: the free area, the domain minus keep-out zones);
//  2. random sites in the free area; weights w_i found by Newton's method so that each power
//     cell {x : |x - s_i|^2 - w_i <= |x - s_j|^2 - w_j for all j} has free area A_i / C
//     (semi-discrete optimal transport; Kitagawa, Merigot and Thibert 2019, damped Newton);
//  3. a few Lloyd steps moving each site towards its cell's centroid (fewer and shorter with
//     more irregularity), re-solving the weights after each;
//  4. each cell (convex, inside the domain, disjoint from the others) shrunk about its centroid
//     to area A_i: the floe. It lies inside its own cell, so no two floes overlap, and the
//     concentration is C to round-off.
//  5. the floes numbered along a Hilbert curve through their centroids (neighbours near in
//     number, so near in the engines' memory).
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "floedem/field/size_distribution.hpp"
#include "floedem/geometry/vec2.hpp"

namespace floedem {

/// Floe thickness: one value, or drawn per floe.
struct ThicknessDistribution {
  enum class Kind : std::uint8_t { constant, uniform, lognormal };
  Kind kind = Kind::constant;
  double value = 1.0;           ///< m (constant)
  double min = 0.0, max = 0.0;  ///< m (uniform)
  double mean = 0.0, std = 0.0; ///< m, of the thickness itself (lognormal)
};

struct FieldSpec {
  Vec2 origin;                   ///< m, lower-left corner of the domain
  double width = 0.0;            ///< m
  double height = 0.0;           ///< m
  double concentration = 0.0;    ///< ice area / free area, in (0, max_concentration]
  double alpha = 2.0;            ///< power-law exponent of the size survival function
  double d_min = 0.0;            ///< m, smallest equal-area diameter
  double d_max = 0.0;            ///< m, largest
  ThicknessDistribution thickness;
  double irregularity = 0.5;     ///< 0: rounder, more regular floes ... 1: raw random cells
  std::uint64_t seed = 1;
  std::vector<std::vector<Vec2>> keep_out;  ///< simple polygons (concave allowed) kept free of ice
  std::vector<std::string> keep_out_names;  ///< for messages; "keep_out[k]" where not given

  /// Highest concentration accepted: the weights are solved to a relative cell-area error of
  /// 1e-6, far inside the 1 % margin this leaves, but above 0.99 the gaps between floes (a
  /// fraction 1 - sqrt(C) of each cell's radius) shrink below a few centimetres for metre-
  /// scale floes, and the field is a jam rather than broken ice.
  static constexpr double max_concentration = 0.99;
  /// Most floes one field may hold (memory and time grow with each: about 1 KB a floe).
  static constexpr double max_floes = 2e7;
};

/// Bad field parameters: `parameter` is the FieldSpec member's name ("concentration",
/// "d_min", "keep_out[2]", ...), so that callers can name their own key or flag.
class FieldSpecError : public std::runtime_error {
 public:
  FieldSpecError(std::string parameter, const std::string& what)
      : std::runtime_error(what), parameter_(std::move(parameter)) {}
  const std::string& parameter() const { return parameter_; }

 private:
  std::string parameter_;
};

struct FieldStats {
  std::size_t floes = 0;
  double free_area = 0.0;             ///< m^2, domain minus keep-out zones
  double ice_area = 0.0;              ///< m^2
  double concentration = 0.0;         ///< achieved: ice_area / free_area
  PowerLawFit fit;                    ///< exponent fitted to the floes' equal-area diameters
  int newton_iterations = 0;          ///< total over all weight solves
  int lloyd_steps = 0;
  double max_cell_area_error = 0.0;   ///< relative, of the last weight solve
  std::size_t floes_short_of_area = 0;///< floes cut smaller by a keep-out zone, kept (at least d_min)
  std::size_t floes_dropped_below_d_min = 0;///< cells a keep-out zone cut below a floe of d_min: no floe
};

struct Field {
  std::vector<std::vector<Vec2>> floes;  ///< counter-clockwise, strictly convex, world coordinates
  std::vector<double> thickness;         ///< m, per floe
  FieldStats stats;
};

/// Throws FieldSpecError for the first parameter out of range (every bound in the message).
void check_field_spec(const FieldSpec& spec);

/// Checks the spec, then generates. The same spec (seed included) gives the identical field.
Field generate_field(const FieldSpec& spec);

}  // namespace floedem
