#pragma once
// The truncated power law of floe sizes (docs/model.md section 5): the number of floes larger than
// d falls as d^-alpha between d_min and d_max, d = sqrt(4 A / pi) the equal-area diameter.
//   survival   S(d) = (d^-alpha - d_max^-alpha) / (d_min^-alpha - d_max^-alpha)
//   density    p(d) = alpha d^-(alpha+1) / (d_min^-alpha - d_max^-alpha)
//   quantile   d(q) = (d_min^-alpha - q (d_min^-alpha - d_max^-alpha))^(-1/alpha),  q = 1 - S
#include <cstddef>
#include <span>
#include <vector>

namespace floedem {

struct TruncatedPowerLaw {
  double alpha = 2.0;
  double d_min = 1.0;
  double d_max = 100.0;

  double survival(double d) const;
  double quantile(double q) const;        ///< q in [0, 1]
  double mean_area() const;               ///< E[pi d^2 / 4], m^2
};

/// Sizes drawn by stratified quantiles, d_i = d((i + u) / N), i = 0..N-1, with one common
/// offset u in [0, 1] and N chosen so that the areas add up to `total_area` exactly (to
/// round-off). Stratification removes the sampling noise of independent draws: the sizes
/// follow the law as closely as N points can. The sum of the areas grows with u by exactly
/// A(d_max) - A(d_min) over [0, 1] (the sum telescopes), which is at least one mean floe
/// area, so consecutive N overlap and a solution always exists once total_area >= A(d_min).
/// Returned in increasing order.
std::vector<double> stratified_sizes(const TruncatedPowerLaw& law, double total_area);

/// Maximum-likelihood exponent of a truncated power law with known bounds
/// (Clauset, Shalizi and Newman 2009, with the truncation at d_max in the normalisation):
///   l(alpha) = N ln alpha - (alpha + 1) sum ln d_i - N ln(d_min^-alpha - d_max^-alpha),
/// concave in alpha (an exponential family in ln d), so its root of dl/dalpha is unique.
/// stderr = 1 / sqrt(-l''(alpha)) = 1 / sqrt(N Var[ln d]) at the estimate.
struct PowerLawFit {
  double alpha = 0.0;
  double stderr_alpha = 0.0;
  std::size_t n = 0;
};
PowerLawFit fit_truncated_power_law(std::span<const double> sizes, double d_min, double d_max);

}  // namespace floedem
