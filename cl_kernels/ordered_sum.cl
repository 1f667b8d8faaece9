// Sums of per-item values in a fixed order (engine/energy.hpp, OrderedSums): items are
// taken in blocks of ORDERED_BLOCK consecutive indices, each block summed left to right;
// the host adds the blocks' sums in block order. A split run's rank 0 adds the gathered
// values in the same blocks on the host, so both give the same bits.

// One work-item per block b: for each of `width` columns (first, first + 1, ...) of the
// items' rows of `stride` reals, the sum over the block's items in index order.
__kernel void ordered_block_sums(const uint n,
                                 const uint stride,
                                 const uint first,
                                 const uint width,
                                 __global const real* restrict values,
                                 __global real* restrict partial) {
  const uint b = get_global_id(0);
  const uint begin = b * ORDERED_BLOCK;
  if (begin >= n) return;
  const uint end = min(n, begin + (uint)ORDERED_BLOCK);
  for (uint c = 0; c < width; ++c) {
    real s = (real)0;
    for (uint i = begin; i < end; ++i) s += values[i * stride + first + c];
    partial[b * width + c] = s;
  }
}
