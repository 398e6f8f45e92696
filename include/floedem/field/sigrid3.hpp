#pragma once
// The SIGRID-3 codes an ice chart's polygons carry, and what the field generator takes from
// them (docs/ice_charts.md). SIGRID-3 is the WMO's vector archive format for ice charts
// (JCOMM Expert Team on Sea Ice 2014, "SIGRID-3: a vector archive format for sea ice
// georeferenced information and data", version 3.0, WMO/TD-No. 1214, JCOMM Technical Report
// No. 23): each polygon holds the egg code's figures as two-digit codes. The ranges of floe
// size and thickness behind the codes are those of the WMO Sea-Ice Nomenclature (WMO-No. 259).
#include <optional>
#include <string>

namespace floedem::sigrid3 {

/// A range of a code, and the code's name.
struct CodeRange {
  double lo = 0.0;
  double hi = 0.0;
  const char* name = "";
};

/// Total concentration (CT): the fraction of the sea surface covered by ice, the middle of an
/// interval code ("46": 4/10 to 6/10 -> 0.5); 0 for the ice-free codes (00 ice free, 01 less
/// than 1/10, 02 bergy water). None for 99 (unknown) and for numbers that are no code.
std::optional<double> concentration(int code);

/// Stage of development (SA): the thickness range, m. None for codes without one (80 no stage,
/// 98 glacier ice, 99 unknown) and numbers that are no code.
std::optional<CodeRange> thickness(int code);

/// Form of ice (FA): the range of floe sizes, m (the generator's d_min and d_max, equal-area
/// diameters). None for forms that are no broken ice of bounded size (07 giant floes, 08 fast
/// ice, 09 growlers and floebergs, 10 icebergs, 21 level ice, 99 unknown) and numbers that are
/// no code.
std::optional<CodeRange> floe_size(int code);

/// The codes each function accepts, for messages ("00, 01, 02, 10, 12, ..."): "CT", "SA" or "FA".
std::string allowed(const std::string& attribute);

}  // namespace floedem::sigrid3
