#include "io/case_toml.hpp"

#include <algorithm>
#include <cstdlib>

namespace fdem::io::detail {

std::string describe(const toml::node& n) {
  if (auto s = n.value_exact<std::string>()) return "string \"" + *s + "\"";
  if (auto i = n.value_exact<std::int64_t>()) return "integer " + std::to_string(*i);
  if (auto d = n.value_exact<double>()) return "number " + format_number(*d, kDigits);
  if (auto b = n.value_exact<bool>()) return std::string("boolean ") + (*b ? "true" : "false");
  if (auto* a = n.as_array())
    return a->is_array_of_tables() ? "array of tables" : "array of " + std::to_string(a->size());
  if (n.is_table()) return "table";
  return "a date/time";
}

namespace {
bool is_control(char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; }
std::string hex(char c) {
  const auto byte = static_cast<unsigned char>(c);
  return {"0123456789abcdef"[byte >> 4], "0123456789abcdef"[byte & 15]};
}
}  // namespace

std::string shortest_text(double v) {
  for (int digits = 1; digits < 17; ++digits)
    if (const std::string s = format_number(v, digits); std::strtod(s.c_str(), nullptr) == v) return s;
  return format_number(v, 17);
}

std::string quoted_text(std::string_view s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '\n') out += "\\n";
    else if (c == '\t') out += "\\t";
    else if (c == '\r') out += "\\r";
    else if (c == '"' || c == '\\') out += std::string("\\") + c;
    else if (is_control(c)) out += "\\u00" + hex(c);
    else out += c;
  }
  return out + "\"";
}

std::string control_character(std::string_view s) {
  for (char c : s)
    if (is_control(c)) return "byte 0x" + hex(c);
  return "";
}

std::string Range::text(std::string_view name) const {
  const std::string n(name);
  const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
  if (has_lo && has_hi)
    return format_number(lo, kDigits) + (lo_open ? " < " : " <= ") + n +
           (hi_open ? " < " : " <= ") + format_number(hi, kDigits);
  if (has_lo) return n + (lo_open ? " > " : " >= ") + format_number(lo, kDigits);
  if (has_hi) return n + (hi_open ? " < " : " <= ") + format_number(hi, kDigits);
  return n + " finite";
}

bool Context::from_override(const toml::node& n) const {
  const toml::source_region& src = n.source();
  return created_.count(&n) || (src.path && override_sources_.count(*src.path));
}

std::string Context::where(const toml::node& n) const {
  if (auto it = created_.find(&n); it != created_.end()) return from_set(it->second);
  const toml::source_region& src = n.source();
  if (src.path && override_sources_.count(*src.path)) return from_set(*src.path);
  return path_ + ":" + std::to_string(std::max<toml::source_index>(src.begin.line, 1));
}

double as_number(const Context& ctx, const toml::node& n, const std::string& path,
                 const Range& range) {
  std::optional<double> v;
  if (auto i = n.value_exact<std::int64_t>()) v = static_cast<double>(*i);
  if (auto d = n.value_exact<double>()) v = *d;
  if (!v) ctx.fail(n, path + " must be a number, found " + describe(n));
  if (!std::isfinite(*v)) ctx.fail(n, path + " must be finite, found " + format_number(*v, kDigits));
  // Magnitudes outside [1e-30, 1e30] (other than 0) are refused: no quantity of a case in
  // SI units lies outside (time steps of picoseconds, penalties of 1e16 Pa/m), and the
  // run multiplies such values (dt² E, 6 P_n / h) into overflow or underflow: dt = 1e308
  // once ran to a NaN state with exit 0. That includes the subnormal numbers (-1e-310),
  // which a device may also flush to zero, silently turning a positive value into 0.
  if (*v != 0 && !(std::fabs(*v) >= kSmallestMagnitude && std::fabs(*v) <= kLargestMagnitude))
    ctx.fail(n, path + " = " + shortest_text(*v) + " is out of range (allowed: 0, or " +
                    format_number(kSmallestMagnitude) + " <= |" + path + "| <= " + format_number(kLargestMagnitude) +
                    (std::fpclassify(*v) == FP_SUBNORMAL ? "; subnormal numbers are refused" : "") +
                    ": no quantity of a case in SI units lies outside, and products of such values "
                    "overflow or underflow a double)");
  if (!range.contains(*v))
    ctx.fail(n, path + " = " + format_number(*v, kDigits) + " is out of range (allowed: " +
                    range.text(path) + ")");
  return *v;
}

std::string as_string(const Context& ctx, const toml::node& n, const std::string& path) {
  auto s = n.value_exact<std::string>();
  if (!s) ctx.fail(n, path + " must be a string, found " + describe(n));
  return *s;
}

// ---------------------------------------------------------------------------------------
// TableReader

void TableReader::check_keys(const Schema& schema) const {
  for (auto&& [key, node] : table_)
    if (!schema.find(key.str()))
      ctx_.fail(node, unknown_name_message(key.str(), shape_of(node), schema, heading_));
}

void TableReader::fail(std::string_view key, const std::string& what) const {
  const toml::node* n = find(key);
  ctx_.fail(n ? *n : static_cast<const toml::node&>(table_), what);
}

void TableReader::missing(std::string_view key) const {
  ctx_.fail(table_, title_ + " is missing required key '" + std::string(key) + "'");
}

