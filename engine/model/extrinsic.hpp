// Extrinsic cohesive elements (fracture.model = "extrinsic"): what the host prepares for
// cl_kernels/extrinsic.cl, and the cases the model refuses for now (docs/case-format.md).
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "engine/model/model.hpp"
#include "io/case_config.hpp"

namespace fdem {

// The most copies one mesh vertex may have (triangles at it) in an extrinsic region: the
// tie kernel keeps a label per copy in private memory.
constexpr int kExtrinsicMaxCopies = 32;

// Per CE4 whether it is extrinsic (its fracture set's model); empty when none is.
std::vector<char> extrinsic_ce4(const Model& model);
bool has_extrinsic(const Model& model);

// The tie kernel's lists: per mesh vertex with an extrinsic CE4 at it (in mesh-vertex
// order) its copies (every node that is a copy of it, in node order) and its links (two
// copies, as indices among the vertex's copies, joined by an end of an extrinsic CE4, and
// that CE4), CSR; and per CE4 the corner-force slots (3 t + k) of the corners opposite its
// edge in its two triangles.
// whole: per such vertex 1 when its links join every copy into one run (the tie kernel's
// fast path while none of them is inserted), else 0. ce4_vertex: per CE4 the tie
// vertices (indices into the lists) of its two ends, (i, i') and (j, j'); 0 for an
// intrinsic CE4.
struct ExtrinsicTies {
  std::vector<uint32_t> copy_start{0}, copy_node, link_start{0};
  std::vector<uint8_t> whole;
  std::vector<std::array<uint32_t, 2>> ce4_vertex;
  std::vector<std::array<uint32_t, 4>> link;
  std::vector<std::array<uint32_t, 2>> opposite;
  size_t vertices() const { return copy_start.size() - 1; }
};
// Throws InputError naming the vertex when one has more than kExtrinsicMaxCopies copies.
ExtrinsicTies extrinsic_ties(const Model& model);

// What `fdem check` says of the extrinsic CE4s ("" without any).
std::string extrinsic_summary(const Model& model);

// Refuses (InputError naming the case file and the material's key) what extrinsic CE4s do
// not support yet: local damping, mass scaling, [in_situ], [fluid]. Called by build_model.
void check_extrinsic(const Model& model, const io::CaseConfig& config);

}  // namespace fdem
