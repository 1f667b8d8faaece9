#!/usr/bin/python3
"""The grain map of a [grains] run (cases/ucs/README.md, section "Grains"): the triangles
coloured by mineral (their element block), the grain boundaries (edges between two
triangles of different GRAIN) in black, the broken CE4s of the last frame in red.

    /usr/bin/python3 cases/ucs/plot_grains.py OUT/ucs.exo [-o cases/ucs/figures/grains_map.png]
        [--frame -1] [--history OUT/ucs_history.nc LABEL ...]

With --history (pairs of a history file and a label), a second panel draws each run's
axial stress (the top platen's force over the specimen's width, 51.7 mm × 1 m) against the
platens' approach over the specimen's height (129.5 mm). Needs numpy, matplotlib and netCDF4
(Debian: python3-numpy python3-matplotlib python3-netcdf4).
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.realpath(__file__)), "..", "..", "python"))
from fdem.load import load_exodus, load_history  # noqa: E402

import matplotlib  # noqa: E402
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402

WIDTH, HEIGHT, THICKNESS = 0.0517, 0.1295, 1.0
COLOURS = ["#e8d9b5", "#9fc5e8", "#b6d7a8", "#f4cccc", "#d9d2e9", "#ffe599"]


def grain_map(ax, exo, frame):
    grain = exo.element_values("GRAIN", frame)
    first = 0
    mineral_of_triangle, tris, names = [], [], []
    for blk in exo.blocks:
        n = blk.num_elem
        if blk.elem_type.upper().startswith("TRI"):
            g = grain[first:first + n]
            if np.any(g > 0):
                names.append(blk.name)
                tris.append(blk.connectivity[:, :3])
                mineral_of_triangle.append(np.full(n, len(names) - 1))
                grains_of = g if len(tris) == 1 else np.concatenate([grains_of, g])  # noqa: F821
        first += n
    tris = np.concatenate(tris)
    mineral = np.concatenate(mineral_of_triangle)
    x, y = exo.x * 1e3, exo.y * 1e3
    for k, name in enumerate(names):
        sel = tris[mineral == k]
        ax.tripcolor(x, y, sel, facecolors=np.zeros(len(sel)), cmap=matplotlib.colors.ListedColormap([COLOURS[k]]),
                     edgecolors="none")
        ax.plot([], [], "s", color=COLOURS[k], label=name)
    # Grain boundaries: an edge of two triangles of different grains. Fracturable triangles
    # own their nodes, so edges are matched by their corners' coordinates.
    key = {}
    segs = []
    for t, tri in enumerate(tris):
        for a, b in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])):
            pa, pb = (round(x[a], 9), round(y[a], 9)), (round(x[b], 9), round(y[b], 9))
            k = (min(pa, pb), max(pa, pb))
            if k in key and grains_of[key[k]] != grains_of[t]:
                segs.append([pa, pb])
            key[k] = t
    ax.add_collection(LineCollection(segs, colors="k", linewidths=0.5))
    n_grains = len(np.unique(grains_of[grains_of > 0]))
    ax.set_title(f"{n_grains} grains, {len(segs)} boundary edges")
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.legend(loc="upper right", fontsize=7, framealpha=0.9)


def stress_strain(ax, pairs):
    # As tools/fdem-plot stress-strain --test ucs: |top platen force| / (W t) against the
    # platens' approach over H.
    for path, label in pairs:
        h = load_history(path)
        missing = [v for v in ("platen_top_force_y", "platen_top_disp_y", "platen_bottom_disp_y") if v not in h.values]
        if missing:
            raise SystemExit(f"{path}: no {', '.join(missing)}")
        top, bottom = h.values["platen_top_disp_y"], h.values["platen_bottom_disp_y"]
        strain = np.abs((top - top[0]) - (bottom - bottom[0])) / HEIGHT
        stress = np.abs(h.values["platen_top_force_y"]) / (WIDTH * THICKNESS) / 1e6
        peak = int(np.nanargmax(stress))
        ax.plot(strain * 1e3, stress, label=f"{label}: peak {stress[peak]:.2f} MPa at strain {strain[peak] * 1e3:.2f}e-3")
    ax.set_xlabel("axial strain [1e-3]")
    ax.set_ylabel("axial stress [MPa]")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("exodus")
    p.add_argument("-o", "--output", default="grains_map.png")
    p.add_argument("--frame", type=int, default=0)
    p.add_argument("--history", nargs=2, action="append", metavar=("FILE", "LABEL"), default=[])
    args = p.parse_args(argv)
    exo = load_exodus(args.exodus)
    panels = 2 if args.history else 1
    fig, axes = plt.subplots(1, panels, figsize=(4.2 * panels + (1.5 if panels > 1 else 0), 7.5), squeeze=False)
    grain_map(axes[0][0], exo, args.frame)
    if args.history:
        stress_strain(axes[0][1], args.history)
    fig.tight_layout()
    fig.savefig(args.output, dpi=130)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
