// Domain decomposition of a model over ranks: which rank owns each triangle, node and
// CE4, and what each rank would have to hold besides (its ghosts). This is the first
// piece of the scale-out design (ARCHITECTURE.md, "Scale-out"); `fdem check --ranks N`
// prints it; engine/run/split_run.* runs the split.
//
// Ownership rules (deterministic, independent of the partitioner):
// - a triangle belongs to the part the partitioner gives it;
// - a node belongs to the part of the lowest-index triangle that uses it;
// - a CE4 belongs to the part of its first triangle (Model::ce4_triangles[k][0]).
// Ghosts of part p (what p must hold to compute the forces on its own nodes exactly as
// one rank does, in the same order):
// - ghost TRI3: triangles of other parts that use a node p owns;
// - ghost CE4: CE4s of other parts that use a node p owns;
// - ghost nodes: nodes of p's triangles, CE4s and ghost elements that p does not own;
// - contact ghost TRI3 (models with contact): triangles of other parts whose bounding
//   box, grown by the contact reach, overlaps the box of one of p's triangles; with CE4s
//   also every CE4 with an end at a mesh node of p's or its contact ghosts' triangles,
//   and that CE4's triangles and nodes (local_model).
#pragma once
#include <cstdint>
#include <string>
#include <vector>
#include "engine/model/model.hpp"

namespace fdem {

enum class PartitionMethod { Metis, Bisection };

// Work weight of each triangle for balancing, from the per-stage times of the 1.08M
// TRI3 bench model on the H200 (README, Performance): a triangle 4 (its forces and its
// nodes' share of gather and integration), each of its CE4s 5 (half of a CE4's 10), a
// contact candidate 100 (about 8 couples through the contact stage). A triangle of a
// fracturable region counts as a candidate when contact is on, since it may become one.
std::vector<int64_t> triangle_work(const Model& model);

struct Partition {
  int parts = 1;
  PartitionMethod method = PartitionMethod::Bisection;
  std::vector<int> triangle_part;  // one per triangle
  // A split run with contact: how far [m] beyond a triangle's reference bounding box
  // the triangles it may meet in contact lie (contact_ghost_reach in engine/run/split_run.hpp: the
  // skin plus twice the travel a node may make from its start). Its rank holds all of
  // them (contact ghosts). 0: no contact ghosts.
  double contact_reach = 0;
};

// Splits the triangles into `parts` parts of about equal work. Metis: METIS's k-way
// partition of the triangle graph (triangles joined across an edge or a CE4), weighted by
// triangle_work, fixed seed; only when the build found METIS (`partition_has_metis()`).
// Bisection: recursive coordinate bisection of the triangle centroids by work (compact
// parts, since contact follows space). Both are deterministic. Throws InputError for
// parts < 1 or parts > triangles.
Partition partition_model(const Model& model, int parts, PartitionMethod method);
bool partition_has_metis();
const char* partition_method_name(PartitionMethod method);

struct PartStats {
  size_t tri3 = 0, ce4 = 0, nodes = 0;
  size_t ghost_tri3 = 0, ghost_ce4 = 0, ghost_nodes = 0, contact_ghost_tri3 = 0;
  // All the part's split run holds, owned and ghost of every kind (local_model's counts,
  // from the same rule): with contact and CE4s this includes the CE4s around the contact
  // ghosts and their triangles and nodes, which the ghost columns above leave out.
  size_t held_tri3 = 0, held_ce4 = 0, held_nodes = 0;
  int64_t work = 0;
};

// Per part, by the ownership and ghost rules above. `contact_reach` [m]: how far contact
// looks beyond a triangle's box (the skin plus the largest triangle's box), used only
// when the model has contact.
std::vector<PartStats> partition_stats(const Model& model, const Partition& partition, double contact_reach);

// Largest part's work over the mean (1 = perfect balance).
double partition_imbalance(const std::vector<PartStats>& stats);

// The nodes' owners by the rule above (lowest-index triangle's part).
std::vector<int> node_owners(const Model& model, const Partition& partition);

// Which nodes `rank` holds (its own and its ghosts, by the rules above): 1 per held
// node. local_model keeps exactly these; halo_plan (engine/parallel/halo.*) asks it of every peer.
std::vector<char> held_nodes(const Model& model, const Partition& partition, const std::vector<int>& owner, int rank);

// One rank's share of a model: its own triangles and CE4s, its ghost elements (above),
// and the nodes they use, each list in the global order (so the node gather's slot
// maps, built from element order, list an owned node's contributions in the order one
// rank does, and its sums are bitwise those of one rank). The CE4s' two triangles are
// included too (a CE4 reads them). Loaded edges that touch an owned node come along.
// Every local node that the rank does not own is a ghost: its position and velocity
// are taken from its owner after every step.
struct LocalModel {
  Model model;
  std::vector<int> node_global, triangle_global, ce4_global, edge_global;  // local index → global (edge: loaded edge)
  std::vector<int> node_owner;                                // rank owning each local node
  std::vector<int> ghost_nodes;                               // local indices of nodes owned elsewhere
};

// With contact (partition.contact_reach > 0) the rank also holds every triangle within
// that reach of one it owns (contact ghosts) and their nodes, and the local model carries
// its owned masks and the whole model's contact scales (Model::triangle_owned); with CE4s
// also every CE4 with an end at a mesh node of those triangles (the CE4 and corner-fan
// states contact reads are then computed on the rank, as by their owner).
LocalModel local_model(const Model& model, const Partition& partition, int rank);

}  // namespace fdem
