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
  std::vector<int> triangle_entity;           // Gmsh elementary surface of each triangle, as read (empty after refine)

  std::vector<std::array<int, 2>> lines;  // 2-node line elements (physical curves)
  std::vector<int> line_group;            // index into groups
  std::vector<long> line_tags;

  std::vector<int> points;       // 1-node point elements (physical points)
  std::vector<int> point_group;  // index into groups

  std::vector<PhysicalGroup> groups;

  // The largest element tag in the file, of any element type (kept, skipped or a
  // dropped duplicate); 0 when unknown (a mesh built in memory). Refinement numbers
  // its new elements above it and above every tag kept here.
  long max_element_tag = 0;

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

// Splits every triangle into four at its edge midpoints, `levels` times (io/mesh_refine.cpp;
// the case's mesh.refine). Each child keeps its parent's physical surface and its
// counter-clockwise orientation: triangle (a, b, c) with midpoints m_ab, m_bc, m_ca becomes
// (a, m_ab, m_ca), (m_ab, b, m_bc), (m_ca, m_bc, c), (m_ab, m_bc, m_ca), in that order, at
// the parent's place. Line elements are halved, (a, b) → (a, m_ab), (m_ab, b), keeping
// their physical curve; point elements stay. A midpoint is one node shared by every
// element on its edge, at ((x_a + x_b)/2, (y_a + y_b)/2).
//
// Numbering, per level (so runs are reproducible): existing nodes keep their indices and
// tags; midpoints are appended in order of first use, walking the triangles in order and
// each triangle's edges a→b, b→c, c→a, then the line elements not on any triangle edge;
// their tags continue from the largest node tag. The children of the k-th triangle get
// element tags M+4k+1 … M+4k+4 and the halves of the k-th line element M+4T+2k+1 and
// M+4T+2k+2, M being the largest element tag (max_element_tag or a kept tag) and T the
// number of triangles before the split. Throws fdem::InputError, naming `what` (e.g.
// "case.toml: mesh.refine = 12"), when the refined mesh would hold more than 2^31 − 1
// triangles or nodes. levels = 0 leaves the mesh untouched.
void refine_mesh(Mesh& mesh, int levels, const std::string& what = "mesh refinement");

// Random perturbation of interior nodes (io/mesh_perturb.cpp; the case's mesh.perturb): it
// breaks the near-lattice that gmsh makes of a region with a uniform size, whose edges
// (and so the only paths a crack can take) lie along three directions 60° apart.
struct PerturbOptions {
  double amplitude = 0.0;    // largest move, as a fraction of the node's mean edge length
  unsigned long long seed = 1;
  double min_quality = 0.5;  // guard: 4√3 A / (a² + b² + c²), 1 for an equilateral triangle
};
struct PerturbSummary {
  long movable = 0;    // nodes eligible (interior to one movable surface)
  long moved = 0;      // nodes moved (a full or a shortened move)
  long kept = 0;       // eligible nodes left in place by the guard
  double min_quality_before = 1.0, min_quality_after = 1.0;  // over the movable surfaces
  double min_height_before = 0.0, min_height_after = 0.0;    // smallest triangle height there
};
// Moves each node that lies inside one physical surface with movable_group[g] set (every
// triangle around it in that surface, on no boundary or interface edge, on no line or
// point element) by a random vector of length up to amplitude × its mean edge length,
// uniform over the disc. Nodes are visited in index order; each draws from a
// counter-based generator (splitmix64 of the seed and its node tag) with arithmetic and
// sqrt only, so the same mesh, options and seed give bitwise the same coordinates on
// every machine. A move is kept only if every triangle around the node stays
// counter-clockwise, keeps quality ≥ min(min_quality, its quality before), and keeps its
// smallest height ≥ the smallest height of the movable surfaces before (so the stable
// time step that their triangles set does not shrink); otherwise the move is halved, up
// to three times, then the node stays. Triangles must be counter-clockwise
// (orient_triangles). amplitude = 0 leaves the mesh untouched.
PerturbSummary perturb_mesh(Mesh& mesh, const std::vector<char>& movable_group, const PerturbOptions& options);

}  // namespace fdem::io
