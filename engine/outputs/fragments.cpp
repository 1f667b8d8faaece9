#include "engine/outputs/fragments.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace fdem {

double FragmentSummary::largest_fraction() const {
  double largest = 0;
  for (const auto& f : fragments) largest = std::max(largest, f.area);
  return total_area > 0 ? largest / total_area : 0.0;
}

namespace {

// Triangle t's current area [m²] (positive counter-clockwise), as every fragment sum takes it.
inline double current_area(const Model& model, const std::vector<real2>& positions, size_t t) {
  const auto& tri = model.triangles[t];
  const real2 a = positions[tri[0]], b = positions[tri[1]], c = positions[tri[2]];
  return 0.5 * ((double(b.x) - a.x) * (double(c.y) - a.y) - (double(c.x) - a.x) * (double(b.y) - a.y));
}

void check_sizes(const char* who, const Model& model, const std::vector<int>& labels, const std::vector<real2>& positions) {
  if (labels.size() != model.num_triangles() || positions.size() != model.num_nodes())
    throw std::logic_error(std::string(who) + ": " + std::to_string(labels.size()) + " labels for " +
                           std::to_string(model.num_triangles()) + " triangles, " + std::to_string(positions.size()) +
                           " positions for " + std::to_string(model.num_nodes()) + " nodes");
}

}  // namespace

PieceAreas piece_areas(const Model& model, const std::vector<int>& labels, const std::vector<real2>& positions) {
  check_sizes("piece_areas", model, labels, positions);
  const size_t n = model.num_triangles();
  // area_of[id]: the running area of the piece whose smallest triangle is id (NaN: none
  // seen yet); ids are at most their triangle's index, so one array of n does.
  std::vector<double> area_of(n, std::numeric_limits<double>::quiet_NaN());
  PieceAreas out;
  double total = 0;
  for (size_t t = 0; t < n; ++t) {
    const int id = labels[t];
    if (id < 0 || size_t(id) > t)
      throw std::logic_error("piece_areas: triangle " + std::to_string(t) + " has label " + std::to_string(id));
    const double area = current_area(model, positions, t);
    double& sum = area_of[id];
    if (std::isnan(sum)) {
      sum = 0;
      ++out.count;
    }
    sum += area;
    total += area;
  }
  double largest = 0;
  for (size_t t = 0; t < n; ++t)
    if (!std::isnan(area_of[t])) largest = std::max(largest, area_of[t]);
  out.largest_fraction = total > 0 ? largest / total : 0.0;
  return out;
}

FragmentSummary summarise_fragments(const Model& model, const std::vector<int>& labels,
                                    const std::vector<real2>& positions) {
  check_sizes("summarise_fragments", model, labels, positions);
  const size_t n = model.num_triangles();
  // slot[id] = index into the summary of the piece whose smallest triangle is id
  std::vector<int> slot(n, -1);
  FragmentSummary out;
  for (size_t t = 0; t < n; ++t) {
    const int id = labels[t];
    if (id < 0 || size_t(id) > t) throw std::logic_error("summarise_fragments: triangle " + std::to_string(t) +
                                                         " has label " + std::to_string(id));
    if (slot[id] < 0) {
      slot[id] = static_cast<int>(out.fragments.size());
      Fragment f;
      f.id = id;
      out.fragments.push_back(f);
    }
  }
  std::vector<double> mx(out.fragments.size(), 0.0), my(out.fragments.size(), 0.0);
  for (size_t t = 0; t < n; ++t) {
    const auto& tri = model.triangles[t];
    const double x0 = model.x[tri[0]], y0 = model.y[tri[0]];
    const double ref_area = 0.5 * ((model.x[tri[1]] - x0) * (model.y[tri[2]] - y0) - (model.x[tri[2]] - x0) * (model.y[tri[1]] - y0));
    const real2 a = positions[tri[0]], b = positions[tri[1]], c = positions[tri[2]];
    const double area = current_area(model, positions, t);
    const double mass = model.materials[model.triangle_material[t]].density * ref_area * model.thickness;
    const int k = slot[labels[t]];
    Fragment& f = out.fragments[k];
    ++f.triangles;
    f.area += area;
    f.mass += mass;
    // Lumped masses: a third of the triangle's mass on each corner.
    mx[k] += mass * (double(a.x) + b.x + c.x) / 3.0;
    my[k] += mass * (double(a.y) + b.y + c.y) / 3.0;
    out.total_area += area;
  }
  const double pi = std::acos(-1.0);
  for (size_t k = 0; k < out.fragments.size(); ++k) {
    Fragment& f = out.fragments[k];
    f.x = f.mass > 0 ? mx[k] / f.mass : 0.0;
    f.y = f.mass > 0 ? my[k] / f.mass : 0.0;
    f.diameter = std::sqrt(4.0 * std::max(f.area, 0.0) / pi);
  }
  // First appearance in triangle order is already increasing id (the id is the piece's
  // smallest triangle).
  return out;
}

}  // namespace fdem
