// The broken-ice field generator (docs/model.md section 5): concentration, power-law exponent, no
// overlap (decided exactly), inside the domain, reproducible, keep-out zones, bad input.
//
// Tolerances (from the issue, and why they are physical): concentration within 0.005 (a
// hundredth of the range of concentrations ice engineers tell apart, 0.1 steps); exponent
// within 0.02 (a tenth of the scatter of exponents fitted to aerial images, 1.5 to 3.5).
// The method makes both exact up to round-off and the exponent up to the discreteness of N
// stratified sizes, far inside those bounds, so the tests also check the much tighter values
// the method reaches (1e-9 and 2e-3), so that a regression shows long before the required bounds.
#include <catch2/catch.hpp>

#include <functional>
#include <numbers>
#include <random>

#include "field/exact_geometry.hpp"
#include "floedem/field/field_generator.hpp"
#include "floedem/field/size_distribution.hpp"
#include "geometry/polygon.hpp"

using namespace floedem;

namespace {

/// A square domain holding about `floes` floes of the law at concentration C.
FieldSpec spec_for(double concentration, double alpha, std::size_t floes, std::uint64_t seed = 11) {
  FieldSpec s;
  s.concentration = concentration;
  s.alpha = alpha;
  s.d_min = 2.0;
  s.d_max = 40.0;
  s.thickness.value = 1.16;
  s.seed = seed;
  const TruncatedPowerLaw law{alpha, s.d_min, s.d_max};
  const double side = std::sqrt(static_cast<double>(floes) * law.mean_area() / concentration);
  s.width = side;
  s.height = side;
  s.origin = {-0.25 * side, 100.0};
  return s;
}

void check_geometry(const FieldSpec& s, const Field& f) {
  const Vec2 lo = s.origin, hi = s.origin + Vec2{s.width, s.height};
  for (const auto& p : f.floes) {
    REQUIRE(p.size() >= 3);
    REQUIRE(is_strictly_convex(p));
    REQUIRE(test::inside_box(p, lo, hi));
  }
  const auto hit = test::first_overlap(f.floes);
  INFO("overlapping floes " << (hit ? hit->first : 0) << " and " << (hit ? hit->second : 0));
  REQUIRE_FALSE(hit.has_value());
}

/// A field of 5 to 60 m floes, 1.16 m thick, round the iceberg of towing_paper.toml and
/// drift_in_field.toml (its waterline as the keep-out zone).
FieldSpec round_iceberg(Vec2 origin, double width, double height, double concentration, std::uint64_t seed) {
  FieldSpec s;
  s.origin = origin;
  s.width = width;
  s.height = height;
  s.concentration = concentration;
  s.alpha = 2.0;
  s.d_min = 5.0;
  s.d_max = 60.0;
  s.thickness.value = 1.16;
  s.seed = seed;
  s.keep_out = {{{-90, -55}, {-20, -62}, {60, -58}, {92, -20}, {88, 35}, {40, 62}, {5, 40}, {-30, 60}, {-85, 45}, {-95, 0}}};
  return s;
}

}  // namespace

TEST_CASE("field: concentration within 0.005 of the target, no overlap, inside the domain", "[field]") {
  for (const double c : {0.1, 0.3, 0.5, 0.7, 0.8}) {
    const FieldSpec s = spec_for(c, 2.0, 5200);
    const Field f = generate_field(s);
    INFO("C = " << c << ", N = " << f.stats.floes);
    REQUIRE(f.stats.floes >= 5000);
    REQUIRE(f.stats.floes_short_of_area == 0);
    // Measured on the polygons, independently of the generator's own statistics.
    double ice = 0.0;
    for (const auto& p : f.floes) ice += signed_area(p);
    const double achieved = ice / (s.width * s.height);
    CHECK(std::abs(achieved - c) <= 0.005);
    CHECK(std::abs(achieved - c) <= 1e-9);
    check_geometry(s, f);
  }
}

TEST_CASE("field: maximum-likelihood exponent within 0.02 of alpha", "[field]") {
  for (const double alpha : {1.5, 2.0, 2.5, 3.0}) {
    const FieldSpec s = spec_for(0.5, alpha, 5200);
    const Field f = generate_field(s);
    std::vector<double> d;
    for (const auto& p : f.floes) d.push_back(std::sqrt(4.0 * signed_area(p) / std::numbers::pi));
    const PowerLawFit fit = fit_truncated_power_law(d, s.d_min, s.d_max);
    INFO("alpha = " << alpha << ", N = " << d.size() << ", fitted " << fit.alpha << " +- " << fit.stderr_alpha);
    REQUIRE(d.size() >= 5000);
    CHECK(std::abs(fit.alpha - alpha) <= 0.02);
    CHECK(std::abs(fit.alpha - alpha) <= 2e-3);
    CHECK(fit.alpha == Approx(f.stats.fit.alpha).epsilon(1e-12));
  }
}

