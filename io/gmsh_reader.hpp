// Gmsh in: the MSH 2.2 and 4.1 reader, ASCII and binary (io/gmsh_msh.cpp, on the byte
// buffer of io/gmsh_buffer.hpp), and meshing of .geo files via the gmsh CLI
// (io/gmsh_geo.cpp). The mesh type and triangle orientation are in io/mesh.hpp.
#pragma once
#include <iosfwd>
#include <stdexcept>
#include <string>
#include <vector>
#include "io/mesh.hpp"

namespace fdem::io {

// Reads a .msh file. Keeps 3-node triangles (type 2), 2-node lines (type 1) and points
// (type 15); other element types are skipped with one note per type in `notes`.
// Throws fdem::InputError naming the file (and line, or byte offset for binary files)
// for: missing file, unknown version, malformed or truncated section, element referring
// to an unknown node tag, triangles outside any physical group, a file with no physical
// groups at all (materials need named surfaces), no 3-node triangles.
Mesh read_gmsh(const std::string& path, std::vector<std::string>* notes = nullptr);

// How mesh_geo runs gmsh. engine/main.cpp sets the process-wide values (geo_meshing())
// from the command line (--max-triangles, --allow-geo-programs, --quiet).
struct GeoMeshing {
  // A .geo whose triangle count, estimated before meshing, is above this is refused.
  long max_triangles = 5'000'000;
  // A .geo file is a program: SystemCall and friends run shell commands (see
  // geo_program_commands). Refused unless this is set.
  bool allow_programs = false;
  // gmsh's last log line, the time so far and the estimate, every progress_every seconds
  // of a meshing that lasts that long; nullptr: silent.
  std::ostream* progress = nullptr;
  double progress_every = 5.0;
};
GeoMeshing& geo_meshing();  // the values mesh_geo uses; progress defaults to std::cerr

// Thrown by mesh_geo when SIGTERM, SIGINT, SIGHUP or SIGUSR1 arrived while gmsh ran: gmsh
// (its whole process group) has been stopped and its temporary files removed. main()
// ends the process as that signal would (exit status 128 + signal).
struct MeshingStopped : std::runtime_error {
  MeshingStopped(int signal_number, const std::string& what) : std::runtime_error(what), signal(signal_number) {}
  int signal;
};

// Meshes a .geo file with the gmsh CLI (2D, MSH 4.1 ASCII), passing `size` as
// -setnumber size <size> when size > 0, and writes the mesh under `cache_dir`.
// The cached file name includes a hash of the .geo text and the size, so an unchanged
// input reuses the mesh; the folders of $FDEM_MESH_CACHE_RO (colon-separated) are
// searched for that name too, and never written (the committed test meshes,
// tests/data/meshes; FDEM_MESH_RECORD=FILE appends "NAME<TAB>SIZE<TAB>GEO" for every mesh
// returned, which is how tools/gpu-suite --refresh-meshes lists them). Before meshing, the same gmsh process meshes the .geo with every
// size scaled up (Mesh.MeshSizeFactor 1e12, 1e12/3, … until a mesh has 2,000 triangles)
// and extrapolates the count to the asked size (N × factor²); above
// options.max_triangles it stops there and mesh_geo throws. Returns the .msh path. Throws
// fdem::InputError when the .geo runs programs and options.allow_programs is off, when
// the estimate is above the limit, when gmsh is missing (naming the apt package), fails
// (with its output), or writes no triangles; MeshingStopped on a signal.
std::string mesh_geo(const std::string& geo_path, double size, const std::string& cache_dir);
std::string mesh_geo(const std::string& geo_path, double size, const std::string& cache_dir,
                     const GeoMeshing& options);
// The same with gmsh's 2D algorithm chosen (the case's mesh.algorithm: "frontal-delaunay",
// "delaunay" or "meshadapt", set as Mesh.Algorithm after the .geo's own settings; "" keeps
// the .geo's). A named algorithm is part of the cache name's hash; "" hashes as before.
// `extra` is .geo text gmsh reads right after the .geo (the embedded [[joint]] files and
// sets, io/joint_geometry.hpp); it too is hashed when not empty.
std::string mesh_geo(const std::string& geo_path, double size, const std::string& algorithm,
                     const std::string& cache_dir, const GeoMeshing& options,
                     const std::string& extra = "");
// gmsh's Mesh.Algorithm number of a mesh.algorithm name; 0 for "" (none set). Throws
// InputError for another name.
int gmsh_algorithm_number(const std::string& algorithm);

// The commands in a .geo file (and in the files it Includes or Merges by literal name,
// recursively) that make gmsh start another program: System, SystemCall,
// NonBlockingSystemCall, OnelabRun, and an Include/Merge of a file gmsh would run (a
// .py, .exe or any name that is not a .geo, options or mesh/CAD data file) or whose name
// is computed. One entry per use, "FILE:LINE: WHAT"; empty when there is none. Comments
// and strings are skipped. Throws InputError for a file that cannot be read.
std::vector<std::string> geo_program_commands(const std::string& geo_path);

// The path of an executable `program` in a directory of $PATH (an empty entry is "."), or
// "" when there is none: how mesh_geo finds gmsh.
std::string find_on_path(const std::string& program);

}  // namespace fdem::io
