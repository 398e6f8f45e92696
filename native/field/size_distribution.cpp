#include "floedem/field/size_distribution.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace floedem {
namespace {

double area_of(double d) { return std::numbers::pi / 4.0 * d * d; }

/// Sum of the stratified areas for N strata and offset u.
double stratified_total(const TruncatedPowerLaw& law, std::size_t n, double u) {
  double s = 0.0;
  for (std::size_t i = 0; i < n; ++i) s += area_of(law.quantile((static_cast<double>(i) + u) / static_cast<double>(n)));
  return s;
}

}  // namespace

double TruncatedPowerLaw::survival(double d) const {
  if (d <= d_min) return 1.0;
  if (d >= d_max) return 0.0;
  const double lo = std::pow(d_min, -alpha), hi = std::pow(d_max, -alpha);
  return (std::pow(d, -alpha) - hi) / (lo - hi);
}

double TruncatedPowerLaw::quantile(double q) const {
  if (q <= 0.0) return d_min;
  if (q >= 1.0) return d_max;
  const double lo = std::pow(d_min, -alpha), hi = std::pow(d_max, -alpha);
  return std::clamp(std::pow(lo - q * (lo - hi), -1.0 / alpha), d_min, d_max);
}

double TruncatedPowerLaw::mean_area() const {
  // E[d^2] = alpha / (d_min^-alpha - d_max^-alpha) * integral_{d_min}^{d_max} d^(1 - alpha) dd
  const double z = std::pow(d_min, -alpha) - std::pow(d_max, -alpha);
  const double integral = std::abs(alpha - 2.0) < 1e-12
                              ? std::log(d_max / d_min)
                              : (std::pow(d_max, 2.0 - alpha) - std::pow(d_min, 2.0 - alpha)) / (2.0 - alpha);
  return std::numbers::pi / 4.0 * alpha / z * integral;
}

std::vector<double> stratified_sizes(const TruncatedPowerLaw& law, double total_area) {
  if (!(total_area >= area_of(law.d_min)))
    throw std::invalid_argument("stratified_sizes: the total area is below one floe of d_min");
  // N near total / E[A]; then the N whose range [S_N(0), S_N(1)] holds the total.
  auto n = static_cast<std::size_t>(std::max(1.0, std::floor(total_area / law.mean_area())));
  for (int guard = 0;; ++guard) {
    if (guard > 10000) throw std::runtime_error("stratified_sizes: no stratum count reaches the total area");
    if (stratified_total(law, n, 1.0) < total_area) {
      ++n;
    } else if (stratified_total(law, n, 0.0) > total_area) {
      if (n == 1) break;
      --n;
    } else {
      break;
    }
  }
  // Bisection on u: the total is increasing in u.
  double lo = 0.0, hi = 1.0;
  for (int k = 0; k < 60; ++k) {
    const double mid = 0.5 * (lo + hi);
    (stratified_total(law, n, mid) < total_area ? lo : hi) = mid;
  }
  const double u = 0.5 * (lo + hi);
  std::vector<double> d(n);
  for (std::size_t i = 0; i < n; ++i) d[i] = law.quantile((static_cast<double>(i) + u) / static_cast<double>(n));
  return d;
}

PowerLawFit fit_truncated_power_law(std::span<const double> sizes, double d_min, double d_max) {
  PowerLawFit fit;
  fit.n = sizes.size();
  if (sizes.empty()) return fit;
  const double n = static_cast<double>(sizes.size());
  double sum_log = 0.0;
  for (const double d : sizes) sum_log += std::log(d);
  const double la = std::log(d_min), lb = std::log(d_max);
  // E_alpha[ln d] and Var_alpha[ln d] of the truncated law: derivatives of ln Z(alpha),
  // Z = (d_min^-alpha - d_max^-alpha) / alpha.
  auto mean_log = [&](double a) {
    const double x = std::exp(-a * (lb - la));  // (d_max / d_min)^-alpha
    // E[ln d] = 1/a + (ln d_min - x ln d_max) / (1 - x)
    return 1.0 / a + (la - x * lb) / (1.0 - x);
  };
  // dl/dalpha = N (E_alpha[ln d] - mean ln d_i): E_alpha[ln d] decreases in alpha.
  const double target = sum_log / n;
  double lo = 1e-6, hi = 50.0;
  for (int k = 0; k < 200; ++k) {
    const double mid = 0.5 * (lo + hi);
    (mean_log(mid) > target ? lo : hi) = mid;
  }
  fit.alpha = 0.5 * (lo + hi);
  // Var[ln d] = -d E[ln d] / d alpha, numerically.
  const double h = 1e-5 * fit.alpha;
  const double var = -(mean_log(fit.alpha + h) - mean_log(fit.alpha - h)) / (2.0 * h);
  fit.stderr_alpha = var > 0.0 ? 1.0 / std::sqrt(n * var) : 0.0;
  return fit;
}

}  // namespace floedem