TEST_CASE("field: the fit recovers the exponent of independent draws within sampling error", "[field]") {
  // Independent draws (inverse transform) from the truncated law: the estimator is unbiased to
  // O(1/N), so it lands within 3 standard errors; its standard error is the one it reports.
  const TruncatedPowerLaw law{2.3, 1.0, 200.0};
  std::mt19937_64 rng(5);
  std::vector<double> d(20000);
  for (double& x : d) x = law.quantile(static_cast<double>(rng() >> 11) * 0x1.0p-53);
  const PowerLawFit fit = fit_truncated_power_law(d, law.d_min, law.d_max);
  CHECK(std::abs(fit.alpha - law.alpha) < 3.0 * fit.stderr_alpha);
  CHECK(fit.stderr_alpha == Approx(law.alpha / std::sqrt(20000.0)).epsilon(0.1));  // ~ alpha/sqrt(N) for wide ranges
}

TEST_CASE("field: stratified sizes add up to the total area and stay in [d_min, d_max]", "[field]") {
  const TruncatedPowerLaw law{1.8, 3.0, 120.0};
  for (const double total : {5e3, 1e5, 3.3e6}) {
    const auto d = stratified_sizes(law, total);
    double sum = 0.0;
    for (const double x : d) {
      CHECK(x >= law.d_min);
      CHECK(x <= law.d_max);
      sum += std::numbers::pi / 4.0 * x * x;
    }
    CHECK(sum == Approx(total).epsilon(1e-12));
    CHECK(std::is_sorted(d.begin(), d.end()));
  }
}

TEST_CASE("field: the same seed gives the identical field, another seed another", "[field][determinism]") {
  FieldSpec s = spec_for(0.6, 2.0, 1500, 21);
  s.thickness = {ThicknessDistribution::Kind::lognormal, 0.0, 0.0, 0.0, 1.2, 0.4};
  const Field a = generate_field(s), b = generate_field(s);
  REQUIRE(a.floes.size() == b.floes.size());
  for (std::size_t i = 0; i < a.floes.size(); ++i) {
    REQUIRE(a.floes[i].size() == b.floes[i].size());
    for (std::size_t k = 0; k < a.floes[i].size(); ++k) REQUIRE(a.floes[i][k] == b.floes[i][k]);
    REQUIRE(a.thickness[i] == b.thickness[i]);
  }
  s.seed = 22;
  const Field c = generate_field(s);
  std::size_t same = 0;
  for (std::size_t i = 0; i < std::min(a.floes.size(), c.floes.size()); ++i)
    if (a.floes[i] == c.floes[i]) ++same;
  CHECK(same == 0);
  // The thickness follows its lognormal law: mean and standard deviation within sampling error.
  double m = 0.0, v = 0.0;
  for (const double t : a.thickness) m += t;
  m /= static_cast<double>(a.thickness.size());
  for (const double t : a.thickness) v += (t - m) * (t - m);
  v /= static_cast<double>(a.thickness.size() - 1);
  CHECK(m == Approx(1.2).epsilon(0.05));
  CHECK(std::sqrt(v) == Approx(0.4).epsilon(0.15));
}

TEST_CASE("field: floes are numbered along a space-filling curve: a floe's nearest neighbour is near in number",
          "[field]") {
  // The solver and the narrow phase go through contacts in the order of the floes' numbers;
  // numbered along a Hilbert curve, floes that touch lie close in memory. Random numbering (the
  // sites' order) puts a floe's nearest neighbour some 0.3 N numbers away at the median; along
  // the curve it is a few numbers away. Checked on a square and on a strip 100 times longer
  // than it is deep (the speed benchmark's shape: a strip along a wall).
  for (const bool strip : {false, true}) {
    FieldSpec s = spec_for(0.5, 2.0, 5200);
    if (strip) {
      const double area = s.width * s.height;
      s.width = std::sqrt(area / 100.0);
      s.height = 100.0 * s.width;
    }
    const Field f = generate_field(s);
    const std::size_t n = f.floes.size();
    std::vector<Vec2> c(n);
    for (std::size_t i = 0; i < n; ++i) c[i] = area_moments(f.floes[i]).centroid;
    std::vector<double> gap(n);
    for (std::size_t i = 0; i < n; ++i) {
      double best = std::numeric_limits<double>::infinity();
      std::size_t nearest = i;
      for (std::size_t j = 0; j < n; ++j) {
        const double d = length_squared(c[j] - c[i]);
        if (j != i && d < best) {
          best = d;
          nearest = j;
        }
      }
      gap[i] = std::abs(static_cast<double>(nearest) - static_cast<double>(i));
    }
    std::nth_element(gap.begin(), gap.begin() + n / 2, gap.end());
    INFO((strip ? "strip" : "square") << ", N = " << n << ", median number gap to the nearest floe " << gap[n / 2]);
    REQUIRE(n >= 5000);
    CHECK(gap[n / 2] <= 0.01 * static_cast<double>(n));
  }
}

