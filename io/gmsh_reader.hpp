// Gmsh in: the MSH 2.2 and 4.1 reader, ASCII and binary (io/gmsh_msh.cpp, on the byte
// buffer of io/gmsh_buffer.hpp), and meshing of .geo files via the gmsh CLI
// (io/gmsh_geo.cpp). The mesh type and triangle orientation are in io/mesh.hpp.
#pragma once
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

// Meshes a .geo file with the gmsh CLI (2D, MSH 4.1 ASCII), passing `size` as
// -setnumber size <size> when size > 0, and writes the mesh under `cache_dir`.
// The cached file name includes a hash of the .geo text and the size, so an unchanged
// input reuses the mesh. Returns the .msh path. Throws fdem::InputError when gmsh is
// missing (naming the apt package), fails (with its output), or writes no triangles.
std::string mesh_geo(const std::string& geo_path, double size, const std::string& cache_dir);

// The path of an executable `program` in a directory of $PATH (an empty entry is "."), or
// "" when there is none: how mesh_geo finds gmsh.
std::string find_on_path(const std::string& program);

}  // namespace fdem::io
