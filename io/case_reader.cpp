// read_case: parses the TOML, applies the --set overrides (io/case_overrides.hpp), then
// reads each table through its reader (io/case_tables.hpp). The known keys of every
// table are listed once, in io/case_schema.cpp.
#include "io/case_config.hpp"

#include <cmath>
#include <limits>
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

// A value as TOML text; numbers with the fewest digits that read back to the same double
// (shortest_text reads back with strtod, which unlike stod never throws: a subnormal once
// aborted every run here).
std::string value_text(const toml::node& node) {
  if (const auto* d = node.as_floating_point()) return shortest_text(d->get());
  if (const auto* a = node.as_array()) {
    std::string out = "[";
    for (size_t k = 0; k < a->size(); ++k) out += (k ? ", " : "") + value_text(*a->get(k));
    return out + "]";
  }
  std::ostringstream text;
  text << toml::toml_formatter{node};
  return text.str();
}

// Every leaf of the tree by dotted path (arrays of tables indexed): its value as TOML text
// into `c.settings`, where it came from into `c.origin`.
void flatten(const toml::node& node, const std::string& path, const Context& ctx, CaseConfig& c) {
  if (const auto* t = node.as_table()) {
    for (const auto& [key, value] : *t)
      flatten(value, path.empty() ? std::string(key.str()) : path + "." + std::string(key.str()), ctx, c);
  } else if (const auto* a = node.as_array(); a && a->is_array_of_tables()) {
    for (size_t k = 0; k < a->size(); ++k) flatten(*a->get(k), path + "." + std::to_string(k), ctx, c);
  } else {
    c.settings[path] = value_text(node);
    c.origin[path] = ctx.where(node);
  }
}

// A count as messages write it: every digit up to 2^53, where doubles hold counts exactly.
std::string count_text(double n) {
  return n <= double(kMaxSteps) ? format_number(std::floor(n), 17) : format_number(n, kDigits);
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
  c.joints = read_joints(top, c.dir, c.mesh);
  if (auto grains = reader("grains")) c.grains = read_grains(*grains, c.materials, c.mesh);
  if (auto gravity = reader("gravity")) c.gravity = read_gravity(*gravity);
  if (auto damping = reader("damping")) c.damping = read_damping(*damping);
  if (auto in_situ = reader("in_situ")) c.in_situ = read_in_situ(*in_situ);
  if (auto fluid = reader("fluid")) c.fluid = read_fluid(*fluid);

  c.boundaries = read_entries(top, "boundary", "region", read_boundary);
  c.initials = read_entries(top, "initial", "region", read_initial);
  if (auto contact = reader("contact")) c.contact = read_contact(*contact, c.materials);
  c.probes = read_probes(top);
  c.excavations = read_excavations(top);
  for (size_t i = 0; i < c.boundaries.size(); ++i)
    if (c.boundaries[i].in_situ && !c.in_situ) {
      const toml::table* entry = table_array(top, "boundary")[i];
      ctx.fail(*entry->get("in_situ"), "boundary[" + std::to_string(i) +
                                           "].in_situ = true needs an [in_situ] table: the traction it applies is "
                                           "that field's σ₀·n");
    }
  flatten(root, "", ctx, c);
  c.text = content.str();
  // With a numeric dt (or a step count) the run's length is known now: check it here,
  // so that `fdem check` refuses it at the key's line before the mesh is read. With
  // dt = "auto" what does not depend on dt is checked (frames at most 10^6).
  run_steps(c, c.time.dt_auto ? 0.0 : c.time.dt);
  return c;
}

std::string origin_of(const CaseConfig& c, const std::string& key) {
  auto it = c.origin.find(key);
  return it != c.origin.end() ? it->second : c.path;
}

long run_steps(const CaseConfig& c, double dt) {
  const TimeConfig& t = c.time;
  const OutputConfig& o = c.output;
  const bool known_dt = dt > 0;  // dt = 0: dt = "auto", before the mesh
  const bool known_steps = known_dt || t.steps > 0;
  const std::string dt_text =
      "time.dt = " + format_number(dt, kDigits) + " s" + (t.dt_auto ? " (\"auto\")" : "");
  auto fail = [&](const std::string& key, const std::string& what) -> void {
    throw InputError(origin_of(c, key) + ": " + what);
  };
  const std::string limit = "2^53 = " + count_text(double(kMaxSteps));
  double steps = known_steps ? double(t.steps) : std::numeric_limits<double>::infinity();
  if (t.steps <= 0 && known_dt) {
    // As the run counts them: the end rounded up to whole steps, a last step that ends
    // within 1e-9 of a step of `end` not counted.
    const double n = std::ceil(t.end / dt - 1e-9);
    if (!(n <= double(kMaxSteps)))
      fail("time.end", "time.end = " + format_number(t.end, kDigits) + " s at " + dt_text + " is " +
                           format_number(t.end / dt, kDigits) + " steps, more than the limit of " + limit +
                           " steps (the time n × dt is exact to the step only up to there): "
                           "give a larger time.dt or a smaller time.end");
    steps = std::max(1.0, n);
  } else if (t.steps > kMaxSteps) {
    fail("time.steps", "time.steps = " + std::to_string(t.steps) + " is more than the limit of " + limit +
                           " steps (the time n × dt is exact to the step only up to there)");
  }
  if (known_dt && !std::isfinite(steps * dt))
    fail(t.steps > 0 ? "time.steps" : "time.end",
         "the run's end time, " + count_text(steps) + " steps × " + dt_text + ", is not a finite number");
  // Steps between frames and rows: the run rounds every / dt to whole steps.
  for (const auto& [key, value] : {std::pair<std::string, double>{"output.every", o.every},
                                   std::pair<std::string, double>{"output.history_every", o.history_every}})
    if (known_dt && value > 0 && !(value / dt <= double(kMaxSteps)))
      fail(key, key + " = " + format_number(value, kDigits) + " s at " + dt_text + " is " +
                    format_number(value / dt, kDigits) + " steps, more than the limit of " + limit + " steps");
  // Frames: output.frames, or one every output.every rounded to whole steps.
  double frames = o.frames > 0 ? o.frames : 20;
  std::string frames_key = "output.frames", subject = "output.frames = " + count_text(frames);
  if (o.every > 0) {
    if (!known_dt) return known_steps ? long(steps) : -1;  // the stride needs dt: checked again with the run's dt
    const double stride = std::max(1.0, std::round(o.every / dt));
    frames = std::ceil(steps / stride) + 1;
    frames_key = "output.every";
    subject = "output.every = " + format_number(o.every, kDigits) + " s gives " + count_text(frames) +
              " frames (one every " + count_text(stride) + " steps at " + dt_text + "), which";
  } else if (!c.origin.count("output.frames")) {
    frames = std::min(frames, steps + 1);  // the default 20 of a short run: the frames it has
  }
  // More frames than steps + 1 (a run shortened with --set time.end, say): a frame after
  // every step, the run's frame schedule takes each step once.
  if (frames > double(kMaxFrames))
    fail(frames_key, subject + " is more than the limit of " + count_text(double(kMaxFrames)) +
                         " frames (for a finer record in time use output.history_every or [[probe]] entries)");
  return known_steps ? long(steps) : -1;
}

}  // namespace fdem::io