TEST_CASE("field: keep-out zones stay free and the concentration holds on the free area", "[field]") {
  FieldSpec s = spec_for(0.6, 2.0, 3000, 3);
  const Vec2 c = s.origin + 0.5 * Vec2{s.width, s.height};
  const std::vector<Vec2> square{c + Vec2{-60, -40}, c + Vec2{60, -40}, c + Vec2{60, 40}, c + Vec2{-60, 40}};
  // An L-shaped (concave) zone reaching over the domain's edge: only its inside part counts.
  const Vec2 o = s.origin;
  const std::vector<Vec2> ell{o + Vec2{-20, -20}, o + Vec2{90, -20}, o + Vec2{90, 30},
                              o + Vec2{30, 30},   o + Vec2{30, 90},  o + Vec2{-20, 90}};
  s.keep_out = {square, ell};
  const Field f = generate_field(s);
  const double free_area = s.width * s.height - 120.0 * 80.0 - (90.0 * 30.0 + 30.0 * 60.0);
  CHECK(f.stats.free_area == Approx(free_area).epsilon(1e-12));
  double ice = 0.0;
  for (const auto& p : f.floes) ice += signed_area(p);
  INFO("floes cut short by a zone: " << f.stats.floes_short_of_area);
  CHECK(std::abs(ice / free_area - s.concentration) <= 0.005);
  check_geometry(s, f);
  const std::vector<std::vector<Vec2>> pieces{square, {ell[0], ell[1], ell[2], ell[3]}, {ell[0], ell[3], ell[4], ell[5]}};
  for (const auto& p : f.floes)
    for (const auto& k : pieces) REQUIRE(test::convex_interiors_disjoint(p, k));
}

TEST_CASE("field: a keep-out cut that leaves a sliver gives no floe, never a degenerate one", "[field]") {
  // Regression: the towing case's iceberg in a 600 m x 400 m field (seed 2016) left one cell
  // cleaned to a segment; it was shrunk by 0 / 0 into a NaN floe that crashed the convex partition.
  const FieldSpec s = round_iceberg({-150.0, -200.0}, 600.0, 400.0, 0.5, 2016);
  const Field f = generate_field(s);
  CHECK(f.stats.floes_short_of_area >= 1);
  for (const auto& p : f.floes) {
    REQUIRE(p.size() >= 3);
    for (const Vec2 v : p) REQUIRE((std::isfinite(v.x) && std::isfinite(v.y)));
    REQUIRE(is_strictly_convex(p));
    REQUIRE(signed_area(p) > 0.0);
  }
  CHECK(std::abs(f.stats.concentration - 0.5) <= 0.005);
}

