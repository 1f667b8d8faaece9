// The pieces of the body at one moment, summed on the host from the device's labels
// (FragmentLabels: per triangle, the smallest triangle index of its piece) and the
// current positions. Sums run over the triangles in index order, so they are
// reproducible and the same on every device.
#pragma once
#include <vector>

#include "engine/model/model.hpp"
#include "engine/model/real.hpp"
#include "io/fragment_writer.hpp"

namespace fdem {

// One piece: id (smallest triangle index, 0-based), triangles, current area [m²], mass
// ρ A₀ t [kg], centre of mass (x, y) at the current positions [m], equivalent diameter
// sqrt(4 A/π) [m] (2D: the circle of the same area).
using Fragment = io::FragmentRecord;

struct FragmentSummary {
  std::vector<Fragment> fragments;  // by id, increasing
  double total_area = 0;            // [m²], current
  // The largest piece's area over total_area (1 for an intact body).
  double largest_fraction() const;
};

// What a history row keeps of the pieces: their number and the largest one's share of
// the area, the same bits as summarise_fragments' (the same sums in the same order),
// without the masses, centres and the summary's allocations (a row at 46k TRI3 took 1 ms).
struct PieceAreas {
  size_t count = 0;
  double largest_fraction = 0;
};
PieceAreas piece_areas(const Model& model, const std::vector<int>& labels, const std::vector<real2>& positions);

// `labels`: per triangle (FragmentLabels::labels); `positions`: current node positions.
FragmentSummary summarise_fragments(const Model& model, const std::vector<int>& labels,
                                    const std::vector<real2>& positions);

}  // namespace fdem
