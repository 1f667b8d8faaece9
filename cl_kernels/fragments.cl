// Fragment labelling: the connected pieces of the body, run only at output frames and
// history rows (engine/stages/fragment_labels.*), never in the step.
// The graph's vertices are the triangles (0 .. n_tri-1) and the nodes (n_tri + node);
// every triangle is joined to its three nodes (triangles sharing a node are one piece)
// and the two triangles of every intact CE4 to each other (status.x == 0; a broken CE4
// joins nothing). Each vertex holds a label: itself at first, afterwards always a vertex
// of the same piece with an index no larger than its own. A round hooks the larger of
// the two labels met over an edge onto the smaller (integer atomic_min) and then points
// every vertex at its root (a vertex that is its own label). A round that hooks nothing
// leaves every piece with one root, its smallest vertex, which is a triangle because
// triangles come first: the result is the smallest triangle index of each piece,
// whatever the order the work-items ran in.

// Hooks the labels of vertices u and v: the entry of the larger label takes the smaller
// (an integer minimum, so the order of concurrent hooks does not matter).
inline void hook(__global int* label, __global int* restrict changed, const int u, const int v) {
  const int lu = label[u], lv = label[v];
  if (lu == lv) return;
  const int low = min(lu, lv), high = max(lu, lv);
  if (atomic_min(&label[high], low) > low) *changed = 1;
}

// One work-item per vertex (triangles, then nodes): its label is its own index.
__kernel void fragment_init(const uint n_vertices, __global int* label) {
  const uint v = get_global_id(0);
  if (v < n_vertices) label[v] = (int)v;
}

// One work-item per triangle: hooks the triangle with each of its three nodes.
__kernel void fragment_hook_triangles(const uint n_tri,
                                      __global const uint* restrict tri_nodes,
                                      __global int* label,
                                      __global int* restrict changed) {
  const uint t = get_global_id(0);
  if (t >= n_tri) return;
  for (int k = 0; k < 3; ++k) hook(label, changed, (int)t, (int)(n_tri + tri_nodes[3 * t + k]));
}

// One work-item per CE4: an intact CE4 hooks its two triangles.
__kernel void fragment_hook_ce4(const uint n_ce4,
                                __global const int2* restrict status,
                                __global const uint2* restrict ce4_triangles,
                                __global int* label,
                                __global int* restrict changed) {
  const uint e = get_global_id(0);
  if (e >= n_ce4 || status[e].x != 0) return;
  const uint2 t = ce4_triangles[e];
  hook(label, changed, (int)t.x, (int)t.y);
}

// One work-item per vertex: follows its labels to the root and keeps the root. Roots do
// not change during this kernel, so a chain read while others shorten it still ends there.
__kernel void fragment_shortcut(const uint n_vertices, __global int* label) {
  const uint v = get_global_id(0);
  if (v >= n_vertices) return;
  int r = label[v];
  int next = label[r];
  while (next != r) {
    r = next;
    next = label[r];
  }
  label[v] = r;
}
