// Reading, meshing and checking a case before it runs (engine/run/prepare_case.hpp).
#include "engine/run/prepare_case.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include "base/errors.hpp"
#include "base/format.hpp"
#include "io/gmsh_reader.hpp"
#include "io/grain_geometry.hpp"
#include "io/joint_geometry.hpp"

namespace fdem {

namespace fs = std::filesystem;

namespace {

// Folders a run must not write its files straight into: the root of the file system, the
// system's own directories (with everything below them), and the folders whose
// subfolders may hold data (/dev/shm, /usr/local/src, /var/tmp, /run/user/UID) but which
// hold none themselves. As root nothing else would stop it.
const char* const kSystemTrees[] = {"/bin",         "/boot",     "/etc",       "/lib",         "/lib32",
                                    "/lib64",       "/libx32",   "/proc",      "/sbin",        "/sys",
                                    "/usr/bin",     "/usr/include", "/usr/lib", "/usr/lib32",  "/usr/lib64",
                                    "/usr/libexec", "/usr/libx32", "/usr/sbin", "/usr/share"};
const char* const kSystemFolders[] = {"/dev", "/home", "/media", "/mnt", "/opt", "/run",
                                      "/srv", "/usr",  "/usr/local", "/usr/src", "/var"};

// InputError when output.dir is one of those, or output.name would put a file elsewhere
// than output.dir (io/case_reader checks the characters of a name; this is the backstop
// for the paths the run builds from it).
void check_output_place(const io::CaseConfig& c) {
  std::error_code ec;
  fs::path dir = fs::weakly_canonical(fs::absolute(c.output.dir, ec), ec);
  if (ec) dir = fs::absolute(c.output.dir).lexically_normal();
  std::string resolved = dir.string();
  while (resolved.size() > 1 && resolved.back() == '/') resolved.pop_back();
  const std::string key = c.path + ": output.dir = \"" + c.output.dir + "\"";
  const std::string advice = ": give the results a folder of their own (the default is \"out\", in the current directory)";
  if (resolved == "/") throw InputError(key + " is the root of the file system" + advice);
  for (const char* tree : kSystemTrees) {
    const std::string t = tree;
    if (resolved == t || resolved.rfind(t + "/", 0) == 0)
      throw InputError(key + " is " + (resolved == c.output.dir ? "" : resolved + ", ") + "in the system directory " + t + advice);
  }
  for (const char* folder : kSystemFolders)
    if (resolved == folder) throw InputError(key + " is the system directory " + resolved + advice);
  const std::string& name = c.output.name;
  if (name.empty() || name == "." || name == ".." || name.find('/') != std::string::npos ||
      std::any_of(name.begin(), name.end(), [](char ch) { return static_cast<unsigned char>(ch) < 0x20; }))
    throw InputError(c.path + ": output.name = \"" + name +
                     "\" is not a file name (no '/', no control characters, not . or ..): the output files go into "
                     "output.dir and nowhere else");
}

// OutputError when `dir` can neither be written (it exists) nor made (the nearest folder
// above it that exists cannot be written): what `fdem run` would meet, found before
// anything is computed, by `fdem check` as well.
void check_output_dir(const std::string& dir) {
  std::error_code ec;
  const fs::path absolute = fs::absolute(dir, ec);
  // The folder itself, or the nearest folder above it that exists, which it is made in.
  fs::path existing = absolute;
  while (!fs::exists(existing, ec) && existing.has_relative_path()) existing = existing.parent_path();
  if (!fs::is_directory(existing, ec))
    throw OutputError("cannot create output directory '" + dir + "': '" + existing.string() + "' is not a directory");
  if (::access(existing.c_str(), W_OK | X_OK) != 0) {
    const std::string why = std::strerror(errno);
    throw OutputError(existing == absolute ? "cannot write in output directory '" + dir + "': " + why
                                           : "cannot create output directory '" + dir + "' in '" + existing.string() +
                                                 "': " + why);
  }
}


}  // namespace

void make_output_dir(const std::string& dir) {
  check_output_dir(dir);
  try {
    fs::create_directories(dir);
  } catch (const fs::filesystem_error& e) {
    throw OutputError("cannot create output directory '" + dir + "': " + e.what());
  }
}


void check_output(const PreparedCase& p) {
  check_output_dir(p.config.output.dir);
  std::error_code ec;
  // A file the run would write, taken by something else (a folder, a FIFO, a device).
  std::vector<std::string> files = {p.exodus_path, p.history_path, checkpoint_path(p)};
  if (!p.model.ce4.empty()) files.insert(files.end(), {p.fragments_path, p.events_path});
  for (const auto& file : files) {
    const auto status = fs::status(file, ec);
    if (!ec && fs::exists(status) && !fs::is_regular_file(status))
      throw OutputError("output file '" + file + "' exists and is not a regular file: move it away or choose another "
                        "output.dir or output.name");
  }
}

// The .geo text that embeds the [[joint]] files and sets and the [grains] boundaries in
// the surfaces of `base` (the .geo meshed as it is), or "" when no joint has a file or a
// set and there are no grains. Notes what each gave. Draws the grains (c.grains->points
// and mineral) from `base`.
static std::string joint_geo_text(io::CaseConfig& c, const io::Mesh& base, std::vector<std::string>& notes) {
  std::vector<io::JointSegment> segments;
  io::GrainDraw grains;
  if (c.grains) {
    grains = io::draw_grains(*c.grains, base, c.mesh.scale, c);
    const auto edges = io::grain_boundaries(c.grains->points, grains.lo, grains.hi, io::kGrainMerge * grains.mean_edge,
                                            &c.grains->cells);
    segments.insert(segments.end(), edges.begin(), edges.end());
  }
  io::Point2 lo{1e300, 1e300}, hi{-1e300, -1e300};
  for (size_t n = 0; n < base.x.size(); ++n) {
    lo = {std::min(lo[0], base.x[n] * c.mesh.scale), std::min(lo[1], base.y[n] * c.mesh.scale)};
    hi = {std::max(hi[0], base.x[n] * c.mesh.scale), std::max(hi[1], base.y[n] * c.mesh.scale)};
  }
  bool any = false;
  for (size_t j = 0; j < c.joints.size(); ++j) {
    const io::JointConfig& joint = c.joints[j];
    if (!joint.file.empty()) {
      const auto read = io::read_polylines(joint.file, int(j));
      segments.insert(segments.end(), read.begin(), read.end());
      any = true;
    }
    if (joint.set) {
      const auto draw = io::draw_joint_set(*joint.set, lo, hi, int(j));
      if (draw.traces.size() > 1000000)
        throw InputError(io::origin_of(c, "joint." + std::to_string(j) + ".set.spacing") + ": joint[" + std::to_string(j) +
                         "].set draws more than 1,000,000 traces over the region: a larger spacing or trace_length");
      segments.insert(segments.end(), draw.traces.begin(), draw.traces.end());
      any = true;
    }
  }
  if (!any && !c.grains) return "";
  std::vector<int> grain_entities;  // the surface entities of the grains' region
  if (c.grains) {
    const int group = base.find_group(c.grains->region, 2);
    for (size_t t = 0; t < base.triangles.size() && t < base.triangle_entity.size(); ++t)
      if (base.triangle_group[t] == group &&
          std::find(grain_entities.begin(), grain_entities.end(), base.triangle_entity[t]) == grain_entities.end())
        grain_entities.push_back(base.triangle_entity[t]);
  }
  const io::JointEmbedding e = io::embed_joints(base, c.mesh.scale, segments, int(c.joints.size()), grain_entities);
  if (c.grains)
    notes.push_back("grains: " + std::to_string(c.grains->points.size()) + " Voronoi grains in '" + c.grains->region +
                    "', their boundaries embedded into " + c.mesh.geo + " (" + std::to_string(e.grain_pieces) +
                    " straight pieces, " + format_number(e.grain_length, 4) + " m; half an element off the region's "
                    "boundaries)");
  for (size_t j = 0; j < c.joints.size(); ++j) {
    if (c.joints[j].file.empty() && !c.joints[j].set) continue;
    if (e.pieces[j] == 0 && c.joints[j].curves.empty())
      throw InputError(io::origin_of(c, "joint." + std::to_string(j) + (c.joints[j].set ? ".set.spacing" : ".file")) +
                       ": joint[" + std::to_string(j) + "] ('" + c.joints[j].name + "'): no joint of its " +
                       (c.joints[j].set ? "set" : "file") + " lies inside the meshed region " + base.source +
                       " (x " + format_number(lo[0]) + " to " + format_number(hi[0]) + ", y " + format_number(lo[1]) +
                       " to " + format_number(hi[1]) + " m)");
    notes.push_back("joint[" + std::to_string(j) + "] ('" + c.joints[j].name + "'): " + std::to_string(e.pieces[j]) +
                    " straight pieces, " + format_number(e.length[j], 4) + " m, embedded into " + c.mesh.geo +
                    " (clipped to the region, half an element off its boundaries)");
  }
  return e.geo;
}

PreparedCase prepare_case(const std::string& case_path, const std::vector<std::string>& overrides) {
  PreparedCase p;
  p.config = io::read_case(case_path, overrides);
  auto& c = p.config;
  if (c.output.name.empty()) c.output.name = fs::path(case_path).stem().string();
  check_output_place(c);

  std::string mesh_path = c.mesh.file;
  if (!c.mesh.geo.empty()) {
    make_output_dir(c.output.dir);
    // Meshes made from .geo files are cached in FDEM_MESH_CACHE when set (shared across
    // runs and machines), else next to the output.
    const char* cache = std::getenv("FDEM_MESH_CACHE");
    const std::string cache_dir = cache && *cache ? cache : c.output.dir;
    mesh_path = io::mesh_geo(c.mesh.geo, c.mesh.size, c.mesh.algorithm, cache_dir, io::geo_meshing());
    // [[joint]] files and sets and [grains]: embedded into the .geo, which is meshed again
    // with them.
    const std::string extra = joint_geo_text(c, io::read_gmsh(mesh_path), p.notes);
    if (!extra.empty())
      mesh_path = io::mesh_geo(c.mesh.geo, c.mesh.size, c.mesh.algorithm, cache_dir, io::geo_meshing(), extra);
  }
  const io::Mesh mesh = io::read_gmsh(mesh_path, &p.notes);
  p.model = build_model(mesh, c, p.notes);
  p.stable = stable_time_step(p.model);
  p.probes = locate_probes(p.model, c.probes, c.path);

  if (p.model.mass_scaling && p.model.contact.enabled)
    throw InputError(c.path + ": [damping] mass_scaling does not account for contact springs, so the step would be "
                     "unstable; relax a contact case with local damping on true masses (mass_scaling = false, dt = \"auto\")");
  if (c.time.dt_auto) {
    p.dt = c.time.safety * p.stable.dt;
  } else {
    p.dt = c.time.dt;
    if (!p.model.mass_scaling && p.dt > p.stable.dt) {
      const size_t t = p.stable.triangle;
      throw InputError(c.path + ": time.dt = " + format_number(p.dt) + " s exceeds the stable estimate " +
                       format_number(p.stable.dt) + " s (set by triangle " + std::to_string(p.model.triangle_tags[t]) +
                       " of material '" + p.model.materials[p.model.triangle_material[t]].name +
                       "'). Use dt = \"auto\", a dt below the estimate, or [damping] mass_scaling = true for a static run.");
    }
  }
  p.steps = io::run_steps(c, p.dt);
  // A checkpoint is written after a step: a shorter interval cannot be kept, and the
  // schedule is reckoned in steps of dt.
  if (c.output.checkpoint_every > 0 && c.output.checkpoint_every < p.dt)
    throw InputError(c.path + ": output.checkpoint_every = " + format_number(c.output.checkpoint_every) +
                     " s is shorter than the time step dt = " + format_number(p.dt) +
                     " s (a checkpoint is written after a step): give at least dt, or 0 for one at the end of the run only");
  p.exodus_path = (fs::path(c.output.dir) / (c.output.name + ".exo")).string();
  p.history_path = (fs::path(c.output.dir) / (c.output.name + "_history.nc")).string();
  p.fragments_path = (fs::path(c.output.dir) / (c.output.name + "_fragments.nc")).string();
  p.events_path = (fs::path(c.output.dir) / (c.output.name + "_events.nc")).string();
  return p;
}

}  // namespace fdem
