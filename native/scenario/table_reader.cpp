#include "scenario/table_reader.hpp"

#include <cmath>
#include <sstream>

#include "floedem/scene/input_error.hpp"

namespace floedem {

namespace {

std::string format_number(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  std::ostringstream s;
  s.precision(12);
  s << v;
  return s.str();
}

std::string type_name(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::table: return "a table";
    case toml::node_type::array: return "an array";
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a number";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::date: return "a date";
    case toml::node_type::time: return "a time";
    case toml::node_type::date_time: return "a date-time";
    default: return "nothing";
  }
}

std::optional<double> as_real(const toml::node& n) {
  if (n.is_floating_point()) return n.as_floating_point()->get();
  if (n.is_integer()) return static_cast<double>(n.as_integer()->get());
  return std::nullopt;
}

}  // namespace

bool Range::contains(double v) const {
  if (lo_open ? !(v > lo) : !(v >= lo)) return false;
  if (hi_open ? !(v < hi) : !(v <= hi)) return false;
  return true;
}

std::string Range::describe() const {
  return std::string(lo_open ? "(" : "[") + format_number(lo) + ", " + format_number(hi) +
         (hi_open ? ")" : "]");
}

TableReader::TableReader(const toml::table& table, std::string file, std::string prefix)
    : table_(table), file_(std::move(file)), prefix_(std::move(prefix)) {}

std::string TableReader::field_name(std::string_view key) const {
  return prefix_.empty() ? std::string(key) : prefix_ + "." + std::string(key);
}

std::uint32_t TableReader::line_of(std::string_view key) const {
  if (const toml::node* n = table_.get(key)) return n->source().begin.line;
  return table_.source().begin.line;
}

void TableReader::fail(std::string_view key, const std::string& what) const {
  throw InputError(input_message(file_, line_of(key), field_name(key), what));
}

bool TableReader::has(std::string_view key) const { return table_.contains(key); }

const toml::node* TableReader::lookup(std::string_view key) {
  read_.insert(std::string(key));
  return table_.get(key);
}

double TableReader::real(std::string_view key, std::optional<double> fallback, Range range) {
  const toml::node* n = lookup(key);
  if (!n) {
    if (!fallback) fail(key, "missing (required), allowed " + range.describe());
    return *fallback;
  }
  const auto v = as_real(*n);
  if (!v) fail(key, "expected a number, got " + type_name(*n) + "; allowed " + range.describe());
  if (!std::isfinite(*v)) fail(key, "must be finite, got " + format_number(*v) + "; allowed " + range.describe());
  if (!range.contains(*v)) fail(key, format_number(*v) + " is out of range; allowed " + range.describe());
  return *v;
}

std::int64_t TableReader::integer(std::string_view key, std::optional<std::int64_t> fallback,
                                  std::int64_t lo, std::int64_t hi) {
  const std::string allowed = "allowed integers in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  const toml::node* n = lookup(key);
  if (!n) {
    if (!fallback) fail(key, "missing (required), " + allowed);
    return *fallback;
  }
  if (!n->is_integer()) fail(key, "expected an integer, got " + type_name(*n) + "; " + allowed);
  const std::int64_t v = n->as_integer()->get();
  if (v < lo || v > hi) fail(key, std::to_string(v) + " is out of range; " + allowed);
  return v;
}

bool TableReader::boolean(std::string_view key, std::optional<bool> fallback) {
  const toml::node* n = lookup(key);
  if (!n) {
    if (!fallback) fail(key, "missing (required), allowed true or false");
    return *fallback;
  }
  if (!n->is_boolean()) fail(key, "expected true or false, got " + type_name(*n));
  return n->as_boolean()->get();
}

std::string TableReader::string(std::string_view key, std::optional<std::string> fallback,
                                const std::vector<std::string>& allowed) {
  std::string list;
  for (const auto& a : allowed) list += (list.empty() ? "\"" : ", \"") + a + "\"";
  const std::string allowed_text = allowed.empty() ? "a string" : "one of " + list;
  const toml::node* n = lookup(key);
  if (!n) {
    if (!fallback) fail(key, "missing (required), allowed " + allowed_text);
    return *fallback;
  }
  if (!n->is_string()) fail(key, "expected " + allowed_text + ", got " + type_name(*n));
  std::string v = n->as_string()->get();
  if (!allowed.empty()) {
    bool ok = false;
    for (const auto& a : allowed) ok = ok || a == v;
    if (!ok) fail(key, "\"" + v + "\" is not allowed; allowed " + allowed_text);
  }
  return v;
}

std::vector<std::string> TableReader::strings(std::string_view key) {
  const toml::node* n = lookup(key);
  std::vector<std::string> out;
  if (!n) return out;
  const toml::array* a = n->as_array();
  if (!a) fail(key, "expected an array of strings, got " + type_name(*n));
  for (const toml::node& e : *a) {
    if (!e.is_string()) fail(key, "expected an array of strings, got an element of type " + type_name(e));
    out.push_back(e.as_string()->get());
  }
  return out;
}