TEST_CASE("field: bad parameters name the parameter and the allowed range", "[field][input]") {
  struct Bad {
    const char* parameter;
    std::function<void(FieldSpec&)> change;
    const char* says;
  };
  const std::vector<Bad> cases = {
      {"concentration", [](FieldSpec& s) { s.concentration = 0.0; }, "(0, 0.99]"},
      {"concentration", [](FieldSpec& s) { s.concentration = 1.0; }, "(0, 0.99]"},
      {"concentration", [](FieldSpec& s) { s.concentration = std::nan(""); }, "(0, 0.99]"},
      {"alpha", [](FieldSpec& s) { s.alpha = -1.0; }, "(0, 10]"},
      {"d_max", [](FieldSpec& s) { s.d_max = s.d_min; }, "allowed ("},
      {"d_min", [](FieldSpec& s) { s.d_min = 0.0; }, "(0, inf)"},
      {"width", [](FieldSpec& s) { s.width = 0.5 * s.d_max; }, "at least d_max"},
      {"height", [](FieldSpec& s) { s.height = -1.0; }, "(0, 1e+07]"},
      {"irregularity", [](FieldSpec& s) { s.irregularity = 1.5; }, "[0, 1]"},
      {"thickness", [](FieldSpec& s) { s.thickness.value = 0.0; }, "(0, inf)"},
      {"keep_out", [](FieldSpec& s) {
         s.keep_out = {{s.origin - Vec2{1, 1}, s.origin + Vec2{s.width + 1, -1},
                        s.origin + Vec2{s.width + 1, s.height + 1}, s.origin + Vec2{-1, s.height + 1}}};
       }, "cover the whole domain"},
      {"keep_out[1]", [](FieldSpec& s) {
         s.keep_out = {{s.origin, s.origin + Vec2{50, 0}, s.origin + Vec2{50, 50}},
                       {s.origin + Vec2{10, 1}, s.origin + Vec2{60, 1}, s.origin + Vec2{60, 60}}};
       }, "overlaps keep_out[0]"},
      {"keep_out[0]", [](FieldSpec& s) {
         s.keep_out = {{s.origin, s.origin + Vec2{50, 50}, s.origin + Vec2{50, 0}, s.origin + Vec2{0, 50}}};
       }, "self-intersecting"},
      {"keep_out[0]", [](FieldSpec& s) { s.keep_out = {{s.origin, s.origin + Vec2{4e75, 0}, s.origin + Vec2{0, 50}}}; },
       "within 1e7 m"},
      {"keep_out[0]", [](FieldSpec& s) { s.keep_out = {{s.origin, s.origin + Vec2{50, 0}}}; }, "allowed at least 3"},
      {"keep_out[0]", [](FieldSpec& s) {
         s.keep_out = {{s.origin, s.origin + Vec2{50, 0}, s.origin + Vec2{100, 0}}};
       }, "zero area"},
      {"origin", [](FieldSpec& s) { s.origin.x = std::nan(""); }, "|x|, |y| <= 1e7 m"},
      {"origin", [](FieldSpec& s) { s.origin.y = 2e7; }, "|x|, |y| <= 1e7 m"},
      // The largest floe's cell, pi d_max^2 / (4 C), is 1.57 times the domain.
      {"d_max", [](FieldSpec& s) { s.d_max = s.width = s.height; }, "smaller than the cell the largest floe needs"},
      // ... and, with keep-out zones (here all but a 1 m strip), it is they that leave too little room.
      {"keep_out", [](FieldSpec& s) {
         s.keep_out = {{s.origin, s.origin + Vec2{s.width, 0}, s.origin + Vec2{s.width, s.height - 1},
                        s.origin + Vec2{0, s.height - 1}}};
       }, "smaller keep-out zones"},
      {"d_min", [](FieldSpec& s) { s.d_min = 1e-5; }, "allowed at most 2e+07"},
  };
  for (const Bad& b : cases) {
    FieldSpec s = spec_for(0.5, 2.0, 500);
    b.change(s);
    INFO(b.parameter << ": " << b.says);
    try {
      check_field_spec(s);
      FAIL("accepted");
    } catch (const FieldSpecError& e) {
      CHECK(e.parameter() == b.parameter);
      CHECK(std::string(e.what()).find(b.says) != std::string::npos);
    }
  }
}

TEST_CASE("field: no floe a keep-out cut leaves smaller than d_min", "[field]") {
  // drift_in_field's iceberg and field with seed 2 left a 0.6 m fragment (d_min 5 m) at the
  // iceberg's corner: 289 kg among 5e4 kg floes, squeezed out at 1.5 m/s in the run.
  const FieldSpec s = round_iceberg({-500.0, -350.0}, 1000.0, 700.0, 0.4, 2);
  const Field f = generate_field(s);
  CHECK(f.stats.floes_dropped_below_d_min >= 1);
  const double smallest = std::numbers::pi / 4.0 * s.d_min * s.d_min;
  for (const auto& p : f.floes) REQUIRE(signed_area(p) >= smallest * (1.0 - 1e-9));
  CHECK(std::abs(f.stats.concentration - 0.4) <= 0.005);
}

TEST_CASE("field: a keep-out zone cut by the domain's edge is refused by name when its pockets cannot be filled",
          "[field][input]") {
  // The towing case's iceberg with the domain's top edge across its notch (y = 50 m): the edge
  // closes off water between the notch and the edge. For most seeds no weights fill the cells
  // there; that must be a refusal naming the zone, never the generator's internal error.
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    FieldSpec s = round_iceberg({-150.0, -350.0}, 1500.0, 400.0, 0.5, seed);
    s.keep_out_names = {"body 'iceberg'"};
    try {
      const Field f = generate_field(s);
      CHECK(f.stats.max_cell_area_error <= 1e-3);
    } catch (const FieldSpecError& e) {
      CHECK(e.parameter() == "keep_out[0]");
      CHECK_THAT(e.what(), Catch::StartsWith("body 'iceberg' crosses the domain's edge"));
    }
  }
}
