// [grains]: a physical surface cut into Voronoi grains (docs/case-format.md, [grains]).
// The front end (engine/run/prepare_case.cpp) draws the seeds and the minerals over the
// region of the .geo meshed as it is (draw_grains), embeds the cells' edges into the .geo
// with the [[joint]] machinery (grain_boundaries → io::embed_joints), and meshes it again;
// build_model (engine/model/model.cpp) then gives each triangle of the region the grain
// whose seed is nearest its centroid (grain_of) and the grain's mineral.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "io/case_config.hpp"
#include "io/joint_geometry.hpp"
#include "io/mesh.hpp"

namespace fdem::io {

// What draw_grains measured of the region, for messages and `fdem check`.
struct GrainDraw {
  double area = 0;       // [m²] of the region's triangles
  double mean_edge = 0;  // [m] mean element edge there
  Point2 lo{}, hi{};     // bounding box [m]
};

// Fills grains.points and grains.mineral from the region's triangles of `mesh`
// (coordinates × scale = metres). The number of grains is `count`, or the region's area
// over π size²/4, at least 1. Seeds are uniform over the region (splitmix64 of the seed and
// a counter; a draw is kept inside the region and at least half a mean grain diameter
// from the seeds kept before it), so the same keys and mesh give bitwise the same seeds.
// Minerals: the grains, in an order shuffled by the same stream, each take the mineral
// furthest below its share of the area so far (a grain's area: the region's triangles
// whose centroid is nearest its seed). Throws InputError naming `where`'s keys: region
// not a physical surface of the mesh, more than kMaxGrains grains, a mean grain diameter
// below 3 mean element edges of the region, seeds that cannot be placed.
GrainDraw draw_grains(GrainsConfig& grains, const Mesh& mesh, double scale, const CaseConfig& config);

// Voronoi vertices closer than kGrainMerge × the region's mean element edge are merged
// (engine/run/prepare_case.cpp).
constexpr double kGrainMerge = 0.6;

// The edges of the Voronoi cells of `points` (bisectors between neighbouring seeds),
// clipped to the box [lo, hi] grown by a tenth, as segments with joint = -1 (a grain
// boundary). A vertex where three cells meet has the same coordinates in all its edges
// (the circumcentre of the three seeds, in index order); vertices closer than
// `merge` [m] are merged (so gmsh meets no edge much shorter than an element).
// `cells`, when given, receives each seed's cell as a polygon (counter-clockwise) over the
// merged vertices: the embedded segments are its edges, so a point inside it (a
// triangle's centroid) lies in that grain whatever the merging moved.
std::vector<JointSegment> grain_boundaries(const std::vector<Point2>& points, Point2 lo, Point2 hi, double merge,
                                           std::vector<std::vector<Point2>>* cells = nullptr);


// The seed nearest a point (the lowest index on a tie; -1 when there are none), through a
// grid of buckets over the seeds.
class GrainFinder {
 public:
  explicit GrainFinder(const std::vector<Point2>& points);
  int nearest(Point2 p) const;

 private:
  const std::vector<Point2>& points_;
  Point2 lo_{};
  double cell_ = 1;
  int nx_ = 1, ny_ = 1;
  std::vector<std::vector<int>> buckets_;
};

// The grain of a point: the cell of `cells` holding it, trying the nearest seed's first;
// the nearest seed when none holds it (a point outside them all).
int grain_at(const GrainFinder& finder, const std::vector<std::vector<Point2>>& cells, Point2 p);

}  // namespace fdem::io
