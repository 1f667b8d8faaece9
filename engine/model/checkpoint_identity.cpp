// Which run a checkpoint belongs to: its format version, precision, case settings and mesh
// hash, written with each checkpoint and checked before a restart (engine/model/checkpoint_identity.hpp).
#include "engine/model/checkpoint_identity.hpp"

#include <map>
#include <set>
#include <sstream>
#include <string>

#include "base/errors.hpp"
#include "base/hash.hpp"
#include "engine/model/real.hpp"

namespace fdem {

namespace {

// A hash of the mesh the run computes on (coordinates, triangles, CE4s): a checkpoint of
// another mesh is refused.
std::string model_hash(const Model& m) {
  Fnv1a h;
  h.add(m.x.data(), m.x.size() * sizeof(double));
  h.add(m.y.data(), m.y.size() * sizeof(double));
  for (const auto& t : m.triangles) h.add(t.data(), sizeof(t));
  for (const auto& c : m.ce4) h.add(c.data(), sizeof(c));
  std::ostringstream s;
  s << std::hex << h.value() << std::dec << " (" << m.num_nodes() << " nodes, " << m.num_triangles() << " TRI3, " << m.ce4.size() << " CE4)";
  return s.str();
}

std::string settings_text(const std::map<std::string, std::string>& settings) {
  std::string out;
  for (const auto& [key, value] : settings) out += key + " = " + value + "\n";
  return out;
}

std::map<std::string, std::string> parse_settings(const std::string& text) {
  std::map<std::string, std::string> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    const auto eq = line.find(" = ");
    if (eq != std::string::npos) out[line.substr(0, eq)] = line.substr(eq + 3);
  }
  return out;
}

// Keys that may change between a checkpoint and its restart.
bool may_change(const std::string& key) {
  return key == "time.end" || key == "time.steps" || key.rfind("output.", 0) == 0 || key == "output";
}

// The version of what a checkpoint holds; a change of its contents changes it.
constexpr const char* kCheckpointFormat = "9";

}  // namespace

void check_fits(const io::CheckpointData& data, const PreparedCase& p, const std::string& path) {
  const auto text = [&](const char* key) {
    const auto it = data.text.find(key);
    return it == data.text.end() ? std::string() : it->second;
  };
  // 3 (2026-12-02): the break catalogue, and contact histories in one array. 4 (2026-12-02,
  // later): a broken CE4 is closed (1) or released (2 + step); version 3 had 1 for both.
  // 5 (2026-12-02): the loads' work per loaded edge (load_edge_energy) instead of per work-group.
  // 6 (2026-12-03): no ce4_output; a CE4's break time is the w of ce4_friction_slip.
  // 7 (2026-12-03, later): every attribute is under the checksums (io/checkpoint_file.cpp),
  // and the digests of the records the output files held (io/output_resume.hpp).
  // 8 (2026-12-03, session 11): the energy rows' sums taken in the kernels (no per-node
  // energy array, integrate's group slots in blocks of 256).
  if (text("format_version") != kCheckpointFormat)
    throw InputError("checkpoint '" + path + "' has format version '" + text("format_version") + "'; this fdem reads version " +
                     kCheckpointFormat + ": continue that run with the fdem that wrote it, or start it again");
  const std::string precision = kDoublePrecision ? "double" : "float";
  if (text("precision") != precision)
    throw InputError("checkpoint '" + path + "' was written by a " + text("precision") + "-precision build; this is a " +
                     precision + "-precision build (rebuild with -DFDEM_PRECISION=" + text("precision") + ")");
  const auto before = parse_settings(text("settings"));
  const auto& now = p.config.settings;
  std::set<std::string> keys;
  for (const auto& kv : before) keys.insert(kv.first);
  for (const auto& kv : now) keys.insert(kv.first);
  for (const auto& key : keys) {
    if (may_change(key)) continue;
    const auto a = before.find(key), b = now.find(key);
    const std::string was = a == before.end() ? "(absent)" : a->second, is = b == now.end() ? "(absent)" : b->second;
    if (was != is)
      throw InputError("checkpoint '" + path + "': " + key + " was " + was + " in the checkpointed run and is " + is +
                       " now; only time.end (time.steps) and output.* may change on restart");
  }
  // The same settings can still mesh differently (an edited .geo or .msh file).
  const std::string mesh = model_hash(p.model);
  if (text("mesh_hash") != mesh)
    throw InputError("checkpoint '" + path + "' is of another mesh: " + text("mesh_hash") + " in the checkpoint, " +
                     mesh + " now");
}

void stamp_checkpoint(io::CheckpointData& data, const PreparedCase& p) {
  data.text["format_version"] = kCheckpointFormat;
  data.text["precision"] = kDoublePrecision ? "double" : "float";
  data.text["settings"] = settings_text(p.config.settings);
  data.text["mesh_hash"] = model_hash(p.model);
}

}  // namespace fdem
