// Reads a TOML case file into CaseConfig. The known keys of every table are listed once
// (the Schema constants below) and serve both to reject unknown keys with a suggestion
// and to walk --set paths; each table then has its own read_* function.
#include "io/case_config.hpp"

#include "base/errors.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string_view>

namespace fdem::io {
namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------
// Schema: the known keys of each table. Adding a key is one line here plus reading it.

enum class Shape { Key, Table, TableArray };

struct Schema;

struct Field {
  constexpr Field(std::string_view n, Shape s = Shape::Key, const Schema* c = nullptr)
      : name(n), shape(s), child(c) {}
  std::string_view name;
  Shape shape;
  const Schema* child;  // the keys of a Table or of each TableArray entry
};

struct Schema {
  std::vector<Field> fields;
  const Field* find(std::string_view name) const {
    for (const Field& f : fields)
      if (f.name == name) return &f;
    return nullptr;
  }
};

const Schema kMeshKeys{{{"geo"}, {"file"}, {"size"}, {"scale"}, {"thickness"}}};
const Schema kTimeKeys{{{"dt"}, {"safety"}, {"end"}, {"steps"}}};
const Schema kOutputKeys{{{"dir"}, {"name"}, {"frames"}, {"every"}, {"history_every"}, {"regions"}}};
const Schema kStiffnessKeys{
    {{"c11"}, {"c22"}, {"c12"}, {"c66"}, {"c16"}, {"c26"}, {"angle"}}};
const Schema kPenaltyKeys{{{"opening"}, {"sliding"}, {"overlap"}}};
const Schema kSofteningKeys{{{"a"}, {"b"}, {"c"}}};
const Schema kFractureKeys{{{"tensile_strength"}, {"cohesion"}, {"friction_angle"}, {"gf1"},
                            {"gf2"}, {"penalty", Shape::Table, &kPenaltyKeys},
                            {"softening", Shape::Table, &kSofteningKeys}}};
const Schema kMaterialKeys{{{"name"}, {"regions"}, {"density"}, {"young"}, {"poisson"},
                            {"elasticity"}, {"plane"}, {"viscosity"},
                            {"stiffness", Shape::Table, &kStiffnessKeys},
                            {"fracture", Shape::Table, &kFractureKeys}}};
// An [[interface]] has the keys of [material.fracture] and the pair of materials.
Schema with_fields(std::vector<Field> fields, const Schema& more) {
  fields.insert(fields.end(), more.fields.begin(), more.fields.end());
  return Schema{std::move(fields)};
}
const Schema kInterfaceKeys = with_fields({{"materials"}}, kFractureKeys);
const Schema kGravityKeys{{{"g"}}};
const Schema kDampingKeys{{{"local"}, {"mass_scaling"}}};
const Schema kBlastKeys{{{"peak"}, {"rise"}, {"ratio"}}};
const Schema kPressureTableKeys{{{"times"}, {"values"}}};
const Schema kBoundaryKeys{{{"region"}, {"fix"}, {"velocity"}, {"rise"}, {"traction"}, {"pressure"},
                            {"blast", Shape::Table, &kBlastKeys}, {"absorbing"}}};
const Schema kInitialKeys{{{"region"}, {"velocity"}}};
const Schema kContactDampingKeys{{{"transition"}, {"exponent"}}};
const Schema kContactPairKeys{{{"materials"}, {"normal_penalty"}, {"tangential_penalty"},
                               {"friction"}, {"damping", Shape::Table, &kContactDampingKeys}}};
const Schema kContactKeys{{{"normal_penalty"}, {"tangential_penalty"}, {"friction"},
                           {"damping", Shape::Table, &kContactDampingKeys}, {"activation"},
                           {"regions"}, {"rebuild"}, {"skin"},
                           {"pair", Shape::TableArray, &kContactPairKeys}}};
const Schema kProbeKeys{{{"name"}, {"point"}}};
const Schema kRootKeys{{{"title"},
                        {"mesh", Shape::Table, &kMeshKeys},
                        {"time", Shape::Table, &kTimeKeys},
                        {"output", Shape::Table, &kOutputKeys},
                        {"material", Shape::TableArray, &kMaterialKeys},
                        {"interface", Shape::TableArray, &kInterfaceKeys},
                        {"gravity", Shape::Table, &kGravityKeys},
                        {"damping", Shape::Table, &kDampingKeys},
                        {"boundary", Shape::TableArray, &kBoundaryKeys},
                        {"initial", Shape::TableArray, &kInitialKeys},
                        {"contact", Shape::Table, &kContactKeys},
                        {"probe", Shape::TableArray, &kProbeKeys}}};

// ---------------------------------------------------------------------------------------
// Suggestions for misspelt names.

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      const bool same = std::tolower(static_cast<unsigned char>(a[i - 1])) ==
                        std::tolower(static_cast<unsigned char>(b[j - 1]));
      row[j] = std::min({above + 1, row[j - 1] + 1, diagonal + (same ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// The nearest candidate, if it is close enough to be a plausible typo.
std::optional<std::string_view> nearest(std::string_view name,
                                        const std::vector<std::string_view>& candidates) {
  std::optional<std::string_view> best;
  std::size_t best_distance = std::numeric_limits<std::size_t>::max();
  for (std::string_view c : candidates) {
    const std::size_t d = edit_distance(name, c);
    if (d < best_distance) best_distance = d, best = c;
  }
  if (best && best_distance <= std::max<std::size_t>(2, name.size() / 3)) return best;
  return std::nullopt;
}

// How a name is written in messages: top-level tables in brackets, keys in quotes.
std::string spelled(std::string_view name, Shape shape, bool top_level) {
  if (top_level && shape == Shape::Table) return "[" + std::string(name) + "]";
  if (top_level && shape == Shape::TableArray) return "[[" + std::string(name) + "]]";
  return "'" + std::string(name) + "'";
}

// "unknown key 'youngs' in [[material]] (did you mean 'young'?)"; at the top level a
// table is "unknown table [gravty]". `heading` is empty for the top level.
std::string unknown_name_message(std::string_view name, Shape found, const Schema& schema,
                                 const std::string& heading) {
  const bool top = heading.empty();
  std::string msg;
  if (top && found != Shape::Key)
    msg = "unknown table " + spelled(name, found, top);
  else
    msg = "unknown key '" + std::string(name) + "'" + (top ? "" : " in " + heading);
  std::vector<std::string_view> names;
  for (const Field& f : schema.fields) names.push_back(f.name);
  if (auto guess = nearest(name, names))
    msg += " (did you mean " + spelled(*guess, schema.find(*guess)->shape, top) + "?)";
  return msg;
}

Shape shape_of(const toml::node& n) {
  if (n.is_table()) return Shape::Table;
  return n.is_array_of_tables() ? Shape::TableArray : Shape::Key;
}

// ---------------------------------------------------------------------------------------
// Formatting values for messages.

std::string format_number(double v) {
  std::ostringstream s;
  s.precision(15);
  s << v;
  return s.str();
}

std::string describe(const toml::node& n) {
  if (auto s = n.value_exact<std::string>()) return "string \"" + *s + "\"";
  if (auto i = n.value_exact<std::int64_t>()) return "integer " + std::to_string(*i);
  if (auto d = n.value_exact<double>()) return "number " + format_number(*d);
  if (auto b = n.value_exact<bool>()) return std::string("boolean ") + (*b ? "true" : "false");
  if (auto* a = n.as_array())
    return a->is_array_of_tables() ? "array of tables" : "array of " + std::to_string(a->size());
  if (n.is_table()) return "table";
  return "a date/time";
}

// "0 < safety <= 1", "density > 0": the allowed range, spelled with the key's name.
struct Range {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false, hi_open = false;

  bool contains(double v) const {
    return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  }
  std::string text(std::string_view name) const {
    const std::string n(name);
    const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
    if (has_lo && has_hi)
      return format_number(lo) + (lo_open ? " < " : " <= ") + n + (hi_open ? " < " : " <= ") +
             format_number(hi);
    if (has_lo) return n + (lo_open ? " > " : " >= ") + format_number(lo);
    if (has_hi) return n + (hi_open ? " < " : " <= ") + format_number(hi);
    return n + " finite";
  }
};

const Range kAny{};
const Range kPositive{0.0, std::numeric_limits<double>::infinity(), true, false};
const Range kNonNegative{0.0, std::numeric_limits<double>::infinity(), false, false};

// ---------------------------------------------------------------------------------------
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

  bool from_override(const toml::node& n) const {
    const toml::source_region& src = n.source();
    return created_.count(&n) || (src.path && override_sources_.count(*src.path));
  }
  std::string where(const toml::node& n) const {
    if (auto it = created_.find(&n); it != created_.end()) return from_set(it->second);
    const toml::source_region& src = n.source();
    if (src.path && override_sources_.count(*src.path)) return from_set(*src.path);
    return path_ + ":" + std::to_string(std::max<toml::source_index>(src.begin.line, 1));
  }
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

// ---------------------------------------------------------------------------------------
// Typed access to one table; every failure names the key's dotted path.

double as_number(const Context& ctx, const toml::node& n, const std::string& path,
                 const Range& range) {
  std::optional<double> v;
  if (auto i = n.value_exact<std::int64_t>()) v = static_cast<double>(*i);
  if (auto d = n.value_exact<double>()) v = *d;
  if (!v) ctx.fail(n, path + " must be a number, found " + describe(n));
  if (!std::isfinite(*v)) ctx.fail(n, path + " must be finite, found " + format_number(*v));
  if (!range.contains(*v))
    ctx.fail(n, path + " = " + format_number(*v) + " is out of range (allowed: " +
                    range.text(path) + ")");
  return *v;
}

std::string as_string(const Context& ctx, const toml::node& n, const std::string& path) {
  auto s = n.value_exact<std::string>();
  if (!s) ctx.fail(n, path + " must be a string, found " + describe(n));
  return *s;
}

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

  void check_keys(const Schema& schema) const {
    for (auto&& [key, node] : table_)
      if (!schema.find(key.str()))
        ctx_.fail(node, unknown_name_message(key.str(), shape_of(node), schema, heading_));
  }

  // Fails at the key's own line, or at the table's line when the key is absent.
  [[noreturn]] void fail(std::string_view key, const std::string& what) const {
    const toml::node* n = find(key);
    ctx_.fail(n ? *n : static_cast<const toml::node&>(table_), what);
  }
  [[noreturn]] void missing(std::string_view key) const {
    ctx_.fail(table_, title_ + " is missing required key '" + std::string(key) + "'");
  }
  // Of two keys, the one a message about both is reported at: the only one present,
  // else the one given by --set, else the later of the two in the file.
  std::string_view blamed(std::string_view a, std::string_view b) const {
    if (!has(a) || !has(b)) return has(a) ? a : b;
    const toml::node &na = *find(a), &nb = *find(b);
    const bool blame_a = ctx_.from_override(na) != ctx_.from_override(nb)
                             ? ctx_.from_override(na)
                             : na.source().begin.line > nb.source().begin.line;
    return blame_a ? a : b;
  }
  void exclusive(std::string_view a, std::string_view b) const {
    if (!has(a) || !has(b)) return;
    fail(blamed(a, b), key_path(a) + " and " + key_path(b) + " are exclusive: give only one");
  }
  void exactly_one(std::string_view a, std::string_view b) const {
    exclusive(a, b);
    if (!has(a) && !has(b))
      ctx_.fail(table_, title_ + " needs one of '" + std::string(a) + "' or '" +
                            std::string(b) + "'");
  }

  std::optional<double> number(std::string_view key, const Range& range = kAny) const {
    const toml::node* n = find(key);
    if (!n) return std::nullopt;
    return as_number(ctx_, *n, key_path(key), range);
  }
  double required_number(std::string_view key, const Range& range = kAny) const {
    if (!has(key)) missing(key);
    return *number(key, range);
  }
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
  std::optional<std::string> string(std::string_view key) const {
    const toml::node* n = find(key);
    if (!n) return std::nullopt;
    return as_string(ctx_, *n, key_path(key));
  }
  std::string required_string(std::string_view key) const {
    if (!has(key)) missing(key);
    std::string s = *string(key);
    if (s.empty()) fail(key, key_path(key) + " must not be empty");
    return s;
  }
  std::optional<bool> boolean(std::string_view key) const {
    const toml::node* n = find(key);
    if (!n) return std::nullopt;
    auto b = n->value_exact<bool>();
    if (!b) ctx_.fail(*n, key_path(key) + " must be a boolean, found " + describe(*n));
    return b;
  }
  // An array of exactly two numbers: vectors in the plane.
  std::optional<std::array<double, 2>> pair(std::string_view key) const {
    const toml::node* n = find(key);
    if (!n) return std::nullopt;
    const toml::array* a = n->as_array();
    if (!a || a->size() != 2)
      ctx_.fail(*n, key_path(key) + " must be an array of 2 numbers, found " + describe(*n));
    return std::array<double, 2>{as_number(ctx_, *a->get(0), key_path(key) + "[0]", kAny),
                                 as_number(ctx_, *a->get(1), key_path(key) + "[1]", kAny)};
  }
  std::optional<std::vector<std::string>> strings(std::string_view key) const {
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
    if (auto guess = nearest(*s, names)) msg += " (did you mean \"" + std::string(*guess) + "\"?)";
    fail(key, msg);
  }
  // A number, or one keyword in its place (dt = "auto"); nullopt inside means the keyword.
  std::optional<std::optional<double>> number_or_keyword(std::string_view key,
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

 private:
  const Context& ctx_;
  const toml::table& table_;
  std::string path_, heading_, title_;
};

// The entries of an array of tables such as [[material]] or [[contact.pair]] (`top` being
// the reader of [contact]); empty when absent.
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

// ---------------------------------------------------------------------------------------
// One function per table.

std::string resolve_against(const std::string& dir, const std::string& file) {
  const fs::path p(file);
  if (p.is_absolute()) return file;
  return (fs::path(dir) / p).lexically_normal().string();
}

MeshConfig read_mesh(const TableReader& r, const std::string& case_dir) {
  r.check_keys(kMeshKeys);
  r.exactly_one("geo", "file");
  MeshConfig m;
  const std::string_view key = r.has("geo") ? "geo" : "file";
  const std::string resolved = resolve_against(case_dir, r.required_string(key));
  std::error_code ec;
  if (!fs::is_regular_file(resolved, ec))
    r.fail(key, r.key_path(key) + ": file not found: " + resolved);
  (key == "geo" ? m.geo : m.file) = resolved;
  if (r.has("size") && key == "file")
    r.fail("size", "mesh.size only applies with mesh.geo (gmsh meshes the .geo at that size)");
  m.size = r.number("size", kPositive).value_or(0.0);
  m.scale = r.number("scale", kPositive).value_or(1.0);
  m.thickness = r.number("thickness", kPositive).value_or(1.0);
  return m;
}

TimeConfig read_time(const TableReader& r) {
  r.check_keys(kTimeKeys);
  TimeConfig t;
  if (!r.has("dt")) r.missing("dt");
  const std::optional<double> dt = *r.number_or_keyword("dt", "auto", kPositive);
  t.dt_auto = !dt;
  t.dt = dt.value_or(0.0);
  t.safety = r.number("safety", Range{0.0, 1.0, true, false}).value_or(0.5);
  r.exactly_one("end", "steps");
  t.end = r.number("end", kPositive).value_or(-1.0);
  t.steps = r.integer<long>("steps", 1).value_or(-1);
  return t;
}

OutputConfig read_output(const TableReader& r, const std::string& case_path) {
  r.check_keys(kOutputKeys);
  OutputConfig o;
  if (auto dir = r.string("dir")) o.dir = *dir;
  o.name = r.string("name").value_or(fs::path(case_path).stem().string());
  if (o.dir.empty()) r.fail("dir", "output.dir must not be empty");
  if (o.name.empty()) r.fail("name", "output.name must not be empty");
  r.exclusive("frames", "every");
  o.every = r.number("every", kPositive).value_or(-1.0);
  o.frames = r.integer<int>("frames", 1).value_or(o.every > 0 ? -1 : 20);
  o.history_every = r.number("history_every", kPositive).value_or(-1.0);
  if (r.has("regions")) o.regions = *r.strings("regions");
  return o;
}

Stiffness read_stiffness(const TableReader& r) {
  r.check_keys(kStiffnessKeys);
  Stiffness s;
  s.c11 = r.required_number("c11", kPositive);
  s.c22 = r.required_number("c22", kPositive);
  s.c12 = r.required_number("c12");
  s.c66 = r.required_number("c66", kPositive);
  s.c16 = r.number("c16").value_or(0.0);
  s.c26 = r.number("c26").value_or(0.0);
  s.angle = r.number("angle").value_or(0.0);
  // Leading principal minors of [[c11 c12 c16] [c12 c22 c26] [c16 c26 c66]]: a matrix that
  // is not positive definite has zero or negative strain energy for some strain.
  const double minor2 = s.c11 * s.c22 - s.c12 * s.c12;
  const double det = s.c11 * (s.c22 * s.c66 - s.c26 * s.c26) -
                     s.c12 * (s.c12 * s.c66 - s.c26 * s.c16) +
                     s.c16 * (s.c12 * s.c26 - s.c22 * s.c16);
  if (minor2 <= 0 || det <= 0)
    r.ctx().fail(r.table(), r.path() + " is not positive definite (need c11*c22 > c12^2 and a "
                                "positive determinant including c16, c26, c66)");
  return s;
}

// The keys [material.fracture] and [[interface]] share (the CE4 law, Eqs. 4–14); the
// caller checks for unknown keys, since an [[interface]] has one more.
FractureConfig read_fracture_keys(const TableReader& r) {
  FractureConfig f;
  f.tensile_strength = r.required_number("tensile_strength", kPositive);
  f.cohesion = r.required_number("cohesion", kPositive);
  f.friction_angle = r.required_number("friction_angle", Range{0.0, 90.0, false, true});
  f.gf1 = r.required_number("gf1", kPositive);
  f.gf2 = r.required_number("gf2", kPositive);
  if (!r.has("penalty")) r.missing("penalty");
  const std::string penalty_path = r.key_path("penalty");
  const TableReader penalty(r.ctx(), *subtable(r, "penalty"), penalty_path, penalty_path,
                            penalty_path);
  penalty.check_keys(kPenaltyKeys);
  f.penalty_opening = penalty.required_number("opening", kPositive);
  f.penalty_sliding = penalty.required_number("sliding", kPositive);
  f.penalty_overlap = penalty.required_number("overlap", kPositive);
  if (const toml::table* t = subtable(r, "softening")) {
    const std::string path = r.key_path("softening");
    const TableReader softening(r.ctx(), *t, path, path, path);
    softening.check_keys(kSofteningKeys);
    f.softening_a = softening.number("a", kPositive).value_or(f.softening_a);
    f.softening_b = softening.number("b", kPositive).value_or(f.softening_b);
    f.softening_c = softening.number("c", kPositive).value_or(f.softening_c);
    // Eq. 10 divides by 1 - a - b and needs f(0) = 1 > f(1) = 0 in between.
    if (!(f.softening_a + f.softening_b > 1.0))
      softening.fail(softening.blamed("a", "b"),
                     path + ": a + b = " + format_number(f.softening_a + f.softening_b) +
                         " is out of range (allowed: a + b > 1)");
  }
  return f;
}

MaterialConfig read_material(const TableReader& r) {
  r.check_keys(kMaterialKeys);
  MaterialConfig m;
  m.name = r.required_string("name");
  if (!r.has("regions")) r.missing("regions");
  m.regions = *r.strings("regions");
  m.density = r.required_number("density", kPositive);
  m.young = r.required_number("young", kPositive);
  m.poisson = r.required_number("poisson", Range{-1.0, 0.5, true, true});
  m.elasticity = r.choice<Elasticity>("elasticity", {{"neo-hookean", Elasticity::NeoHookean},
                                                     {"hyperelastic", Elasticity::Hyperelastic}})
                     .value_or(Elasticity::NeoHookean);
  m.plane = r.choice<Plane>("plane", {{"strain", Plane::Strain}, {"stress", Plane::Stress}})
                .value_or(Plane::Strain);
  if (const toml::table* t = subtable(r, "stiffness")) {
    if (m.elasticity != Elasticity::Hyperelastic)
      r.fail("stiffness", r.key_path("stiffness") +
                              " is only allowed with elasticity = \"hyperelastic\"");
    const std::string path = r.key_path("stiffness");
    m.stiffness = read_stiffness(TableReader(r.ctx(), *t, path, path, path));
  }
  if (const toml::table* t = subtable(r, "fracture")) {
    const std::string path = r.key_path("fracture");
    const TableReader fracture(r.ctx(), *t, path, path,
                               "[material.fracture] of " + r.path() + " ('" + m.name + "')");
    fracture.check_keys(kFractureKeys);
    m.fracture = read_fracture_keys(fracture);
  }
  if (auto v = r.number_or_keyword("viscosity", "critical", kNonNegative)) {
    m.viscosity_critical = !*v;
    m.viscosity = v->value_or(0.0);
  }
  return m;
}

std::vector<MaterialConfig> read_materials(const TableReader& top) {
  std::map<std::string, std::string> path_of_name;    // "rock" → "material[0]"
  std::map<std::string, std::string> owner_of_region;  // region → "material[0] ('rock')"
  auto materials = read_entries(top, "material", "name", [&](const TableReader& r) {
    MaterialConfig m = read_material(r);
    if (auto [it, fresh] = path_of_name.emplace(m.name, r.path()); !fresh)
      r.fail("name", r.key_path("name") + ": '" + m.name + "' is already the name of " +
                         it->second);
    for (const std::string& region : m.regions)
      if (auto [it, fresh] = owner_of_region.emplace(region, r.path() + " ('" + m.name + "')");
          !fresh)
        r.fail("regions", r.key_path("regions") + ": region '" + region + "' is already in " +
                              it->second + ": a region belongs to one material");
    return m;
  });
  if (materials.empty()) top.ctx().fail(top.table(), "the case needs at least one [[material]]");
  return materials;
}

GravityConfig read_gravity(const TableReader& r) {
  r.check_keys(kGravityKeys);
  if (!r.has("g")) r.missing("g");
  return GravityConfig{*r.pair("g")};
}

DampingConfig read_damping(const TableReader& r) {
  r.check_keys(kDampingKeys);
  DampingConfig d;
  if (auto alpha = r.number("local", Range{0.0, 1.0, false, true})) {
    d.local_enabled = true;
    d.local = *alpha;
  }
  d.mass_scaling = r.boolean("mass_scaling").value_or(false);
  return d;
}

// An array of numbers of any length (at least one), e.g. times = [0.0, 1e-4].
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

// `pressure` is a number, or a table { times, values } of a piecewise linear pressure;
// `blast = { peak, rise, ratio }` is the pressure of Eq. 21.
void read_boundary_pressure(const TableReader& r, BoundaryConfig& b) {
  const toml::node* p = r.find("pressure");
  if (p && p->is_table()) {
    const std::string path = r.key_path("pressure");
    const TableReader t(r.ctx(), *p->as_table(), path, path, path);
    t.check_keys(kPressureTableKeys);
    PressureTable table{read_numbers(t, "times"), read_numbers(t, "values")};
    if (table.times.size() != table.values.size())
      t.fail("values", path + ": times has " + std::to_string(table.times.size()) + " entries but values has " +
                           std::to_string(table.values.size()) + "; give one value per time");
    for (std::size_t i = 1; i < table.times.size(); ++i)
      if (!(table.times[i] > table.times[i - 1]))
        t.fail("times", path + ".times must increase: times[" + std::to_string(i) + "] = " +
                            format_number(table.times[i]) + " follows " + format_number(table.times[i - 1]));
    b.pressure_table = table;
  } else if (p && !p->is_number()) {
    r.fail("pressure", r.key_path("pressure") + " must be a number or a table { times = [...], values = [...] }, found " +
                           describe(*p));
  } else {
    b.pressure = r.number("pressure");
  }
  if (const toml::table* t = subtable(r, "blast")) {
    const std::string path = r.key_path("blast");
    const TableReader blast(r.ctx(), *t, path, path, path);
    blast.check_keys(kBlastKeys);
    b.blast = BlastConfig{blast.required_number("peak", kPositive), blast.required_number("rise", kPositive),
                          blast.required_number("ratio", Range{1.0, std::numeric_limits<double>::infinity(), true, false})};
  }
}

BoundaryConfig read_boundary(const TableReader& r) {
  r.check_keys(kBoundaryKeys);
  BoundaryConfig b;
  b.region = r.required_string("region");
  if (const toml::node* fix = r.find("fix")) {
    const std::vector<std::string> axes = *r.strings("fix");
    for (std::size_t i = 0; i < axes.size(); ++i) {
      bool& flag = axes[i] == "x" ? b.fix_x : b.fix_y;
      if (axes[i] != "x" && axes[i] != "y")
        r.ctx().fail(*fix->as_array()->get(i), r.key_path("fix") + "[" + std::to_string(i) +
                                                   "] = \"" + axes[i] +
                                                   "\" is not an axis (allowed: \"x\", \"y\")");
      if (flag) r.fail("fix", r.key_path("fix") + " lists \"" + axes[i] + "\" twice");
      flag = true;
    }
  }
  b.velocity = r.pair("velocity");
  b.traction = r.pair("traction");
  read_boundary_pressure(r, b);
  b.absorbing = r.boolean("absorbing").value_or(false);
  const bool loads = b.traction || b.pressure || b.pressure_table || b.blast || b.absorbing;
  const bool motion = b.fix_x || b.fix_y || b.velocity;
  if (!loads && !motion)
    r.ctx().fail(r.table(), r.title() + " needs at least one of 'fix', 'velocity', 'traction', "
                                    "'pressure', 'blast', 'absorbing = true'");
  const char* kinds[] = {"traction", "pressure", "blast", "absorbing"};
  const int count = b.absorbing ? 4 : 3;  // absorbing = false is no load
  for (int i = 0; i < count; ++i)
    for (int j = i + 1; j < count; ++j) r.exclusive(kinds[i], kinds[j]);
  if (loads && motion) {
    const char* load = b.traction ? "traction" : b.blast ? "blast" : b.absorbing ? "absorbing" : "pressure";
    r.fail(load, r.key_path(load) + " cannot be combined with fix or velocity in one [[boundary]]: use two entries");
  }
  for (int axis = 0; axis < 2; ++axis)
    if (b.velocity && (axis == 0 ? b.fix_x : b.fix_y) && (*b.velocity)[axis] != 0.0)
      r.fail("velocity", r.key_path("velocity") + "[" + std::to_string(axis) + "] = " +
                             format_number((*b.velocity)[axis]) + " but " + r.key_path("fix") +
                             " holds \"" + (axis == 0 ? "x" : "y") +
                             "\" still: it must be 0");
  if (r.has("rise") && !b.velocity && !b.traction && !b.pressure)
    r.fail("rise", r.key_path("rise") + " needs a velocity, traction or pressure to ramp" +
                       (b.blast ? " (a blast has its own rise inside: blast = { rise = ... })"
                        : b.pressure_table ? " (a pressure table gives the time dependence itself)"
                                           : ""));
  b.rise = r.number("rise", kNonNegative).value_or(0.0);
  return b;
}

InitialConfig read_initial(const TableReader& r) {
  r.check_keys(kInitialKeys);
  InitialConfig c;
  c.region = r.required_string("region");
  if (!r.has("velocity")) r.missing("velocity");
  c.velocity = *r.pair("velocity");
  return c;
}

ContactDampingConfig read_contact_damping(const TableReader& r) {
  r.check_keys(kContactDampingKeys);
  ContactDampingConfig d;
  if (auto t = r.number("transition", kPositive)) d.transition = *t;
  d.exponent = r.number("exponent", Range{1.0, std::numeric_limits<double>::infinity()})
                   .value_or(1.0);
  return d;
}

// `damping = { ... }` inside [contact] or a [[contact.pair]]; nullopt when absent.
std::optional<ContactDampingConfig> read_contact_damping_in(const TableReader& r) {
  const toml::table* t = subtable(r, "damping");
  if (!t) return std::nullopt;
  const std::string path = r.key_path("damping");
  return read_contact_damping(TableReader(r.ctx(), *t, path, path, path));
}

// `materials = ["rock", "steel"]` of a [[contact.pair]] or an [[interface]]: two names of
// [[material]] entries; a misspelt one gets a suggestion.
std::array<std::string, 2> material_names(const TableReader& r,
                                          const std::vector<MaterialConfig>& materials) {
  std::array<std::string, 2> out;
  if (!r.has("materials")) r.missing("materials");
  const toml::node& names = *r.find("materials");
  const toml::array* a = names.as_array();
  if (!a || a->size() != 2)
    r.fail("materials", r.key_path("materials") +
                            " must be an array of 2 material names, found " + describe(names));
  std::vector<std::string_view> known;
  for (const MaterialConfig& m : materials) known.push_back(m.name);
  for (std::size_t i = 0; i < 2; ++i) {
    const toml::node& n = *a->get(i);
    const std::string path = r.key_path("materials") + "[" + std::to_string(i) + "]";
    out[i] = as_string(r.ctx(), n, path);
    if (std::find(known.begin(), known.end(), out[i]) != known.end()) continue;
    std::string msg = path + " = \"" + out[i] + "\" is not the name of a [[material]]";
    if (auto guess = nearest(out[i], known))
      msg += " (did you mean \"" + std::string(*guess) + "\"?)";
    r.ctx().fail(n, msg);
  }
  return out;
}

// Each unordered pair once: ("rock", "steel") and ("steel", "rock") are the same.
// `seen` maps the pairs so far to the entry that gave them ("contact.pair[0]").
using PairEntries = std::map<std::pair<std::string, std::string>, std::string>;
void check_new_pair(PairEntries& seen, const TableReader& entry,
                    const std::array<std::string, 2>& names) {
  const auto key = std::minmax(names[0], names[1]);
  if (auto [it, fresh] = seen.emplace(key, entry.path()); !fresh)
    entry.fail("materials", entry.key_path("materials") + ": the pair ('" + key.first +
                                "', '" + key.second + "') is already given in " + it->second);
}

ContactPairConfig read_contact_pair(const TableReader& r,
                                    const std::vector<MaterialConfig>& materials) {
  r.check_keys(kContactPairKeys);
  ContactPairConfig p;
  p.materials = material_names(r, materials);
  p.normal_penalty = r.number("normal_penalty", kPositive);
  p.tangential_penalty = r.number("tangential_penalty", kNonNegative);
  p.friction = r.number("friction", kNonNegative);
  p.damping = read_contact_damping_in(r);
  return p;
}

ContactConfig read_contact(const TableReader& r, const std::vector<MaterialConfig>& materials) {
  r.check_keys(kContactKeys);
  ContactConfig c;
  // [[contact.pair]] entries alone make an implicit [contact], at their first line.
  if (!r.has("normal_penalty") && r.has("pair"))
    r.ctx().fail(r.table(), r.title() + " is missing required key 'normal_penalty', which "
                                        "[[contact.pair]] entries need (they override "
                                        "[contact]'s values)");
  c.normal_penalty = r.required_number("normal_penalty", kPositive);
  c.tangential_penalty = r.number("tangential_penalty", kNonNegative).value_or(c.normal_penalty);
  c.friction = r.number("friction", kNonNegative).value_or(0.0);
  c.damping = read_contact_damping_in(r);
  c.activation = r.choice<std::string>("activation", {{"all", "all"}, {"fractured", "fractured"}})
                     .value_or("all");
  if (r.has("regions") && c.activation != "fractured")
    r.fail("regions", r.key_path("regions") + " is only allowed with " +
                          r.key_path("activation") + " = \"fractured\" (with \"all\" every "
                          "triangle takes part in contact from the start)");
  if (r.has("regions")) c.regions = *r.strings("regions");
  c.rebuild = r.choice<ContactRebuild>("rebuild", {{"step", ContactRebuild::Step},
                                                   {"skin", ContactRebuild::Skin}})
                  .value_or(ContactRebuild::Step);
  if (c.rebuild == ContactRebuild::Skin && !r.has("skin"))
    r.fail("rebuild", r.key_path("rebuild") + " = \"skin\" needs " + r.key_path("skin") +
                          " > 0 (the margin by which the boxes are enlarged)");
  c.skin = r.number("skin", c.rebuild == ContactRebuild::Skin ? kPositive : kNonNegative)
               .value_or(0.0);

  PairEntries seen;
  c.pairs = read_entries(r, "pair", "", [&](const TableReader& entry) {
    ContactPairConfig p = read_contact_pair(entry, materials);
    check_new_pair(seen, entry, p.materials);
    return p;
  });
  return c;
}

InterfaceConfig read_interface(const TableReader& r,
                               const std::vector<MaterialConfig>& materials) {
  r.check_keys(kInterfaceKeys);
  InterfaceConfig i;
  i.materials = material_names(r, materials);
  if (i.materials[0] == i.materials[1])
    r.fail("materials", r.key_path("materials") + " names '" + i.materials[0] +
                            "' twice: an interface joins two different materials (within one "
                            "material its [material.fracture] applies)");
  for (std::size_t k = 0; k < 2; ++k) {
    const auto m = std::find_if(materials.begin(), materials.end(),
                                [&](const MaterialConfig& c) { return c.name == i.materials[k]; });
    if (!m->fracture)
      r.ctx().fail(*r.find("materials")->as_array()->get(k),
                   r.key_path("materials") + "[" + std::to_string(k) + "] = \"" +
                       i.materials[k] + "\" is a [[material]] without [material.fracture]: an "
                       "interface joins two fracturable materials");
  }
  i.fracture = read_fracture_keys(r);
  return i;
}

std::vector<InterfaceConfig> read_interfaces(const TableReader& top,
                                             const std::vector<MaterialConfig>& materials) {
  PairEntries seen;
  return read_entries(top, "interface", "", [&](const TableReader& entry) {
    InterfaceConfig i = read_interface(entry, materials);
    check_new_pair(seen, entry, i.materials);
    return i;
  });
}

// [[probe]] entries: the name prefixes history variables, so it must be a netCDF-safe
// identifier and unique. Whether the point lies in the mesh is checked with the model.
std::vector<ProbeConfig> read_probes(const TableReader& top) {
  std::map<std::string, std::string> seen;  // name -> entry that gave it
  return read_entries(top, "probe", "name", [&](const TableReader& r) {
    r.check_keys(kProbeKeys);
    ProbeConfig p;
    p.name = r.required_string("name");
    const bool identifier = std::isalpha(static_cast<unsigned char>(p.name[0])) &&
                            std::all_of(p.name.begin(), p.name.end(), [](char c) {
                              return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
                            });
    if (!identifier)
      r.fail("name", r.key_path("name") + " = \"" + p.name + "\" must start with a letter and "
                     "hold only letters, digits and '_' (it prefixes history variables)");
    if (auto [it, fresh] = seen.emplace(p.name, r.path()); !fresh)
      r.fail("name", r.key_path("name") + " = \"" + p.name + "\" is already the name of " +
                         it->second + ": probe names must be unique");
    if (!r.has("point")) r.missing("point");
    p.point = *r.pair("point");
    return p;
  });
}

// ---------------------------------------------------------------------------------------
// --set: "a.b.c=value" edits the parsed tree before validation.

bool is_index(std::string_view s) {
  return !s.empty() && s.size() < 10 &&
         std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

void apply_override(toml::table& root, const std::string& text, Context& ctx) {
  const std::string source_name = "--set " + text;
  auto fail = [&](const std::string& what) -> void {
    throw InputError(ctx.from_set(source_name) + ": " + what);
  };
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos) fail("expected key.path=value");
  const std::string key_path = text.substr(0, eq), value_text = text.substr(eq + 1);
  std::vector<std::string> parts;
  for (std::size_t start = 0;;) {
    const std::size_t dot = key_path.find('.', start);
    parts.push_back(key_path.substr(start, dot - start));
    if (parts.back().empty()) fail("empty component in key path '" + key_path + "'");
    if (dot == std::string::npos) break;
    start = dot + 1;
  }

  toml::table parsed;
  try {
    parsed = toml::parse("v = " + value_text, source_name);
  } catch (const toml::parse_error& e) {
    // A bare word (output.dir=out2) is taken as a string, as a shell user would expect;
    // anything that starts like an array, table or quoted string must be valid TOML.
    const bool bare_word = !value_text.empty() && value_text.find_first_of("[]{}\"'\n=") == std::string::npos;
    if (!bare_word)
      fail("value '" + value_text + "' is not valid TOML (" + std::string(e.description()) + ")");
    parsed = toml::parse("v = '" + value_text + "'", source_name);  // a TOML literal string
  }
  if (parsed.size() != 1 || !parsed.contains("v")) fail("the value must be one TOML value");
  ctx.add_override(source_name);
  toml::node& value = *parsed.get("v");

  // Walk down, checking each name against the schema so a typo is caught here, with the
  // same suggestion an unknown key in the file gets.
  toml::node* cur = &root;
  const Schema* schema = &kRootKeys;
  // The path walked so far as given ("contact.pair.0") and as the reader spells it
  // ("contact.pair[0]"), and the table kind for messages ("[[contact.pair]]").
  std::string shown, path, heading;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const std::string& part = parts[i];
    const bool last = i + 1 == parts.size();
    if (toml::array* entries = cur->as_array()) {
      if (!is_index(part))
        fail(shown + " is an array of tables: give an index, e.g. " + shown + ".0." + part);
      const std::size_t index = std::stoul(part);
      if (index >= entries->size())
        fail("index " + part + " is out of range: the case has " +
             std::to_string(entries->size()) + " " + heading + " entries (indices start at 0)");
      if (last && !value.is_table()) fail(shown + "." + part + " must be a table");
      if (last) {
        entries->replace(entries->cbegin() + static_cast<std::ptrdiff_t>(index), std::move(value));
        return;
      }
      cur = entries->get(index);
      shown += "." + part;
      path += "[" + part + "]";
      continue;
    }
    toml::table& table = *cur->as_table();
    const Field* field = schema->find(part);
    if (!field) {
      // A name not in the file yet is a table when the path goes on through it.
      const toml::node* existing = table.get(part);
      const Shape found = existing ? shape_of(*existing)
                          : last   ? Shape::Key
                          : is_index(parts[i + 1]) ? Shape::TableArray
                                                   : Shape::Table;
      fail(unknown_name_message(part, found, *schema, heading));
    }
    if (last) {
      table.insert_or_assign(part, std::move(value));
      return;
    }
    shown += (shown.empty() ? "" : ".") + part;
    path += (path.empty() ? "" : ".") + part;
    toml::node* child = table.get(part);
    if (field->shape == Shape::Key) fail(shown + " is a value, not a table");
    if (field->shape == Shape::TableArray) {
      heading = "[[" + path + "]]";
      const std::size_t count = child && child->is_array() ? child->as_array()->size() : 0;
      if (!child || !child->is_array_of_tables()) {
        if (is_index(parts[i + 1]))
          fail("index " + parts[i + 1] + " is out of range: the case has " +
               std::to_string(count) + " " + heading + " entries");
        fail(shown + " is an array of tables: give an index, e.g. " + shown + ".0");
      }
    } else {
      heading = i == 0 ? "[" + part + "]" : path;
      if (!child) {
        child = &table.insert(part, toml::table{}).first->second;
        ctx.note_created(child, source_name);
      } else if (!child->is_table()) {
        fail(shown + " is not a table (found " + describe(*child) + ")");
      }
    }
    cur = child;
    schema = field->child;
  }
}

}  // namespace

CaseConfig read_case(const std::string& path, const std::vector<std::string>& overrides) {
  std::ifstream in(path, std::ios::binary);
  if (!in || fs::is_directory(path)) throw InputError(path + ": cannot open the case file");
  std::ostringstream content;
  content << in.rdbuf();

  toml::table root;
  try {
    root = toml::parse(content.str(), path);
  } catch (const toml::parse_error& e) {
    throw InputError(path + ":" + std::to_string(e.source().begin.line) + ":" +
                     std::to_string(e.source().begin.column) + ": " +
                     std::string(e.description()));
  }
  Context ctx(path);
  for (const std::string& o : overrides) apply_override(root, o, ctx);

  CaseConfig c;
  c.path = path;
  c.dir = fs::path(path).parent_path().string();
  if (c.dir.empty()) c.dir = ".";

  const TableReader top(ctx, root, "", "", "the case file");
  top.check_keys(kRootKeys);
  c.title = top.string("title").value_or("");

  // Each [table] is read through a reader that knows its dotted name.
  auto reader = [&](std::string_view key) -> std::optional<TableReader> {
    const toml::table* t = subtable(top, key);
    if (!t) return std::nullopt;
    const std::string heading = "[" + std::string(key) + "]";
    return TableReader(ctx, *t, std::string(key), heading, heading);
  };
  auto mesh = reader("mesh");
  if (!mesh) ctx.fail(root, "the case is missing required table [mesh]");
  c.mesh = read_mesh(*mesh, c.dir);
  auto time = reader("time");
  if (!time) ctx.fail(root, "the case is missing required table [time]");
  c.time = read_time(*time);
  const toml::table no_output;  // [output] is optional: read its defaults from nothing
  c.output = read_output(reader("output").value_or(
                             TableReader(ctx, no_output, "output", "[output]", "[output]")),
                         path);
  c.materials = read_materials(top);
  c.interfaces = read_interfaces(top, c.materials);
  if (auto gravity = reader("gravity")) c.gravity = read_gravity(*gravity);
  if (auto damping = reader("damping")) c.damping = read_damping(*damping);

  c.boundaries = read_entries(top, "boundary", "region", read_boundary);
  c.initials = read_entries(top, "initial", "region", read_initial);
  if (auto contact = reader("contact")) c.contact = read_contact(*contact, c.materials);
  c.probes = read_probes(top);
  return c;
}

}  // namespace fdem::io
