// Typed access to the parsed TOML tree of a case file. Every failure throws InputError
// naming the file and line (or the --set that gave the value) and the key's dotted path.
#pragma once
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <toml++/toml.h>

#include "base/errors.hpp"
#include "base/format.hpp"
#include "io/case_schema.hpp"

namespace fdem::io::detail {

// Values from the case file are echoed in messages to 15 significant digits.
constexpr int kDigits = 15;

// Every number of a case is 0 or of a magnitude in [1e-30, 1e30] (as_number).
constexpr double kSmallestMagnitude = 1e-30, kLargestMagnitude = 1e30;

// "string \"x\"", "integer 3", "array of 2": what a node holds, for messages.
std::string describe(const toml::node& n);

// "0 < safety <= 1", "density > 0": the allowed range, spelled with the key's name.
struct Range {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false, hi_open = false;

  bool contains(double v) const {
    return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  }
  std::string text(std::string_view name) const;
};

inline const Range kAny{};
inline const Range kPositive{0.0, std::numeric_limits<double>::infinity(), true, false};
inline const Range kNonNegative{0.0, std::numeric_limits<double>::infinity(), false, false};

// Where a node came from: "case.toml:12" or "case.toml (from --set material.0.young=2)".
class Context {
 public:
  explicit Context(std::string case_path) : path_(std::move(case_path)) {}

  const std::string& path() const { return path_; }

  // Override values are parsed with the source name "--set <text>", which is how their
  // nodes are recognised later.
  void add_override(const std::string& source_name) { override_sources_.insert(source_name); }
  void note_created(const toml::node* table, const std::string& source_name) {
    created_[table] = source_name;
  }

  bool from_override(const toml::node& n) const;
  std::string where(const toml::node& n) const;
  std::string from_set(const std::string& source_name) const {
    return path_ + " (from " + source_name + ")";
  }
  [[noreturn]] void fail(const toml::node& n, const std::string& what) const {
    throw InputError(where(n) + ": " + what);
  }

 private:
  std::string path_;
  std::set<std::string> override_sources_;
  std::map<const toml::node*, std::string> created_;  // tables that --set had to create
};

// The fewest digits that read back as v (what the user wrote for a subnormal, where 15
// digits would show round-off: -1e-310, not -9.99999999999997e-311).
std::string shortest_text(double v);
// A string as messages show it: in double quotes, control characters escaped ("a\nb").
std::string quoted_text(std::string_view s);
// The first control character of s (bytes below 0x20, and 0x7f) as "byte 0x0a", or "".
std::string control_character(std::string_view s);

double as_number(const Context& ctx, const toml::node& n, const std::string& path,
                 const Range& range);
std::string as_string(const Context& ctx, const toml::node& n, const std::string& path);

// One table of the case; every failure names the key's dotted path.
class TableReader {
 public:
  // `path` is the dotted prefix of its keys ("material[1]", "" at the top level);
  // `heading` names the table kind in unknown-key messages ("[[material]]");
  // `title` names this very table in missing-key messages ("[[material]] #1 ('rock')").
  TableReader(const Context& ctx, const toml::table& table, std::string path,
              std::string heading, std::string title)
      : ctx_(ctx), table_(table), path_(std::move(path)), heading_(std::move(heading)),
        title_(std::move(title)) {}

  const Context& ctx() const { return ctx_; }
  const toml::table& table() const { return table_; }
  const std::string& path() const { return path_; }
  const std::string& title() const { return title_; }
  const toml::node* find(std::string_view key) const { return table_.get(key); }
  bool has(std::string_view key) const { return table_.contains(key); }
  std::string key_path(std::string_view key) const {
    return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
  }

  // Rejects a key the schema does not list, suggesting the nearest that it does.
  void check_keys(const Schema& schema) const;

  // Fails at the key's own line, or at the table's line when the key is absent.
  [[noreturn]] void fail(std::string_view key, const std::string& what) const;
  [[noreturn]] void missing(std::string_view key) const;
  // Of two keys, the one a message about both is reported at: the only one present,
  // else the one given by --set, else the later of the two in the file.
  std::string_view blamed(std::string_view a, std::string_view b) const;
  void exclusive(std::string_view a, std::string_view b) const;
  void exactly_one(std::string_view a, std::string_view b) const;

