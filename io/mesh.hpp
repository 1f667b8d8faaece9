// The mesh as read from a Gmsh file: raw geometry, 0-based indices, physical groups.
// Units are the file's (the case's mesh.scale converts to metres later). Triangle
// orientation is checked here (io/mesh.cpp); io/gmsh_reader.hpp reads meshes.
#pragma once
#include <array>
#include <string>
#include <vector>

namespace fdem::io {

struct PhysicalGroup {
  int dim = 0;       // 0 point, 1 curve, 2 surface
  int tag = 0;       // Gmsh physical tag
  std::string name;  // from $PhysicalNames; "" when the group has no name
};

struct Mesh {
  std::string source;                    // path of the file, for messages
  std::vector<double> x, y;              // node coordinates, index = node index
  std::vector<long> node_tags;           // Gmsh node tag of each node index (tags may have gaps)

  std::vector<std::array<int, 3>> triangles;  // node indices, 0-based
  std::vector<int> triangle_group;            // index into groups, one per triangle
  std::vector<long> triangle_tags;            // Gmsh element tag of each triangle

  std::vector<std::array<int, 2>> lines;  // 2-node line elements (physical curves)
  std::vector<int> line_group;            // index into groups
  std::vector<long> line_tags;

  std::vector<int> points;       // 1-node point elements (physical points)
  std::vector<int> point_group;  // index into groups

  std::vector<PhysicalGroup> groups;

  // Index into groups of the group with this name and dimension, or -1.
  int find_group(const std::string& name, int dim) const {
    for (size_t i = 0; i < groups.size(); ++i)
      if (groups[i].name == name && groups[i].dim == dim) return static_cast<int>(i);
    return -1;
  }
};

// Checks every triangle's signed area. Clockwise triangles are re-oriented to
// counter-clockwise (swapping their 2nd and 3rd node); the count is returned and one
// note per triangle (at most 10, then a summary) is added to `notes`. A triangle whose
// area is below `degenerate_tol` × (longest edge)² throws fdem::InputError naming the
// file and the Gmsh element tag.
int orient_triangles(Mesh& mesh, std::vector<std::string>* notes = nullptr,
                     double degenerate_tol = 1e-10);

}  // namespace fdem::io
