#pragma once
// Calendar arithmetic for instants in UTC (the proleptic Gregorian calendar of ISO 8601 and of
// CF's "standard" calendar), for [run] start and the time axes of forcing files.
#include <cstdint>

namespace floedem {

/// Days from 1970-01-01 to the civil date y-m-d: the era arithmetic of the 400-year cycle,
/// with March-based years so that the leap day ends a year.
inline std::int64_t days_from_civil(std::int64_t y, int m, int d) {
  y -= m <= 2 ? 1 : 0;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const std::int64_t yoe = y - era * 400;                                   // [0, 399]
  const std::int64_t doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;  // [0, 365]
  const std::int64_t doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;          // [0, 146096]
  return era * 146097 + doe - 719468;
}

inline bool leap_year(std::int64_t y) { return (y % 4 == 0 && y % 100 != 0) || y % 400 == 0; }

/// Whether y-m-d hh:mm:ss is a valid date and time of day.
inline bool valid_instant(std::int64_t y, int m, int d, int h, int mi, double s) {
  static const int kDays[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  return m >= 1 && m <= 12 && d >= 1 && d <= kDays[m - 1] + (m == 2 && leap_year(y) ? 1 : 0) && h >= 0 && h <= 23 &&
         mi >= 0 && mi <= 59 && s >= 0.0 && s < 60.0;
}

/// s since 1970-01-01T00:00:00Z.
inline double unix_seconds(std::int64_t y, int m, int d, int h, int mi, double s) {
  return static_cast<double>(days_from_civil(y, m, d)) * 86400.0 + h * 3600.0 + mi * 60.0 + s;
}

}  // namespace floedem