  std::optional<double> number(std::string_view key, const Range& range = kAny) const;
  double required_number(std::string_view key, const Range& range = kAny) const;
  // An integer of type T (steps, frames) no smaller than `min`.
  template <class T>
  std::optional<T> integer(std::string_view key, T min) const {
    const toml::node* n = find(key);
    if (!n) return std::nullopt;
    auto v = n->value_exact<std::int64_t>();
    if (!v) ctx_.fail(*n, key_path(key) + " must be an integer, found " + describe(*n));
    const std::int64_t max = std::numeric_limits<T>::max();
    if (*v < min || *v > max)
      ctx_.fail(*n, key_path(key) + " = " + std::to_string(*v) + " is out of range (allowed: " +
                        key_path(key) + " >= " + std::to_string(min) +
                        (max < std::numeric_limits<std::int64_t>::max()
                             ? " and <= " + std::to_string(max) : "") + ")");
    return static_cast<T>(*v);
  }
  std::optional<std::string> string(std::string_view key) const;
  std::string required_string(std::string_view key) const;
  std::optional<bool> boolean(std::string_view key) const;
  // An array of exactly two numbers: vectors in the plane.
  std::optional<std::array<double, 2>> pair(std::string_view key) const;
  std::optional<std::vector<std::string>> strings(std::string_view key) const;
  // A string from a fixed list, e.g. elasticity = "neo-hookean".
  template <class E>
  std::optional<E> choice(std::string_view key,
                          const std::vector<std::pair<std::string_view, E>>& options) const {
    auto s = string(key);
    if (!s) return std::nullopt;
    std::vector<std::string_view> names;
    std::string allowed;
    for (const auto& [name, value] : options) {
      if (name == *s) return value;
      names.push_back(name);
      allowed += (allowed.empty() ? "\"" : ", \"") + std::string(name) + "\"";
    }
    std::string msg = key_path(key) + " = \"" + *s + "\" is not valid (allowed: " + allowed + ")";
    const std::string guess = nearest_key(*s, names);
    if (!guess.empty()) msg += " (did you mean \"" + guess + "\"?)";
    fail(key, msg);
  }
  // A number, or one keyword in its place (dt = "auto"); nullopt inside means the keyword.
  std::optional<std::optional<double>> number_or_keyword(std::string_view key,
                                                         std::string_view keyword,
                                                         const Range& range) const;

 private:
  const Context& ctx_;
  const toml::table& table_;
  std::string path_, heading_, title_;
};

// The entries of an array of tables such as [[material]] or [[contact.pair]] (`top` being
// the reader of [contact]); empty when absent.
std::vector<const toml::table*> table_array(const TableReader& top, std::string_view key);

// The sub-table `key` of r, or nullptr when absent; a non-table there is an error.
const toml::table* subtable(const TableReader& r, std::string_view key);

// A reader for the sub-table at r's `key`, titled by its dotted path (material[0].stiffness).
TableReader subtable_reader(const TableReader& r, const toml::table& t, std::string_view key);

// Reads each entry of an array of tables such as [[boundary]] with `read_entry`, through
// a reader titled by index and label ("[[boundary]] #0 ('left')"; no label when
// `label_key` is empty). Inside a table the kind is dotted: [[contact.pair]], contact.pair[0].
template <class ReadEntry>
auto read_entries(const TableReader& top, std::string_view kind, std::string_view label_key,
                  ReadEntry read_entry) {
  std::vector<decltype(read_entry(top))> out;
  const std::vector<const toml::table*> entries = table_array(top, kind);
  const std::string name = top.key_path(kind), heading = "[[" + name + "]]";
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const std::string index = std::to_string(i);
    std::string title = heading + " #" + index;
    if (!label_key.empty())
      if (auto label = (*entries[i])[label_key].value_exact<std::string>())
        title += " ('" + *label + "')";
    out.push_back(read_entry(
        TableReader(top.ctx(), *entries[i], name + "[" + index + "]", heading, title)));
  }
  return out;
}

// An array of numbers of any length (at least one), e.g. times = [0.0, 1e-4].
std::vector<double> read_numbers(const TableReader& r, std::string_view key);

}  // namespace fdem::io::detail
