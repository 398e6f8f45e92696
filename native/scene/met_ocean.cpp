#include "floedem/scene/met_ocean.hpp"

#include <algorithm>
#include <cmath>

#include "floedem/scene/scene.hpp"

namespace floedem {

namespace {
struct Standard {
  const char* name;
  double speed;  // deg per mean solar hour
};
// The constituents' angular speeds from their Doodson numbers (Pugh 1987, "Tides, Surges and
// Mean Sea-Level", chapter 4; the same in Foreman's tidal analysis tables): period = 360 / speed h.
constexpr Standard kStandard[] = {
    {"M2", 28.9841042}, {"S2", 30.0000000}, {"N2", 28.4397295}, {"K2", 30.0821373},
    {"K1", 15.0410686}, {"O1", 13.9430356}, {"P1", 14.9589314}, {"Q1", 13.3986609},
};
}  // namespace

double tidal_period(const std::string& name) {
  for (const Standard& s : kStandard)
    if (name == s.name) return 360.0 / s.speed * 3600.0;
  return 0.0;
}

const std::vector<std::string>& tidal_constituent_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const Standard& s : kStandard) n.emplace_back(s.name);
    return n;
  }();
  return names;
}

// U = e^{i theta} (A cos psi + i B sin psi), psi = omega t - phase:
//   u = A cos theta cos psi - B sin theta sin psi,  v = A sin theta cos psi + B cos theta sin psi;
// dU/dt = omega e^{i theta} (-A sin psi + i B cos psi).
Vec2 TidalConstituent::velocity(double t) const {
  const double psi = 2.0 * M_PI * t / period - phase;
  const double a = major * std::cos(psi), b = minor * std::sin(psi);
  const double c = std::cos(inclination), s = std::sin(inclination);
  return {c * a - s * b, s * a + c * b};
}

Vec2 TidalConstituent::acceleration(double t) const {
  const double omega = 2.0 * M_PI / period;
  const double psi = omega * t - phase;
  const double a = -omega * major * std::sin(psi), b = omega * minor * std::cos(psi);
  const double c = std::cos(inclination), s = std::sin(inclination);
  return {c * a - s * b, s * a + c * b};
}

Vec2 VelocitySeries::at(double t) const {
  if (time.empty()) return {};
  if (t <= time.front()) return velocity.front();
  if (t >= time.back()) return velocity.back();
  const std::size_t k = static_cast<std::size_t>(std::upper_bound(time.begin(), time.end(), t) - time.begin());
  // v_a + w (v_b - v_a): a steady record gives its value to the bit.
  const double w = (t - time[k - 1]) / (time[k] - time[k - 1]);
  return velocity[k - 1] + w * (velocity[k] - velocity[k - 1]);
}

Vec2 VelocitySeries::slope(double t) const {
  if (time.size() < 2 || t < time.front() || t >= time.back()) return {};
  const std::size_t k = static_cast<std::size_t>(std::upper_bound(time.begin(), time.end(), t) - time.begin());
  return (1.0 / (time[k] - time[k - 1])) * (velocity[k] - velocity[k - 1]);
}

Vec2 EnvironmentSpec::current_change(double t) const {
  Vec2 v = current_series.empty() ? Vec2{} : current_series.at(t);
  for (const TidalConstituent& c : tides) v += c.velocity(t);
  return v;
}

Vec2 EnvironmentSpec::current_change_rate(double t) const {
  Vec2 a = current_series.empty() ? Vec2{} : current_series.slope(t);
  for (const TidalConstituent& c : tides) a += c.acceleration(t);
  return a;
}

}  // namespace floedem
