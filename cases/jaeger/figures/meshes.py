#!/usr/bin/python3
"""The meshes of cases/jaeger with their joint CE4s (JOINT >= 1) in red, from Exodus files:
    /usr/bin/python3 cases/jaeger/figures/meshes.py OUT1/jaeger.exo:TITLE1 ... PNG
(figures/joints.png: the validation runs jaeger-b45 and jaeger-b70, and a one-step run of
the intact specimen with a [[joint]] set as in tests/test_joints.cpp)."""
import sys, netCDF4 as nc, numpy as np, matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.collections import LineCollection
files = sys.argv[1:-1]; out = sys.argv[-1]
fig, axes = plt.subplots(1, len(files), figsize=(3.0 * len(files), 5.2))
for ax, spec in zip(axes, files):
    path, title = spec.split(":", 1)
    d = nc.Dataset(path)
    x, y = d["coordx"][:] * 1e3, d["coordy"][:] * 1e3
    tri = d["connect1"][:] - 1
    ce4 = d["connect2"][:] - 1
    names = [n.tobytes().decode().rstrip("\x00").strip() for n in d["name_elem_var"][:]]
    k = names.index("JOINT") + 1
    joint = d[f"vals_elem_var{k}eb2"][-1]
    segs = [[(x[t[i]], y[t[i]]), (x[t[(i + 1) % 3]], y[t[(i + 1) % 3]])] for t in tri for i in range(3)]
    ax.add_collection(LineCollection(segs, colors="0.6", linewidths=0.3))
    js = [[(x[c[0]], y[c[0]]), (x[c[1]], y[c[1]])] for c, j in zip(ce4, joint) if j >= 1]
    ax.add_collection(LineCollection(js, colors="C3", linewidths=1.6))
    ax.set_aspect("equal"); ax.set_xlim(-27, 27); ax.set_ylim(-52, 52)
    ax.set_title(title, fontsize=8); ax.set_xlabel("x [mm]")
axes[0].set_ylabel("y [mm]")
fig.tight_layout(); fig.savefig(out, dpi=120); print(out)
