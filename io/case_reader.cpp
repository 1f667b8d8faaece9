// read_case: parses the TOML, applies the --set overrides (io/case_overrides.hpp), then
// reads each table through its reader (io/case_tables.hpp). The known keys of every
// table are listed once, in io/case_schema.cpp.
#include "io/case_config.hpp"

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "base/errors.hpp"
#include "io/case_overrides.hpp"
#include "io/case_tables.hpp"

namespace fdem::io {

using namespace detail;
namespace fs = std::filesystem;

namespace {

// A value as TOML text; numbers with the fewest digits that read back to the same double.
std::string value_text(const toml::node& node) {
  if (const auto* d = node.as_floating_point()) {
    const double v = d->get();
    for (int digits = 1; digits <= 17; ++digits) {
      std::ostringstream s;
      s << std::setprecision(digits) << v;
      if (std::stod(s.str()) == v) return s.str();
    }
  }
  if (const auto* a = node.as_array()) {
    std::string out = "[";
    for (size_t k = 0; k < a->size(); ++k) out += (k ? ", " : "") + value_text(*a->get(k));
    return out + "]";
  }
  std::ostringstream text;
  text << toml::toml_formatter{node};
  return text.str();
}

// Every leaf of the tree by dotted path (arrays of tables indexed), value as TOML text.
void flatten(const toml::node& node, const std::string& path, std::map<std::string, std::string>& out) {
  if (const auto* t = node.as_table()) {
    for (const auto& [key, value] : *t) flatten(value, path.empty() ? std::string(key.str()) : path + "." + std::string(key.str()), out);
  } else if (const auto* a = node.as_array(); a && a->is_array_of_tables()) {
    for (size_t k = 0; k < a->size(); ++k) flatten(*a->get(k), path + "." + std::to_string(k), out);
  } else {
    out[path] = value_text(node);
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
  flatten(root, "", c.settings);
  c.text = content.str();
  return c;
}

}  // namespace fdem::io
