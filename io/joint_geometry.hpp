// Joints that are not curves of the user's .geo ([[joint]] `file` and `set`): polylines
// read from a file or drawn as a statistical joint set, clipped to the meshed region and
// written as .geo text that embeds them in the surfaces they cross (`Curve{..} In
// Surface{..}`), so that gmsh's element edges follow them. engine/run/prepare_case.cpp
// meshes the user's .geo once (the cached base mesh), finds here which surface holds each
// piece, and meshes the .geo again with the text appended (io::mesh_geo's `extra`; the
// cache name hashes it).
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "io/case_config.hpp"
#include "io/mesh.hpp"

namespace fdem::io {

using Point2 = std::array<double, 2>;

// A straight piece of a joint, in metres, and where it came from for messages
// ("joints.txt:12", or "" for a drawn trace).
struct JointSegment {
  int joint = 0;  // index of the [[joint]]; -1: a grain boundary ([grains], io/grain_geometry.hpp)
  Point2 a{}, b{};
  std::string origin;
};

// A polyline file: one point "x y" a line (metres, the model's frame: mesh coordinates ×
// mesh.scale), a blank line between polylines, '#' starts a comment. Each polyline has at
// least two points and no two consecutive points equal. Throws InputError naming the
// file and line. The segments come in file order, each with its origin "FILE:LINE".
std::vector<JointSegment> read_polylines(const std::string& path, int joint);

// A statistical joint set drawn over the rectangle [lo, hi] (metres). Joint lines run
// along the mean direction `angle`; their positions along its normal are a Poisson
// process of mean spacing `spacing` from a random start; along each line traces of length
// `trace_length` alternate with rock bridges of length trace_length (1 − p) / p from a
// random start (p = persistence; p = 1: whole lines); each trace turns about its
// midpoint by a von Mises angle of concentration `kappa` (0: any direction). Every draw
// comes from splitmix64 of the seed and a counter, so the same keys give the same traces
// bitwise.
struct JointSetDraw {
  std::vector<JointSegment> traces;
  std::vector<double> offsets;  // the lines' positions along the mean normal [m], increasing
  std::vector<double> angles;   // each trace's direction [deg]
};
JointSetDraw draw_joint_set(const JointSetConfig& set, Point2 lo, Point2 hi, int joint);

// What embed_joints made: the .geo text to append, and per joint the pieces and length
// kept inside the region.
struct JointEmbedding {
  std::string geo;
  std::vector<size_t> pieces;
  std::vector<double> length;  // [m]
  size_t grain_pieces = 0;     // of the grain boundaries (segments with joint = -1)
  double grain_length = 0;     // [m]
};

// The physical curve name under which joint j's embedded pieces are meshed.
std::string embedded_joint_curve(int joint);

// Clips each segment to the triangles of `base` (the user's .geo meshed as it is; mesh
// coordinates × scale = metres) less a margin of half the local edge length from every
// boundary between surface entities and from the outer boundary, splits the pieces at
// their crossings (a shared point), and writes them as .geo points and lines embedded in
// the surface entity that holds each, with physical curves embedded_joint_curve(j).
// A segment with an origin (from a file) that lies wholly outside is an InputError naming
// it. `joints` is the number of [[joint]] entries. Segments with joint = -1 (grain
// boundaries) are embedded the same way, with no physical curve.
// `grain_entities`: the surface entities the grain boundaries (joint = -1) may lie in
// (those of the [grains] region); their pieces elsewhere are dropped.
JointEmbedding embed_joints(const Mesh& base, double scale, const std::vector<JointSegment>& segments, int joints,
                            const std::vector<int>& grain_entities = {});

}  // namespace fdem::io
