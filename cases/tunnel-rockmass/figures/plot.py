#!/usr/bin/python3
"""Measures and figures of cases/tunnel-rockmass from a run's output folder:
    /usr/bin/python3 cases/tunnel-rockmass/figures/plot.py OUT [FIGURES]
(OUT: the run's output.dir, default out/tunnel-rockmass; FIGURES: where the PNGs go,
default cases/tunnel-rockmass/figures). Prints the broken CE4s (on the joints, and any
with an excavated triangle), the wall convergence, excavated_energy and the worst
|energy_error|; writes tunnel.png (the mesh round the tunnel: joint CE4s red, broken CE4s
blue, the wall's displacement magnified) and history.png (the ramp, breaks, convergence
and energy_error against time)."""
import os, sys
import numpy as np, netCDF4 as nc, matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.collections import LineCollection

out = sys.argv[1] if len(sys.argv) > 1 else "out/tunnel-rockmass"
figs = sys.argv[2] if len(sys.argv) > 2 else os.path.join(os.path.dirname(os.path.abspath(__file__)))
A = 1.0  # tunnel radius [m]

exo = nc.Dataset(os.path.join(out, "tunnel.exo"))
his = nc.Dataset(os.path.join(out, "tunnel_history.nc"))
ev = nc.Dataset(os.path.join(out, "tunnel_events.nc"))
names = lambda v: [n.tobytes().decode().rstrip("\x00").strip() for n in exo[v][:]]
ev_names, nod_names = names("name_elem_var"), names("name_nod_var")
def elem(name, block):
    return exo[f"vals_elem_var{ev_names.index(name) + 1}eb{block}"]
def nod(name):
    return exo[f"vals_nod_var{nod_names.index(name) + 1}"]
x, y = exo["coordx"][:], exo["coordy"][:]
tri = exo["connect1"][:] - 1
ce4 = exo["connect2"][:] - 1
times = exo["time_whole"][:]
gone = elem("EXCAVATED", 1)[-1]
joint = elem("JOINT", 2)[-1]
broken = elem("BROKEN", 2)[-1]

# Breaks: how many, how many on the joints, and none with an excavated triangle after the ramp began.
bt, bj = ev["break_time"][:], ev["break_joint"][:]
ta, tb = ev["break_tri_a"][:], ev["break_tri_b"][:]
ramped_breaks = int(sum(1 for a, b in zip(ta, tb) if gone[a] > 0 or gone[b] > 0))
print(f"broken CE4s: {len(bt)} ({int((bj >= 0).sum())} on the joints, {len(bt) - int((bj >= 0).sum())} in the rock); "
      f"{ramped_breaks} with an excavated triangle")

# Wall convergence: the wall's nodes on the rock's triangles (reference radius a).
keep = np.zeros(len(x), bool)
for t, g in zip(tri, gone):
    if g == 0:
        keep[t] = True
r = np.hypot(x, y)
wall = np.where(keep & (np.abs(r - A) < 1e-6))[0]
theta = np.degrees(np.arctan2(y[wall], x[wall])) % 360
def radial(frame):
    ux, uy = nod("DISPLX")[frame][wall], nod("DISPLY")[frame][wall]
    return (ux * x[wall] + uy * y[wall]) / r[wall]  # outward positive
def near(angle):
    d = np.abs((theta - angle + 180) % 360 - 180)
    return d < 6.0
def convergence(frame):
    ur = radial(frame)
    # Diametral closure (positive inward): springline (0°, 180°) and crown-invert (90°, 270°).
    horiz = -(ur[near(0)].mean() + ur[near(180)].mean())
    vert = -(ur[near(90)].mean() + ur[near(270)].mean())
    return horiz, vert, -ur.mean()
h, v, m = convergence(-1)
print(f"wall convergence at t = {times[-1] * 1e3:.1f} ms: horizontal (0°-180°) {h * 1e3:.3f} mm, "
      f"vertical (90°-270°) {v * 1e3:.3f} mm, mean radial {m * 1e3:.3f} mm ({len(wall)} wall nodes)")