std::string_view TableReader::blamed(std::string_view a, std::string_view b) const {
  if (!has(a) || !has(b)) return has(a) ? a : b;
  const toml::node &na = *find(a), &nb = *find(b);
  const bool blame_a = ctx_.from_override(na) != ctx_.from_override(nb)
                           ? ctx_.from_override(na)
                           : na.source().begin.line > nb.source().begin.line;
  return blame_a ? a : b;
}

void TableReader::exclusive(std::string_view a, std::string_view b) const {
  if (!has(a) || !has(b)) return;
  fail(blamed(a, b), key_path(a) + " and " + key_path(b) + " are exclusive: give only one");
}

void TableReader::exactly_one(std::string_view a, std::string_view b) const {
  exclusive(a, b);
  if (!has(a) && !has(b))
    ctx_.fail(table_, title_ + " needs one of '" + std::string(a) + "' or '" +
                          std::string(b) + "'");
}

std::optional<double> TableReader::number(std::string_view key, const Range& range) const {
  const toml::node* n = find(key);
  if (!n) return std::nullopt;
  return as_number(ctx_, *n, key_path(key), range);
}

double TableReader::required_number(std::string_view key, const Range& range) const {
  if (!has(key)) missing(key);
  return *number(key, range);
}

std::optional<std::string> TableReader::string(std::string_view key) const {
  const toml::node* n = find(key);
  if (!n) return std::nullopt;
  return as_string(ctx_, *n, key_path(key));
}

std::string TableReader::required_string(std::string_view key) const {
  if (!has(key)) missing(key);
  std::string s = *string(key);
  if (s.empty()) fail(key, key_path(key) + " must not be empty");
  return s;
}

std::optional<bool> TableReader::boolean(std::string_view key) const {
  const toml::node* n = find(key);
  if (!n) return std::nullopt;
  auto b = n->value_exact<bool>();
  if (!b) ctx_.fail(*n, key_path(key) + " must be a boolean, found " + describe(*n));
  return b;
}

std::optional<std::array<double, 2>> TableReader::pair(std::string_view key) const {
  const toml::node* n = find(key);
  if (!n) return std::nullopt;
  const toml::array* a = n->as_array();
  if (!a || a->size() != 2)
    ctx_.fail(*n, key_path(key) + " must be an array of 2 numbers, found " + describe(*n));
  return std::array<double, 2>{as_number(ctx_, *a->get(0), key_path(key) + "[0]", kAny),
                               as_number(ctx_, *a->get(1), key_path(key) + "[1]", kAny)};
}

std::optional<std::vector<std::string>> TableReader::strings(std::string_view key) const {
  const toml::node* n = find(key);
  if (!n) return std::nullopt;
  const toml::array* a = n->as_array();
  if (!a || a->empty())
    ctx_.fail(*n, key_path(key) + " must be a non-empty array of strings, found " +
                      describe(*n));
  std::vector<std::string> out;
  for (std::size_t i = 0; i < a->size(); ++i)
    out.push_back(as_string(ctx_, *a->get(i), key_path(key) + "[" + std::to_string(i) + "]"));
  return out;
}

std::optional<std::optional<double>> TableReader::number_or_keyword(std::string_view key,
                                                                    std::string_view keyword,
                                                                    const Range& range) const {
  const toml::node* n = find(key);
  if (!n) return std::nullopt;
  if (n->value_exact<std::string>() == keyword) return std::optional<double>{};
  if (!n->is_number())
    fail(key, key_path(key) + " must be a number or the string \"" + std::string(keyword) +
                  "\", found " + describe(*n));
  return std::optional<double>{as_number(ctx_, *n, key_path(key), range)};
}

// ---------------------------------------------------------------------------------------
// Sub-tables and arrays of tables

std::vector<const toml::table*> table_array(const TableReader& top, std::string_view key) {
  std::vector<const toml::table*> out;
  const toml::node* n = top.find(key);
  if (!n) return out;
  const toml::array* a = n->as_array();
  if (!a || !a->is_array_of_tables())
    top.fail(key, top.key_path(key) + " must be an array of tables (write [[" +
                      top.key_path(key) + "]] entries), found " + describe(*n));
  for (const toml::node& entry : *a) out.push_back(entry.as_table());
  return out;
}

const toml::table* subtable(const TableReader& r, std::string_view key) {
  const toml::node* n = r.find(key);
  if (n && !n->is_table())
    r.fail(key, r.key_path(key) + " must be a table, found " + describe(*n));
  return n ? n->as_table() : nullptr;
}

TableReader subtable_reader(const TableReader& r, const toml::table& t, std::string_view key) {
  const std::string path = r.key_path(key);
  return TableReader(r.ctx(), t, path, path, path);
}

std::vector<double> read_numbers(const TableReader& r, std::string_view key) {
  if (!r.has(key)) r.missing(key);
  const toml::array* a = r.find(key)->as_array();
  if (!a || a->empty())
    r.fail(key, r.key_path(key) + " must be a non-empty array of numbers, found " + describe(*r.find(key)));
  std::vector<double> out;
  for (std::size_t i = 0; i < a->size(); ++i)
    out.push_back(as_number(r.ctx(), *a->get(i), r.key_path(key) + "[" + std::to_string(i) + "]", kAny));
  return out;
}

}  // namespace fdem::io::detail
