#pragma once
// Typed, range-checked reads from one TOML table, with errors that name the file, the field,
// its line and the allowed range. Every key read is remembered, so that what is left at the
// end is unknown and reported (a misspelt key must not be silently ignored).
#include <cstdint>
#include <limits>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <toml++/toml.h>

#include "floedem/geometry/vec2.hpp"

namespace floedem {

/// An interval for a real value; open or closed at either end.
struct Range {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;
  bool hi_open = false;

  static Range positive() { return {0.0, std::numeric_limits<double>::infinity(), true, true}; }
  static Range non_negative() { return {0.0, std::numeric_limits<double>::infinity(), false, true}; }
  static Range closed(double a, double b) { return {a, b, false, false}; }
  static Range any() { return {}; }
  bool contains(double v) const;
  std::string describe() const;  ///< "[0, 1]", "(0, inf)"
};

class TableReader {
 public:
  /// prefix: the dotted path of this table ("contact", "body[3]"), empty for the root.
  TableReader(const toml::table& table, std::string file, std::string prefix);

  bool has(std::string_view key) const;
  double real(std::string_view key, std::optional<double> fallback, Range range);
  std::int64_t integer(std::string_view key, std::optional<std::int64_t> fallback, std::int64_t lo,
                       std::int64_t hi);
  bool boolean(std::string_view key, std::optional<bool> fallback);
  std::string string(std::string_view key, std::optional<std::string> fallback,
                     const std::vector<std::string>& allowed = {});
  /// A vector [x, y] of finite numbers.
  Vec2 vec2(std::string_view key, std::optional<Vec2> fallback);
  /// An array of strings; empty when the key is absent.
  std::vector<std::string> strings(std::string_view key);
  /// An array of [x, y] points (no further checks here).
  std::vector<Vec2> points(std::string_view key);
  /// An array of as many finite numbers as `ranges` has entries, entry i within ranges[i];
  /// `fallback` when the key is absent.
  std::vector<double> reals(std::string_view key, std::vector<double> fallback, const std::vector<Range>& ranges);
  /// An array of rows of `width` finite numbers each (at least one row).
  std::vector<std::vector<double>> rows(std::string_view key, std::size_t width);
  /// A sub-table, or nullptr when absent; an error when present with another type.
  const toml::table* table(std::string_view key);
  /// An array of tables ([[key]]), empty when absent.
  std::vector<const toml::table*> array_of_tables(std::string_view key);

  /// Throws InputError for the first key that was never read.
  void reject_unknown() const;

  /// Error for this table's field (line from the node when it exists).
  [[noreturn]] void fail(std::string_view key, const std::string& what) const;
  std::string field_name(std::string_view key) const;
  std::uint32_t line_of(std::string_view key) const;
  const std::string& file() const { return file_; }

 private:
  const toml::node* lookup(std::string_view key);
  const toml::table& table_;
  std::string file_;
  std::string prefix_;
  std::set<std::string, std::less<>> read_;
};

}  // namespace floedem