err = his["energy_error"][:]
print(f"excavated_energy {his['excavated_energy'][-1] / 1e3:.2f} kJ, fracture_dissipation "
      f"{his['fracture_dissipation'][-1] / 1e3:.2f} kJ, worst |energy_error| {np.abs(err).max():.2e}, "
      f"unbalanced_ratio last row {his['unbalanced_ratio'][-1]:.3f}")

# Figure 1: the mesh round the tunnel, joints and breaks, the wall's displacement ×200.
fig, ax = plt.subplots(figsize=(6.2, 6.0))
rock = [t for t, g in zip(tri, gone) if g == 0]
segs = [[(x[t[i]], y[t[i]]), (x[t[(i + 1) % 3]], y[t[(i + 1) % 3]])] for t in rock for i in range(3)]
ax.add_collection(LineCollection(segs, colors="0.75", linewidths=0.3))
js = [[(x[c[0]], y[c[0]]), (x[c[1]], y[c[1]])] for c, j in zip(ce4, joint)
      if j >= 1 and np.hypot(0.5 * (x[c[0]] + x[c[1]]), 0.5 * (y[c[0]] + y[c[1]])) > A]  # the rock's
ax.add_collection(LineCollection(js, colors="C3", linewidths=1.4, label="joint CE4s"))
bs = [[(x[c[0]], y[c[0]]), (x[c[1]], y[c[1]])] for c, b in zip(ce4, broken) if b >= 1]
ax.add_collection(LineCollection(bs, colors="C0", linewidths=2.6, label="broken CE4s"))
order = np.argsort(theta)
ux, uy = nod("DISPLX")[-1][wall][order], nod("DISPLY")[-1][wall][order]
mag = 200.0
ax.plot(np.r_[x[wall][order], x[wall][order][0]], np.r_[y[wall][order], y[wall][order][0]], "k--", lw=0.8,
        label="wall at the start")
ax.plot(np.r_[x[wall][order] + mag * ux, x[wall][order][0] + mag * ux[0]],
        np.r_[y[wall][order] + mag * uy, y[wall][order][0] + mag * uy[0]], "k", lw=1.4,
        label=f"wall at {times[-1] * 1e3:.0f} ms (displacement × {mag:.0f})")
ax.set_xlim(-3.5, 3.5); ax.set_ylim(-3.5, 3.5); ax.set_aspect("equal")
ax.set_xlabel("x [m]"); ax.set_ylabel("y [m]")
ax.set_title("tunnel-rockmass: σ_H 15 MPa (x), σ_h 7.5 MPa (y), joints at 30°", fontsize=9)
ax.legend(loc="lower right", fontsize=7)
fig.tight_layout(); fig.savefig(os.path.join(figs, "tunnel.png"), dpi=120)

# Figure 2: against time.
t = his["time"][:] * 1e3
fig, axes = plt.subplots(2, 2, figsize=(9, 6), sharex=True)
axes[0, 0].plot(t, his["excavated_energy"][:] / 1e3, label="excavated_energy")
axes[0, 0].plot(t, his["fracture_dissipation"][:] / 1e3, label="fracture_dissipation")
axes[0, 0].set_ylabel("kJ"); axes[0, 0].legend(fontsize=7)
axes[0, 1].plot(t, his["broken_ce4"][:]); axes[0, 1].set_ylabel("broken CE4s")
conv = np.array([convergence(k) for k in range(len(times))]) * 1e3
axes[1, 0].plot(times * 1e3, conv[:, 0], "o-", label="horizontal (0°–180°)")
axes[1, 0].plot(times * 1e3, conv[:, 1], "s-", label="vertical (90°–270°)")
axes[1, 0].set_ylabel("wall convergence [mm]"); axes[1, 0].legend(fontsize=7)
axes[1, 1].semilogy(t, np.maximum(np.abs(err), 1e-16)); axes[1, 1].set_ylabel("|energy_error|")
for a in axes[1]:
    a.set_xlabel("time [ms]")
for a in axes.flat:
    a.axvspan(1.0, 6.0, color="0.9", zorder=0)  # the ramp ([[excavation]] start, duration)
fig.tight_layout(); fig.savefig(os.path.join(figs, "history.png"), dpi=120)
print(os.path.join(figs, "tunnel.png"), os.path.join(figs, "history.png"))
