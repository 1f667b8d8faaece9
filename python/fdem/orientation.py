"""Orientation of mesh edges and cracks: rose histograms.

A crack in fdem-cl runs along CE4s, and a CE4 lies on a mesh edge, so the directions the
mesh's edges take are the only directions a crack can take. A region meshed at one size
by gmsh's default algorithm is close to a lattice of equilateral triangles: its edges
cluster around three directions 60 degrees apart, and its cracks with them.

Directions are undirected: an angle in [0, 180) degrees from the x axis,
counter-clockwise. `histogram` counts them in equal bins (12 of 15 degrees by default,
bin k holding [15k, 15k + 15)); `lattice_share` is the largest fraction of them within
15 degrees of three directions 60 degrees apart (six of the twelve 15-degree bins, bins
k, k+1, k+4, k+5, k+8, k+9 mod 12): 0.5 for directions spread evenly, 1 for a perfect
lattice whose directions sit at bin edges.

The CE4s of a run and their directions are read from its Exodus file: the `cohesive`
block's connectivity (i, j, j', i') on the reference coordinates (face i-j), one CE4 per
interior edge of the fracturable regions.
"""

from typing import Optional, Sequence

import numpy as np

__all__ = ["directions", "histogram", "lattice_share", "ce4_directions", "format_bins"]


def directions(x0, y0, x1, y1) -> np.ndarray:
    """Undirected angle of each segment (x0, y0)-(x1, y1), degrees in [0, 180)."""
    angle = np.degrees(np.arctan2(np.asarray(y1, float) - y0, np.asarray(x1, float) - x0))
    angle = np.mod(angle, 180.0)
    return np.where(angle >= 180.0, 0.0, angle)  # mod can round up to exactly 180


def histogram(angles, bins: int = 12, weights: Optional[Sequence[float]] = None) -> np.ndarray:
    """Fraction of the directions (or of the weights) in each of `bins` equal bins over
    [0, 180); all zeros when there are none."""
    angles = np.asarray(angles, float)
    if bins < 1:
        raise ValueError(f"bins must be >= 1 (got {bins})")
    counts, _ = np.histogram(angles, bins=bins, range=(0.0, 180.0), weights=weights)
    total = counts.sum()
    return counts / total if total > 0 else np.zeros(bins)


def lattice_share(angles) -> float:
    """Largest fraction of the directions within 15 degrees of three directions 60
    degrees apart, over the twelve 15-degree bins (see the module's doc); NaN for none."""
    fractions = histogram(angles, 12)
    if fractions.sum() == 0:
        return float("nan")
    return float(max(fractions[[(k + d) % 12 for d in (0, 1, 4, 5, 8, 9)]].sum()
                     for k in range(12)))


def ce4_directions(exo, which=None) -> np.ndarray:
    """Reference direction of each CE4 of an Exodus file (`fdem.load.load_exodus`), in the
    order of its `cohesive` block, or of the CE4s indexed by `which` (0-based). Raises
    ValueError when the file has no cohesive block."""
    for blk in exo.blocks:
        if blk.name.lower() == "cohesive" and blk.connectivity.shape[1] >= 4:
            conn = blk.connectivity if which is None else blk.connectivity[np.asarray(which, int)]
            return directions(exo.x[conn[:, 0]], exo.y[conn[:, 0]], exo.x[conn[:, 1]], exo.y[conn[:, 1]])
    raise ValueError(f"{exo.path}: no 'cohesive' element block (no fracturable material?)")


def format_bins(fractions) -> str:
    """'0.2, 7.9, 25.0, ...' in percent, one decimal."""
    return ", ".join(f"{100 * f:.1f}" for f in fractions)