Vec2 TableReader::vec2(std::string_view key, std::optional<Vec2> fallback) {
  const toml::node* n = lookup(key);
  if (!n) {
    if (!fallback) fail(key, "missing (required), allowed [x, y] of finite numbers");
    return *fallback;
  }
  const toml::array* a = n->as_array();
  if (!a) fail(key, "expected [x, y], got " + type_name(*n));
  if (a->size() != 2)
    fail(key, "expected 2 components [x, y], got " + std::to_string(a->size()));
  Vec2 v;
  for (std::size_t i = 0; i < 2; ++i) {
    const auto c = as_real(*a->get(i));
    if (!c) fail(key, "component " + std::to_string(i) + " is " + type_name(*a->get(i)) + ", expected a number");
    if (!std::isfinite(*c)) fail(key, "component " + std::to_string(i) + " must be finite, got " + format_number(*c));
    (i == 0 ? v.x : v.y) = *c;
  }
  return v;
}

std::vector<Vec2> TableReader::points(std::string_view key) {
  const toml::node* n = lookup(key);
  if (!n) fail(key, "missing (required), allowed an array of at least 3 [x, y] vertices");
  const toml::array* a = n->as_array();
  if (!a) fail(key, "expected an array of [x, y] vertices, got " + type_name(*n));
  std::vector<Vec2> out;
  out.reserve(a->size());
  for (std::size_t k = 0; k < a->size(); ++k) {
    const toml::array* p = a->get(k)->as_array();
    const std::string which = "vertex " + std::to_string(k);
    if (!p) fail(key, which + " is " + type_name(*a->get(k)) + ", expected [x, y]");
    if (p->size() != 2) fail(key, which + " has " + std::to_string(p->size()) + " components, expected 2 [x, y]");
    Vec2 v;
    for (std::size_t i = 0; i < 2; ++i) {
      const auto c = as_real(*p->get(i));
      if (!c) fail(key, which + " component " + std::to_string(i) + " is " + type_name(*p->get(i)) + ", expected a number");
      if (!std::isfinite(*c)) fail(key, which + " component " + std::to_string(i) + " must be finite, got " + format_number(*c));
      (i == 0 ? v.x : v.y) = *c;
    }
    out.push_back(v);
  }
  return out;
}

std::vector<double> TableReader::reals(std::string_view key, std::vector<double> fallback, const std::vector<Range>& ranges) {
  const std::string shape = "an array of " + std::to_string(ranges.size()) + " numbers";
  const toml::node* n = lookup(key);
  if (!n) return fallback;
  const toml::array* a = n->as_array();
  if (!a) fail(key, "expected " + shape + ", got " + type_name(*n));
  if (a->size() != ranges.size()) fail(key, "expected " + shape + ", got " + std::to_string(a->size()));
  std::vector<double> out;
  for (std::size_t i = 0; i < ranges.size(); ++i) {
    const auto c = as_real(*a->get(i));
    if (!c) fail(key, "entry " + std::to_string(i) + " is " + type_name(*a->get(i)) + ", expected a number");
    if (!std::isfinite(*c) || !ranges[i].contains(*c))
      fail(key, "entry " + std::to_string(i) + " is " + format_number(*c) + ", allowed " + ranges[i].describe());
    out.push_back(*c);
  }
  return out;
}

std::vector<std::vector<double>> TableReader::rows(std::string_view key, std::size_t width) {
  const std::string shape = "an array of rows of " + std::to_string(width) + " numbers";
  const toml::node* n = lookup(key);
  if (!n) fail(key, "missing (required), allowed " + shape);
  const toml::array* a = n->as_array();
  if (!a || a->empty()) fail(key, "expected " + shape);
  std::vector<std::vector<double>> out;
  for (std::size_t k = 0; k < a->size(); ++k) {
    const toml::array* row = a->get(k)->as_array();
    const std::string which = "row " + std::to_string(k);
    if (!row || row->size() != width) fail(key, which + " must have " + std::to_string(width) + " numbers; allowed " + shape);
    std::vector<double> r;
    for (std::size_t i = 0; i < width; ++i) {
      const auto c = as_real(*row->get(i));
      if (!c || !std::isfinite(*c)) fail(key, which + " entry " + std::to_string(i) + " must be a finite number");
      r.push_back(*c);
    }
    out.push_back(std::move(r));
  }
  return out;
}

const toml::table* TableReader::table(std::string_view key) {
  const toml::node* n = lookup(key);
  if (!n) return nullptr;
  if (!n->is_table()) fail(key, "expected a table [" + field_name(key) + "], got " + type_name(*n));
  return n->as_table();
}

std::vector<const toml::table*> TableReader::array_of_tables(std::string_view key) {
  const toml::node* n = lookup(key);
  if (!n) return {};
  const toml::array* a = n->as_array();
  if (!a) fail(key, "expected an array of tables [[" + field_name(key) + "]], got " + type_name(*n));
  std::vector<const toml::table*> out;
  for (std::size_t i = 0; i < a->size(); ++i) {
    const toml::table* t = a->get(i)->as_table();
    if (!t) fail(key, "element " + std::to_string(i) + " is " + type_name(*a->get(i)) + ", expected a table");
    out.push_back(t);
  }
  return out;
}

void TableReader::reject_unknown() const {
  for (auto&& [k, v] : table_) {
    if (!read_.contains(k.str())) {
      throw InputError(input_message(file_, v.source().begin.line, field_name(k.str()),
                                     "unknown key (misspelt? see scenarios/README.md)"));
    }
  }
}

}  // namespace floedem
