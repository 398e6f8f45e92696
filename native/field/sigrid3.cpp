#include "floedem/field/sigrid3.hpp"

#include <array>
#include <cstdio>

namespace floedem::sigrid3 {
namespace {

struct Entry {
  int code;
  CodeRange range;
};

// CT: single tenths 10 ... 90; 91 is "9/10 to 10/10" (9+/10), 92 "10/10"; a two-digit code ab
// with b > a is the interval a/10 to b/10, and 81 is 8/10 to 10/10 (SIGRID-3, concentration
// table). The generator takes the middle of an interval.
constexpr std::array<Entry, 29> kConcentration{{
    {0, {0.0, 0.0, "ice free"}},         {1, {0.0, 0.1, "less than 1/10 (open water)"}},
    {2, {0.0, 0.0, "bergy water"}},      {10, {0.1, 0.1, "1/10"}},
    {12, {0.1, 0.2, "1/10 to 2/10"}},    {13, {0.1, 0.3, "1/10 to 3/10"}},
    {20, {0.2, 0.2, "2/10"}},            {23, {0.2, 0.3, "2/10 to 3/10"}},
    {24, {0.2, 0.4, "2/10 to 4/10"}},    {30, {0.3, 0.3, "3/10"}},
    {34, {0.3, 0.4, "3/10 to 4/10"}},    {35, {0.3, 0.5, "3/10 to 5/10"}},
    {40, {0.4, 0.4, "4/10"}},            {45, {0.4, 0.5, "4/10 to 5/10"}},
    {46, {0.4, 0.6, "4/10 to 6/10"}},    {50, {0.5, 0.5, "5/10"}},
    {56, {0.5, 0.6, "5/10 to 6/10"}},    {57, {0.5, 0.7, "5/10 to 7/10"}},
    {60, {0.6, 0.6, "6/10"}},            {67, {0.6, 0.7, "6/10 to 7/10"}},
    {68, {0.6, 0.8, "6/10 to 8/10"}},    {70, {0.7, 0.7, "7/10"}},
    {78, {0.7, 0.8, "7/10 to 8/10"}},    {79, {0.7, 0.9, "7/10 to 9/10"}},
    {80, {0.8, 0.8, "8/10"}},            {89, {0.8, 0.9, "8/10 to 9/10"}},
    {81, {0.8, 1.0, "8/10 to 10/10"}},   {90, {0.9, 0.9, "9/10"}},
    {91, {0.9, 1.0, "9/10 to 10/10"}},
}};
constexpr Entry kCompact{92, {1.0, 1.0, "10/10"}};

// SA: the stages' thickness in the WMO Sea-Ice Nomenclature. Where it gives only an upper
// bound (new ice, nilas: under 10 cm) the lower is taken as 5 cm; where only a lower one (thick
// first-year: over 120 cm) the upper is first-year ice's 2 m; old, second- and multi-year ice
// run from first-year's 2 m to their typical thickness (2.5 m second-year, 3 m old and
// multi-year).
constexpr std::array<Entry, 14> kStage{{
    {81, {0.05, 0.10, "new ice"}},
    {82, {0.05, 0.10, "nilas, ice rind"}},
    {83, {0.10, 0.30, "young ice"}},
    {84, {0.10, 0.15, "grey ice"}},
    {85, {0.15, 0.30, "grey-white ice"}},
    {86, {0.30, 2.00, "first-year ice"}},
    {87, {0.30, 0.70, "thin first-year ice"}},
    {88, {0.30, 0.50, "thin first-year ice, first stage"}},
    {89, {0.50, 0.70, "thin first-year ice, second stage"}},
    {91, {0.70, 1.20, "medium first-year ice"}},
    {93, {1.20, 2.00, "thick first-year ice"}},
    {95, {2.00, 3.00, "old ice"}},
    {96, {2.00, 2.50, "second-year ice"}},
    {97, {2.00, 3.00, "multi-year ice"}},
}};

// FA: the nomenclature's horizontal extents. Small ice cakes and brash are "under 2 m": the
// lower end is taken as 0.5 m.
constexpr std::array<Entry, 7> kForm{{
    {22, {0.3, 3.0, "pancake ice"}},
    {1, {0.5, 2.0, "small ice cake, brash ice"}},
    {2, {2.0, 20.0, "ice cake"}},
    {3, {20.0, 100.0, "small floe"}},
    {4, {100.0, 500.0, "medium floe"}},
    {5, {500.0, 2000.0, "big floe"}},
    {6, {2000.0, 10000.0, "vast floe"}},
}};

template <std::size_t N>
std::optional<CodeRange> find(const std::array<Entry, N>& table, int code) {
  for (const Entry& e : table)
    if (e.code == code) return e.range;
  return std::nullopt;
}

template <std::size_t N>
std::string list(const std::array<Entry, N>& table) {
  std::string out;
  for (const Entry& e : table) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "%s%02d", out.empty() ? "" : ", ", e.code);
    out += buf;
  }
  return out;
}

}  // namespace

std::optional<double> concentration(int code) {
  if (code == kCompact.code) return 1.0;
  const auto r = find(kConcentration, code);
  if (!r) return std::nullopt;
  if (code <= 2) return 0.0;  // ice free, open water, bergy water: no floes
  return 0.5 * (r->lo + r->hi);
}

std::optional<CodeRange> thickness(int code) { return find(kStage, code); }

std::optional<CodeRange> floe_size(int code) { return find(kForm, code); }

std::string allowed(const std::string& attribute) {
  if (attribute == "CT") return list(kConcentration) + ", 92";
  if (attribute == "SA") return list(kStage);
  return list(kForm);
}

}  // namespace floedem::sigrid3
