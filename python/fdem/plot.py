"""Plot fdem-cl output without ParaView.

  fdem-plot field OUT.exo --var SXX [--frame -1 | --time T | --frames A B C | --times T1 T2]
            [--cracks] [--deformed-scale 1.0] [--cmap viridis] [--range LO HI] -o field.png
  fdem-plot history OUT_history.nc VAR [VAR ...] [--log] -o hist.png
  fdem-plot stress-strain OUT_history.nc --test brazilian|ucs --load-region top_platen
            [--support-region bottom_platen] --size D --thickness t [--width W]
            [--mark-times T1 T2 T3] -o curve.png [--csv curve.csv]
  fdem-plot cracks OUT.exo [--frame -1 | --time T] -o cracks.png
  fdem-plot compare VAR A_history.nc[:LABEL] B_history.nc[:LABEL] [--normalize] [--ms] -o c.png
  fdem-plot bench BENCH.csv[:LABEL] ... -o bench.png
  fdem-plot events OUT [--breaks] [--mc MC] [--dm DM] [--bin-width 0.1] [-o OUT/NAME_events.png]
  fdem-plot fragments OUT [--frame -1] [--without-largest] [--include-unfracturable]
            [-o OUT/NAME_fragments.png]

OUT is a run's output folder, OUT/NAME when it holds several runs, or one of its files.

Stresses are shown in MPa (--range is in the units shown). Exit codes: 0 success,
2 bad input (unknown variable, frame out of range, unreadable file).
"""

import argparse
import os
import re
import sys
import warnings

import numpy as np  # noqa: E402
import matplotlib  # noqa: E402

matplotlib.use("Agg")  # files only: no display needed
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.tri import Triangulation  # noqa: E402
from mpl_toolkits.axes_grid1 import make_axes_locatable  # noqa: E402

from . import figures  # noqa: E402
from . import load as fdem_load  # noqa: E402


class PlotError(Exception):
    """Bad input from the user: reported in one line, exit code 2."""


# Exodus carries no units; fdem-cl's element variable names follow these conventions.
_STRESS = re.compile(r"^(S(XX|YY|ZZ|XY|YZ|XZ|[123]|MAX|MIN|VM|MISES)|PS[123]|(VON_?)?MISES|"
                     r"PRESSURE|FLUID_PRESSURE|STRESS\w*|SIG\w*)$", re.IGNORECASE)
_UNITS = [
    (re.compile(r"^DISPL?[XYZ]?$|^DISP\w*$", re.IGNORECASE), "m", 1.0),
    (re.compile(r"^VEL\w*$", re.IGNORECASE), "m/s", 1.0),
    (re.compile(r"^(OPENING|SLIP|FLUID_APERTURE)$", re.IGNORECASE), "m", 1.0),
    (re.compile(r"^(STRAIN|E(XX|YY|XY))\w*$", re.IGNORECASE), "", 1.0),
]


def display_unit(name):
    """(unit label, divisor) for an element or nodal variable name."""
    if _STRESS.match(name):
        return "MPa", 1.0e6
    for pattern, unit, divisor in _UNITS:
        if pattern.match(name):
            return unit, divisor
    return "", 1.0


def axis_label(name, unit):
    return f"{name} [{unit}]" if unit else name


def choose_frame(exo, frame, time):
    """Index of the frame to plot: nearest to `time` when given, else `frame`."""
    n = exo.num_frames
    if n == 0:
        raise PlotError(f"{exo.path} has no frames yet")
    if time is not None:
        return int(np.argmin(np.abs(exo.times - time)))
    if not -n <= frame < n:
        raise PlotError(f"frame {frame} out of range: {exo.path} has {n} frames "
                        f"(0..{n - 1}, or -1 for the last)")
    return frame % n


def load(path, loader):
    try:
        return loader(path)
    except FileNotFoundError:
        raise PlotError(f"{path}: no such file")
    except (OSError, KeyError, ValueError) as exc:
        raise PlotError(f"{path}: cannot read it as fdem-cl output ({exc})")


COHESIVE_BLOCK = "cohesive"
# Failure modes of broken CE4s as the engine writes them in MODE, with their colors.
MODES = [(1, "mode I", "tab:red"), (2, "mode II", "tab:blue"), (3, "mixed", "tab:green")]


def triangles_of(blocks):
    """Triangles of every block and, per triangle, the index of its element in the
    block-concatenated element order. Quadrilaterals are split in two; the `cohesive`
    block (CE4s: zero area while intact, drawn as cracks instead) and line elements are
    not filled: skipped (the cohesive block silently)."""
    tris, owner, skipped = [], [], []
    first = 0
    for blk in blocks:
        conn = blk.connectivity
        elems = np.arange(first, first + blk.num_elem)
        kind = blk.elem_type.upper()
        if blk.name.lower() == COHESIVE_BLOCK:
            pass
        elif kind.startswith("TRI") and conn.shape[1] >= 3:
            tris.append(conn[:, :3])
            owner.append(elems)
        elif (kind.startswith("QUAD") or kind.startswith("SHELL")) and conn.shape[1] >= 4:
            tris.append(conn[:, [0, 1, 2]])
            tris.append(conn[:, [0, 2, 3]])
            owner.extend([elems, elems])
        else:
            skipped.append(f"{blk.name} ({blk.elem_type or 'no type'})")
        first += blk.num_elem
    if not tris:
        return np.zeros((0, 3), dtype=np.int64), np.zeros(0, dtype=np.int64), skipped
    return np.concatenate(tris), np.concatenate(owner), skipped


def cohesive_block(exo):
    """Index of the `cohesive` QUAD4 block, or None."""
    for b, blk in enumerate(exo.blocks):
        if blk.name.lower() == COHESIVE_BLOCK and blk.connectivity.shape[1] >= 4:
            return b
    return None


def broken_faces(exo, frame, path):
    """Both faces of every broken CE4 at `frame`: (node pairs (2k, 2), MODE per pair).
    A CE4 (i, j, j', i') has faces i-j and i'-j'; they coincide until it opens."""
    b = cohesive_block(exo)
    if b is None:
        raise PlotError(f"{path} has no '{COHESIVE_BLOCK}' element block (the case has no "
                        f"fracturable material?); blocks: "
                        f"{', '.join(blk.name for blk in exo.blocks) or 'none'}")
    if "BROKEN" not in exo.element:
        raise PlotError(f"no element variable 'BROKEN' in {path}; available: "
                        f"{', '.join(exo.element) or 'none'}")
    broken = exo.element["BROKEN"][b][frame]
    broken = np.isfinite(broken) & (broken > 0.5)
    conn = exo.blocks[b].connectivity[broken]
    if "MODE" in exo.element:
        mode = np.nan_to_num(exo.element["MODE"][b][frame][broken]).round().astype(int)
    else:
        mode = np.zeros(len(conn), dtype=int)
    pairs = np.concatenate([conn[:, [0, 1]], conn[:, [3, 2]]])
    return pairs, np.concatenate([mode, mode])


def deformed_coordinates(exo, frame, scale, path):
    x, y = exo.x.copy(), exo.y.copy()
    if "DISPLX" in exo.nodal and "DISPLY" in exo.nodal:
        scale = 1.0 if scale is None else scale
        x += scale * exo.nodal["DISPLX"][frame]
        y += scale * exo.nodal["DISPLY"][frame]
    elif scale not in (None, 0.0):
        print(f"fdem-plot: note: {path} has no DISPLX/DISPLY; plotting the "
              "undeformed mesh", file=sys.stderr)
    return x, y


def outline_edges(exo):
    """Node pairs of the mesh outline: triangle edges used by one triangle only, less
    the CE4 faces (in a fracturable region every triangle has its own nodes, so the
    edges between triangles are told apart by the CE4 joining them)."""
    edges = []
    for blk in exo.blocks:
        if blk.name.lower() == COHESIVE_BLOCK or not blk.elem_type.startswith("TRI"):
            continue
        conn = blk.connectivity[:, :3]
        edges.append(np.concatenate([conn[:, [0, 1]], conn[:, [1, 2]], conn[:, [2, 0]]]))
    if not edges:
        return np.zeros((0, 2), dtype=np.int64)
    edges = np.sort(np.concatenate(edges), axis=1)
    keys, counts = np.unique(edges, axis=0, return_counts=True)
    outline = keys[counts == 1]
    b = cohesive_block(exo)
    if b is not None and len(outline):
        conn = exo.blocks[b].connectivity
        faces = np.sort(np.concatenate([conn[:, [0, 1]], conn[:, [3, 2]]]), axis=1)
        width = int(max(outline.max(), faces.max() if len(faces) else 0)) + 1
        inner = np.isin(outline[:, 0] * width + outline[:, 1],
                        faces[:, 0] * width + faces[:, 1])
        outline = outline[~inner]
    return outline


def draw_segments(ax, x, y, pairs, **style):
    if len(pairs):
        segs = np.stack([np.column_stack([x[pairs[:, 0]], y[pairs[:, 0]]]),
                         np.column_stack([x[pairs[:, 1]], y[pairs[:, 1]]])], axis=1)
        ax.add_collection(LineCollection(segs, **style))


def plot_field(args):
    exo = load(args.file, fdem_load.load_exodus)
    if args.var not in exo.element:
        available = ", ".join(exo.element) or "none"
        raise PlotError(f"no element variable {args.var!r} in {args.file}; "
                        f"available: {available}")
    if args.frames is not None:
        frames = [choose_frame(exo, f, None) for f in args.frames]
    elif args.times is not None:
        frames = [choose_frame(exo, -1, t) for t in args.times]
    else:
        frames = [choose_frame(exo, args.frame, args.time)]
    unit, divisor = display_unit(args.var)

    tris, owner, skipped = triangles_of(exo.blocks)
    if skipped:
        print(f"fdem-plot: note: blocks not drawn: {', '.join(skipped)}", file=sys.stderr)
    if len(tris) == 0:
        raise PlotError(f"{args.file}: no triangle or quadrilateral blocks to draw")

    # Per frame: coordinates, values on the drawn triangles, broken CE4 faces.
    panels = []
    for frame in frames:
        x, y = deformed_coordinates(exo, frame, args.deformed_scale, args.file)
        face_values = exo.element_values(args.var, frame)[owner] / divisor
        cracks = broken_faces(exo, frame, args.file)[0] if args.cracks else None
        panels.append((frame, x, y, face_values, cracks))

    if args.range is not None:
        vmin, vmax = args.range
    else:
        # One color scale for every frame shown, so that they compare.
        finite = np.concatenate([p[3][np.isfinite(p[3])] for p in panels])
        if len(finite) == 0:
            raise PlotError(f"{args.var} has no finite value at frame"
                            f"{'s' if len(frames) > 1 else ''} "
                            f"{', '.join(map(str, frames))}")
        vmin, vmax = float(np.min(finite)), float(np.max(finite))

    several = len(panels) > 1
    if several:
        fig, axes = plt.subplots(1, len(panels), figsize=(4.2 * len(panels) + 1.2, 5.0),
                                 sharex=True, sharey=True, squeeze=False,
                                 layout="constrained")
        axes = axes[0]
    else:
        fig, ax = plt.subplots(figsize=(8, 6))
        axes = [ax]
    # Element outlines help on small meshes and turn into noise on large ones.
    edges = dict(edgecolors="k", linewidth=0.3) if len(tris) <= 5000 else \
        dict(edgecolors="face", linewidth=0.0)
    for ax, (frame, x, y, face_values, cracks) in zip(axes, panels):
        # Elements where the variable is undefined (truth table 0) are left blank.
        missing = ~np.isfinite(face_values)
        triang = Triangulation(x, y, tris, mask=missing if missing.any() else None)
        mappable = ax.tripcolor(triang, facecolors=face_values, cmap=args.cmap,
                                vmin=vmin, vmax=vmax, shading="flat", **edges)
        if cracks is not None:
            draw_segments(ax, x, y, cracks, colors="k", linewidths=1.0)
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        t = exo.times[frame]
        if several:
            n_broken = len(cracks) // 2 if cracks is not None else None
            ax.set_title(f"t = {t:.4g} s (frame {frame})" +
                         (f"\n{n_broken} broken CE4s" if n_broken is not None else ""),
                         fontsize="medium")
    axes[0].set_ylabel("y [m]")
    label = axis_label(args.var, unit)
    if several:
        fig.colorbar(mappable, ax=list(axes), label=label, shrink=0.8)
        fig.suptitle(f"{args.var}{' and broken CE4s' if args.cracks else ''} "
                     f"(frames 0-{exo.num_frames - 1})")
    else:
        ax, frame = axes[0], frames[0]
        # A colorbar as tall as the (equal-aspect) mesh, not as the figure.
        cax = make_axes_locatable(ax).append_axes("right", size="4%", pad=0.1)
        fig.colorbar(mappable, cax=cax, label=label)
        t = exo.times[frame]
        title = f"{args.var} at t = {t:.6g} s (frame {frame}; frames 0-{exo.num_frames - 1})"
        if args.time is not None and not np.isclose(t, args.time):
            title += f", nearest to {args.time:g} s"
        if args.cracks:
            title += f"\nbroken CE4s in black: {len(panels[0][4]) // 2}"
        ax.set_title(title)
        fig.tight_layout()
    save(fig, args.output)


def plot_cracks(args):
    """Mesh outline and broken CE4s colored by failure mode (or, with --rose, their
    orientation roses)."""
    if args.rose:
        return plot_crack_rose(args)
    if args.events:
        raise PlotError("--events goes with --rose")
    exo = load(args.file, fdem_load.load_exodus)
    frame = choose_frame(exo, args.frame, args.time)
    x, y = deformed_coordinates(exo, frame, args.deformed_scale, args.file)
    pairs, modes = broken_faces(exo, frame, args.file)
    outline = outline_edges(exo)

    fig, ax = plt.subplots(figsize=(7, 7))
    draw_segments(ax, x, y, outline, colors="0.35", linewidths=0.8)
    handles = []
    counts = []
    known = set()
    for value, name, color in MODES:
        chosen = pairs[modes == value]
        known.add(value)
        draw_segments(ax, x, y, chosen, colors=color, linewidths=1.2)
        counts.append(len(chosen) // 2)
        handles.append(Line2D([], [], color=color, lw=2, label=f"{name} ({len(chosen) // 2})"))
    other = pairs[~np.isin(modes, list(known))]
    if len(other):
        draw_segments(ax, x, y, other, colors="0.6", linewidths=1.2)
        handles.append(Line2D([], [], color="0.6", lw=2,
                              label=f"mode not given ({len(other) // 2})"))
    handles.append(Line2D([], [], color="0.35", lw=0.8, label="outline"))
    ax.autoscale_view()
    used = np.unique(np.concatenate([outline.ravel(), pairs.ravel()])) if \
        len(outline) or len(pairs) else np.arange(len(x))
    if len(used):
        pad = 0.03 * max(np.ptp(x[used]), np.ptp(y[used]), 1e-12)
        ax.set_xlim(x[used].min() - pad, x[used].max() + pad)
        ax.set_ylim(y[used].min() - pad, y[used].max() + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.02, 1.0),
              title="broken CE4s", fontsize="small")
    ax.set_title(f"broken CE4s at t = {exo.times[frame]:.6g} s (frame {frame}; "
                 f"frames 0-{exo.num_frames - 1}): {len(pairs) // 2}")
    fig.tight_layout()
    save(fig, args.output)
    print(f"frame {frame}, t = {exo.times[frame]:.6g} s: {len(pairs) // 2} broken CE4s "
          f"(mode I {counts[0]}, mode II {counts[1]}, mixed {counts[2]})")


def draw_rose(ax, fractions, color="tab:blue", title=""):
    """A rose of undirected directions on a polar axis: each bin drawn at angle and angle
    + 180 degrees, radius the fraction in percent."""
    bins = len(fractions)
    width = np.pi / bins
    centres = (np.arange(bins) + 0.5) * width
    radius = 100.0 * np.asarray(fractions)
    for offset in (0.0, np.pi):
        ax.bar(centres + offset, radius, width=width * 0.95, color=color, alpha=0.8,
               edgecolor="k", linewidth=0.3)
    ax.set_theta_zero_location("E")
    ax.set_theta_direction(1)
    ax.set_yticklabels([])
    if title:
        ax.set_title(title, fontsize="small")


def rose_of_breaks(exo, path, frame, events_path):
    """(directions, modes) of the broken CE4s: from the events catalogue (break_ce4,
    break_mode; breaks up to the frame's time) when `events_path` is given, else from
    the frame's BROKEN and MODE."""
    from . import orientation
    if events_path:
        from . import output
        try:
            ev = output.read_events(events_path)
        except (OSError, ValueError) as exc:
            raise PlotError(f"{events_path}: cannot read it ({exc})")
        if "break_ce4" not in ev:
            raise PlotError(f"{events_path}: no break_ce4 (not an events file, or one "
                            f"written before the catalogue named its CE4s)")
        keep = ev["break_time"].values <= exo.times[frame] if frame is not None else \
            np.ones(len(ev["break_ce4"]), dtype=bool)
        which = ev["break_ce4"].values[keep].astype(int)
        modes = np.nan_to_num(ev["break_mode"].values[keep]).round().astype(int)
    else:
        b = cohesive_block(exo)
        if b is None or "BROKEN" not in exo.element:
            raise PlotError(f"{path}: no cohesive block with BROKEN: nothing to make a rose of")
        broken = exo.element["BROKEN"][b][frame]
        which = np.flatnonzero(np.isfinite(broken) & (broken > 0.5))
        modes = np.nan_to_num(exo.element["MODE"][b][frame][which]).round().astype(int) \
            if "MODE" in exo.element else np.zeros(len(which), dtype=int)
    try:
        angles = orientation.ce4_directions(exo, which)
    except (ValueError, IndexError) as exc:
        raise PlotError(f"{path}: {exc} (the events file is of another mesh?)")
    return angles, modes


def plot_crack_rose(args):
    """Crack-orientation roses: all broken CE4s and each mode, with the mesh's CE4 rose."""
    from . import orientation
    exo = load(args.file, fdem_load.load_exodus)
    frame = choose_frame(exo, args.frame, args.time)
    angles, modes = rose_of_breaks(exo, args.file, frame, args.events)
    mesh_angles = orientation.ce4_directions(exo)
    panels = [("mesh: every CE4", mesh_angles, "0.5"), ("all broken CE4s", angles, "k")]
    panels += [(name, angles[modes == value], color) for value, name, color in MODES]
    fig, axes = plt.subplots(1, len(panels), figsize=(3.2 * len(panels), 3.8),
                             subplot_kw={"projection": "polar"})
    lines = []
    for ax, (name, values, color) in zip(axes, panels):
        fractions = orientation.histogram(values, args.bins)
        draw_rose(ax, fractions, color=color, title=f"{name} ({len(values)})")
        lines.append(f"{name} ({len(values)}): {orientation.format_bins(fractions)} %"
                     + (f"; lattice share {100 * orientation.lattice_share(values):.1f} %"
                        if args.bins == 12 and len(values) else ""))
    when = f"t = {exo.times[frame]:.6g} s (frame {frame})"
    fig.suptitle(args.title or f"crack orientation at {when}, {args.bins} bins of "
                 f"{180 / args.bins:g}\N{DEGREE SIGN} from x, counter-clockwise")
    fig.tight_layout()
    save(fig, args.output)
    print(f"{when}: directions in {args.bins} bins of {180 / args.bins:g} deg from 0 deg (x axis)")
    for line in lines:
        print(line)


def plot_mesh_rose(args):
    """Edge-orientation roses of the CE4s (interior edges of fracturable regions) of one
    or more runs' meshes, side by side."""
    from . import orientation
    runs = []
    for spec in args.files:
        path, _, label = spec.partition(":") if not os.path.exists(spec) else (spec, "", "")
        exo = load(path, fdem_load.load_exodus)
        try:
            angles = orientation.ce4_directions(exo)
        except ValueError as exc:
            raise PlotError(str(exc))
        runs.append((label or os.path.basename(os.path.dirname(os.path.abspath(path))) or path,
                     angles))
    fig, axes = plt.subplots(1, len(runs), figsize=(3.4 * len(runs), 3.9),
                             subplot_kw={"projection": "polar"}, squeeze=False)
    for ax, (label, angles) in zip(axes[0], runs):
        fractions = orientation.histogram(angles, args.bins)
        share = orientation.lattice_share(angles)
        draw_rose(ax, fractions, title=f"{label}\n{len(angles)} CE4s, lattice share "
                                       f"{100 * share:.1f} %")
        print(f"{label}: {len(angles)} CE4s; {args.bins} bins of {180 / args.bins:g} deg: "
              f"{orientation.format_bins(fractions)} %; lattice share {100 * share:.1f} %")
    fig.suptitle(args.title or "directions of the fracturable regions' interior edges")
    fig.tight_layout()
    save(fig, args.output)


# Loading tests: the stress on the specimen from the load region's force F [N].
TESTS = {
    "brazilian": ("indirect tensile stress 2F/(\u03c0Dt)",
                  lambda force, a: 2.0 * force / (np.pi * a.size * a.thickness)),
    "ucs": ("axial stress F/(Wt)", lambda force, a: force / (a.width * a.thickness)),
}


def plot_stress_strain(args):
    hist = load(args.file, fdem_load.load_history)
    force_var = f"{args.load_region}_force_y"
    disp_vars = [f"{args.load_region}_disp_y"]
    if args.support_region:
        disp_vars.append(f"{args.support_region}_disp_y")
    missing = [v for v in [force_var] + disp_vars if v not in hist.values]
    if missing:
        raise PlotError(f"no variable {', '.join(map(repr, missing))} in {args.file} "
                        f"(--load-region {args.load_region}"
                        f"{' --support-region ' + args.support_region if args.support_region else ''}"
                        f"); available: {', '.join(hist.values) or 'none'}")
    if len(hist.times) == 0:
        raise PlotError(f"{args.file} has no rows yet")

    force = np.abs(hist.values[force_var])
    load_disp = hist.values[disp_vars[0]] - hist.values[disp_vars[0]][0]
    if args.support_region:
        support = hist.values[disp_vars[1]] - hist.values[disp_vars[1]][0]
        closure = np.abs(load_disp - support)
    else:
        closure = np.abs(load_disp)  # a fixed support
    strain = closure / args.size
    name, formula = TESTS[args.test]
    stress = formula(force, args)

    k = int(np.nanargmax(stress))
    peak, peak_strain, peak_time = float(stress[k]), float(strain[k]), float(hist.times[k])

    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    ax.plot(strain, stress / 1e6, color="tab:blue", lw=1.5, label=name)
    ax.plot([peak_strain], [peak / 1e6], "o", color="tab:red", ms=7,
            label=f"peak {peak / 1e6:.4g} MPa at strain {peak_strain:.4g} (t = {peak_time:.4g} s)")
    for letter, t in zip("ABCDEFGHIJ", args.mark_times or []):
        j = int(np.argmin(np.abs(hist.times - t)))
        ax.plot([strain[j]], [stress[j] / 1e6], "s", color="k", ms=5)
        ax.annotate(letter, (strain[j], stress[j] / 1e6), textcoords="offset points",
                    xytext=(5, 5), fontweight="bold")
    ax.set_xlabel("axial strain (relative platen displacement / "
                  f"{'D' if args.test == 'brazilian' else 'H'}) [-]")
    ax.set_ylabel(f"{'indirect tensile' if args.test == 'brazilian' else 'axial'} "
                  "stress [MPa]")
    ax.set_xlim(left=0.0)
    ax.set_ylim(bottom=min(0.0, float(np.nanmin(stress)) / 1e6))
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    geometry = (f"D = {args.size * 1e3:g} mm" if args.test == "brazilian" else
                f"H = {args.size * 1e3:g} mm, W = {args.width * 1e3:g} mm")
    ax.set_title(args.title or f"{'Brazilian' if args.test == 'brazilian' else 'Uniaxial compression'}"
                 f" test: {geometry}, t = {args.thickness * 1e3:g} mm")
    fig.tight_layout()
    save(fig, args.output)

    if args.csv:
        try:
            with open(args.csv, "w") as out:
                out.write("time_s,relative_displacement_m,strain,force_N,stress_Pa\n")
                for row in zip(hist.times, closure, strain, force, stress):
                    out.write(",".join(f"{v:.17g}" for v in row) + "\n")
        except OSError as exc:
            raise PlotError(f"cannot write {args.csv}: {exc.strerror or exc}")
    print(f"peak stress: {peak / 1e6:.6g} MPa at strain {peak_strain:.6g} "
          f"(t = {peak_time:.6g} s, F = {force[k]:.6g} N, row {k})")


def plot_history(args):
    hist = load(args.file, fdem_load.load_history)
    unknown = [v for v in args.vars if v not in hist.values]
    if unknown:
        raise PlotError(f"no variable {', '.join(map(repr, unknown))} in {args.file}; "
                        f"available: {', '.join(hist.values) or 'none'}")
    if len(hist.times) == 0:
        raise PlotError(f"{args.file} has no rows yet")

    # One axes per distinct unit, in the order the variables were asked for.
    groups = {}
    for v in args.vars:
        groups.setdefault(hist.units[v], []).append(v)
    fig, axes = plt.subplots(len(groups), 1, sharex=True, squeeze=False,
                             figsize=(8, 2.2 + 2.3 * len(groups)))
    for ax, (unit, names) in zip(axes[:, 0], groups.items()):
        for name in names:
            values = hist.values[name]
            if args.log and np.any(values <= 0):
                print(f"fdem-plot: note: {name} has values <= 0, not shown on a log scale",
                      file=sys.stderr)
            ax.plot(hist.times, values, label=f"{name} ({hist.long_names[name]})"
                    if hist.long_names[name] != name else name)
        if args.log:
            ax.set_yscale("log")
        ax.set_ylabel(f"[{unit}]" if unit else "value")
        ax.legend(loc="best", fontsize="small")
        ax.grid(True, alpha=0.3)
    axes[-1, 0].set_xlabel("time [s]")
    axes[0, 0].set_title(hist.title or os.path.basename(args.file))
    fig.tight_layout()
    save(fig, args.output)


def plot_compare(args):
    """One history variable from several runs on one axes (e.g. impact curves for several b)."""
    fig, ax = plt.subplots(figsize=(8, 4.5))
    unit = None
    for spec in args.runs:
        path, _, label = spec.partition(":")
        hist = load(path, fdem_load.load_history)
        if args.var not in hist.values:
            raise PlotError(f"no variable {args.var!r} in {path}; available: {', '.join(hist.values) or 'none'}")
        values = hist.values[args.var]
        if args.normalize:
            if len(values) == 0 or values[0] == 0:
                raise PlotError(f"{path}: cannot normalise {args.var} by its first value")
            values = values / values[0]
        unit = hist.units[args.var]
        ax.plot(hist.times * args.time_scale, values, label=label or os.path.basename(path))
    ax.set_xlabel("time [ms]" if args.time_scale == 1e3 else "time [s]")
    ax.set_ylabel(f"{args.var} / initial" if args.normalize else f"{args.var} [{unit}]" if unit else args.var)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    if args.title:
        ax.set_title(args.title)
    fig.tight_layout()
    save(fig, args.output)


def plot_bench(args):
    """ms/step against TRI3 from `fdem bench --csv` files, with the paper's GP100 times."""
    import csv
    fig, ax = plt.subplots(figsize=(7, 4.5))
    paper = {}
    for spec in args.csv:
        path, _, label = spec.partition(":")
        try:
            with open(path, newline="") as f:
                rows = list(csv.DictReader(f))
        except OSError as exc:
            raise PlotError(f"cannot read {path}: {exc.strerror or exc}")
        need = {"tri3", "ms_per_step", "paper_ms_per_step"}
        if not rows or not need <= set(rows[0]):
            raise PlotError(f"{path}: not an fdem bench CSV (columns {', '.join(sorted(need))} needed)")
        rows.sort(key=lambda r: float(r["tri3"]))
        tri = np.array([float(r["tri3"]) for r in rows])
        ms = np.array([float(r["ms_per_step"]) for r in rows])
        ax.plot(tri, ms, "o-", label=label or os.path.basename(path))
        if len(tri) >= 2:
            # Linear model ms = a + b·TRI3 by least squares, and its largest relative miss.
            b, a = np.polyfit(tri, ms, 1)
            miss = np.max(np.abs(a + b * tri - ms) / ms)
            print(f"{path}: ms/step ≈ {a:.4g} + {b * 1e6:.4g} × TRI3/1e6, largest miss of the linear fit {100 * miss:.1f}%")
        for r in rows:
            if float(r["paper_ms_per_step"]) > 0:
                paper[float(r["tri3"])] = float(r["paper_ms_per_step"])
    if paper:
        # The paper's own TRI3 counts differ from ours by under 1%: plot at ours.
        keys = sorted(paper)
        ax.plot(keys, [paper[k] for k in keys], "s--", color="gray", label="seed paper, Quadro GP100 (Table 2)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("TRI3")
    ax.set_ylabel("ms per step")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    if args.title:
        ax.set_title(args.title)
    fig.tight_layout()
    save(fig, args.output)


def open_run(path):
    """fdem.open(path), bad input as PlotError."""
    from . import output
    try:
        return output.open(path)
    except (FileNotFoundError, ValueError) as exc:
        raise PlotError(str(exc))


def default_output(run, args, what):
    return args.output or os.path.join(run.folder, f"{run.name}_{what}.png")


def mesh_outline(run):
    """Node pairs of the undeformed outline and the node coordinates, or None without
    an Exodus file."""
    if not run.has("frames"):
        return None
    try:
        exo = run.exodus
    except (OSError, KeyError, ValueError):
        return None
    return outline_edges(exo), exo.x, exo.y


def plot_events(args):
    """Breaks on the model coloured by time and by mode; magnitude-frequency of the
    events with the Gutenberg-Richter fit."""
    from . import analytics
    run = open_run(args.out)
    try:
        ev = run.events
    except (OSError, ValueError) as exc:
        raise PlotError(f"{run.files['events']}: cannot read it ({exc})")
    if ev is None:
        raise PlotError(f"{run.files['events']}: no such file (the run wrote no events: "
                        f"a case without fracture, or a build before the events file)")
    missing = [v for v in ("break_time", "break_x", "break_y") if v not in ev]
    if missing:
        raise PlotError(f"{run.files['events']}: not an events file (no "
                        f"{', '.join(missing)})")
    bx, by = ev["break_x"].values, ev["break_y"].values
    bt = ev["break_time"].values
    bmode = (np.nan_to_num(ev["break_mode"].values).round().astype(int)
             if "break_mode" in ev else np.zeros(len(bx), dtype=int))
    if args.breaks:
        # Each break alone, its magnitude by the engine's event rule.
        energy = ev["break_energy"].values if "break_energy" in ev else np.zeros(0)
        mags = analytics.magnitude_from_energy(energy)
        what = "breaks"
    else:
        mags = ev["event_magnitude"].values if "event_magnitude" in ev else np.zeros(0)
        what = "events"
    mags = mags[np.isfinite(mags)]

    fig, axes = plt.subplots(1, 3, figsize=(17, 5.2))
    outline = mesh_outline(run)
    last = float(np.nanmax(bt)) if len(bt) else 0.0
    time_unit, time_scale = ("µs", 1e6) if last < 1e-3 else ("ms", 1e3) if last < 1 else ("s", 1.0)
    for ax in axes[:2]:
        if outline is not None:
            draw_segments(ax, outline[1], outline[2], outline[0], colors="0.55", linewidths=0.6)
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
    if len(bx):
        sc = axes[0].scatter(bx, by, c=bt * time_scale, s=6, cmap="viridis")
        cax = make_axes_locatable(axes[0]).append_axes("right", size="4%", pad=0.1)
        fig.colorbar(sc, cax=cax, label=f"break time [{time_unit}]")
    axes[0].set_title(f"{len(bx)} breaks by time")
    handles = []
    known = [v for v, _, _ in MODES]
    for value, name, color in MODES + [(None, "mode not given", "0.6")]:
        chosen = np.isin(bmode, known, invert=True) if value is None else bmode == value
        if value is None and not chosen.any():
            continue
        axes[1].scatter(bx[chosen], by[chosen], s=6, color=color)
        handles.append(Line2D([], [], marker="o", ls="", color=color,
                              label=f"{name} ({int(chosen.sum())})"))
    axes[1].legend(handles=handles, loc="best", fontsize="small", title="failure mode")
    axes[1].set_title("breaks by failure mode")
    # The maps show where the breaks are (the outline, when there is one, for context);
    # without breaks, the whole outline.
    if len(bx):
        xs, ys = bx, by
    elif outline is not None and len(outline[0]):
        xs, ys = outline[1][outline[0].ravel()], outline[2][outline[0].ravel()]
    else:
        xs = ys = np.zeros(0)
    if len(xs):
        pad = 0.1 * max(np.ptp(xs), np.ptp(ys), 1e-12)
        for ax in axes[:2]:
            ax.set_xlim(xs.min() - pad, xs.max() + pad)
            ax.set_ylim(ys.min() - pad, ys.max() + pad)

    ax = axes[2]
    fit = None
    line = f"{len(mags)} {what}"
    if len(mags):
        edges, counts, cumulative = analytics.magnitude_frequency(mags, args.bin_width)
        ax.semilogy(edges, cumulative, "o", color="tab:blue", ms=4, label="N(≥ M)")
        ax.bar(edges + 0.5 * args.bin_width, counts, width=args.bin_width * 0.9,
               color="tab:gray", alpha=0.5, label=f"{what} per {args.bin_width:g} bin")
        fit = analytics.b_value(mags, mc=args.mc, dm=args.dm, bin_width=args.bin_width)
        if not fit.ok:  # too few events: the reason instead of a line
            line += f"; {fit.note}"
            fit = None
        if fit is not None:
            m = np.linspace(fit.mc, float(np.max(mags)), 50)
            ax.semilogy(m, fit.count_at_least(m), "-", color="tab:red",
                        label=f"b = {fit.b:.3g} ± {fit.b_error:.2g} (Mc = {fit.mc:.3g}, "
                              f"{fit.n} {what})")
            ax.axvline(fit.mc, color="tab:red", ls=":", lw=1)
            line += (f"; Gutenberg-Richter b = {fit.b:.4g} ± {fit.b_error:.2g} "
                     f"(Aki, Mc = {fit.mc:.4g}, dm = {fit.dm:g}, {fit.n} {what} at or above "
                     f"Mc), a = {fit.a:.4g}")
        ax.legend(loc="best", fontsize="small")
    else:
        ax.text(0.5, 0.5, f"no {what}", transform=ax.transAxes, ha="center")
    ax.set_xlabel("magnitude M" + (" of single breaks, 2/3 (log10 E - 4.8)" if args.breaks else ""))
    ax.set_ylabel(f"number of {what}")
    ax.grid(True, which="both", alpha=0.3)
    ax.set_title("magnitude-frequency")
    fig.suptitle(args.title or f"{run.name}: breaks and events")
    fig.tight_layout()
    output = default_output(run, args, "events")
    save(fig, output)
    print(f"{len(bx)} breaks (mode I {int((bmode == 1).sum())}, mode II "
          f"{int((bmode == 2).sum())}, mixed {int((bmode == 3).sum())}), {line}")
    print(f"wrote {output}")


def plot_fragments(args):
    """Cumulative mass passing against fragment size at one frame, with P50, P80 and the
    Rosin-Rammler and Swebrec fits; fragments and P50 over the frames beside it."""
    from . import analytics, fragments
    run = open_run(args.out)
    try:
        ds = run.fragments
    except (OSError, ValueError) as exc:
        raise PlotError(f"{run.files['fragments']}: cannot read it ({exc})")
    if ds is None:
        raise PlotError(f"{run.files['fragments']}: no such file (the run wrote no "
                        f"fragments: a case without fracture, or a build before the "
                        f"fragments file)")
    include = args.include_unfracturable
    try:
        records = fragments.at_frame(ds, args.frame)
        size, mass = fragments.sizes_and_masses(records, include)
        table = fragments.summary(ds, include_unfracturable=include)
    except ValueError as exc:
        raise PlotError(f"{run.files['fragments']}: {exc}")
    frame = int(fragments.frame_of_records(records)[0])
    t = float(records["fragment_time"].values[0]) if "fragment_time" in records else np.nan
    # Which pieces count: the platens and other non-fracturable bodies are no fragments.
    if not fragments.is_labelled(ds):
        print(f"fdem-plot: note: no {os.path.basename(run.files['frames'])} beside "
              f"{os.path.basename(run.files['fragments'])}: rock cannot be told from other "
              f"bodies (platens), every piece counts", file=sys.stderr)
        bodies = ""
    elif include:
        bodies = " (all bodies, non-fracturable ones included)"
    else:
        skipped = fragments.left_out(records)
        bodies = (f" of fracturable material ({', '.join(skipped)} left out: not "
                  f"fracturable; --include-unfracturable counts them)" if skipped else "")
    if len(size) == 0:
        raise PlotError(f"frame {frame} has no piece of a fracturable material "
                        f"(--include-unfracturable counts the others)")
    left_out = ""
    if args.without_largest:
        if len(size) < 2:
            raise PlotError(f"frame {frame} has {len(size)} fragment: nothing left without "
                            f"the largest")
        largest = int(np.argmax(mass))
        left_out = (f" (the largest, {size[largest]:.4g} m and "
                    f"{100 * mass[largest] / np.sum(mass):.3g}% of the mass, left out)")
        size, mass = np.delete(size, largest), np.delete(mass, largest)
        table = fragments.summary(ds, without_largest=True, include_unfracturable=include)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", analytics.FitWarning)
        dist = analytics.size_distribution(size, mass)
    for w in caught:
        print(f"fdem-plot: warning: {w.message}", file=sys.stderr)
    x, p = analytics.passing(size, mass)

    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(13, 5), gridspec_kw={"width_ratios": [3, 2]})
    ax.step(np.concatenate([[x[0]], x]), 100 * np.concatenate([[0.0], p]), where="post",
            color="k", lw=1.5, label=f"fragments ({dist.n})")
    grid = np.geomspace(max(x[0] * 0.5, x[-1] * 1e-3), x[-1] * 1.2, 200)
    notes = []
    if dist.rosin_rammler is not None:
        rr = dist.rosin_rammler
        ax.plot(grid, 100 * rr.cdf(grid), "--", color="tab:blue",
                label=f"Rosin-Rammler x_c = {rr.xc:.3g} m, n = {rr.n:.3g}")
        notes.append(f"Rosin-Rammler x_c = {rr.xc:.4g} m, n = {rr.n:.4g} (rms {rr.rms:.2g})")
    if dist.swebrec is not None:
        sw = dist.swebrec
        ax.plot(grid, 100 * sw.cdf(grid), "-.", color="tab:green",
                label=f"Swebrec x_max = {sw.xmax:.3g} m, x50 = {sw.x50:.3g} m, b = {sw.b:.3g}")
        notes.append(f"Swebrec x_max = {sw.xmax:.4g} m, x50 = {sw.x50:.4g} m, b = {sw.b:.4g} "
                     f"(rms {sw.rms:.2g}" + (f"; x_max on the {sw.bound} bound of its search"
                                             if sw.bound else "") + ")")
    if not notes:
        notes.append("no fit (fragments of one size)")
    for value, name, color in ((dist.p50, "P50", "tab:red"), (dist.p80, "P80", "tab:orange")):
        level = 50 if name == "P50" else 80
        ax.plot([grid[0], value, value], [level, level, 0], ":", color=color, lw=1.2,
                label=f"{name} = {value:.3g} m")
    ax.set_xscale("log")
    ax.set_ylim(0, 100)
    ax.set_xlim(grid[0], grid[-1])
    ax.set_xlabel("fragment size (equivalent diameter) [m]")
    ax.set_ylabel("mass passing [%]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="upper left", fontsize="small")
    ax.set_title(f"frame {frame}, t = {t:.4g} s" +
                 (": without the largest piece" if args.without_largest else ""))

    times = table["time"].values
    scale, unit = (1e6, "µs") if np.nanmax(np.abs(times), initial=0) < 1e-3 else \
        (1e3, "ms") if np.nanmax(np.abs(times), initial=0) < 1 else (1, "s")
    times = times * scale
    ax2.plot(times, table["fragments"].values, "o-", color="k", ms=3)
    ax2.set_xlabel(f"time [{unit}]")
    ax2.set_ylabel("fragments")
    ax2.grid(True, alpha=0.3)
    ax3 = ax2.twinx()
    ax3.plot(times, table["p50"].values, "s--", color="tab:red", ms=3, label="P50")
    ax3.plot(times, table["p80"].values, "^--", color="tab:orange", ms=3, label="P80")
    ax3.set_ylabel("size [m]")
    ax3.legend(loc="upper right", fontsize="small")
    ax2.set_title("over the frames")
    fig.suptitle(args.title or f"{run.name}: fragment sizes")
    fig.tight_layout()
    output = default_output(run, args, f"fragments_frame{frame}" if args.frame != -1
                            else "fragments")
    save(fig, output)
    print(f"frame {frame}, t = {t:.6g} s: {dist.n} fragments{bodies}{left_out}, P50 = {dist.p50:.6g} m, "
          f"P80 = {dist.p80:.6g} m; {'; '.join(notes)}")
    print(f"wrote {output}")


def save(fig, output):
    figures.save(fig, output, PlotError)


def parse_args(argv):
    parser = argparse.ArgumentParser(prog="fdem-plot", description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)

    field = sub.add_parser("field", help="element variable on the (deformed) mesh")
    field.add_argument("file", help="Exodus file (.exo) written by fdem-cl")
    field.add_argument("--var", required=True, help="element variable, e.g. SXX")
    field.add_argument("--frame", type=int, default=-1,
                       help="frame index, negative counts from the end (default -1)")
    field.add_argument("--time", type=float, default=None,
                       help="plot the frame nearest to this time [s] (overrides --frame)")
    several = field.add_mutually_exclusive_group()
    several.add_argument("--frames", type=int, nargs="+", metavar="N",
                         help="several frames side by side in one image, one color scale "
                              "(overrides --frame/--time)")
    several.add_argument("--times", type=float, nargs="+", metavar="T",
                         help="the frames nearest to these times [s], side by side "
                              "(overrides --frame/--time)")
    field.add_argument("--cracks", action="store_true",
                       help="draw the broken CE4s (BROKEN = 1 in the 'cohesive' block) "
                            "as black lines")
    field.add_argument("--deformed-scale", type=float, default=None,
                       help="displacement magnification (default 1; 0 = undeformed)")
    field.add_argument("--cmap", default="viridis", help="matplotlib colormap")
    field.add_argument("--range", type=float, nargs=2, metavar=("LO", "HI"),
                       help="color range in the units shown (MPa for stresses)")
    field.add_argument("-o", "--output", required=True, help="image file to write")
    field.set_defaults(run=plot_field)

    history = sub.add_parser("history", help="history variables against time")
    history.add_argument("file", help="history file (_history.nc) written by fdem-cl")
    history.add_argument("vars", nargs="+", metavar="VAR", help="variables to plot")
    history.add_argument("--log", action="store_true", help="logarithmic y axis")
    history.add_argument("-o", "--output", required=True, help="image file to write")
    history.set_defaults(run=plot_history)

    curve = sub.add_parser("stress-strain",
                           help="Brazilian / UCS stress against axial strain from the "
                                "platen force and displacements")
    curve.add_argument("file", help="history file (_history.nc) written by fdem-cl")
    curve.add_argument("--test", required=True, choices=sorted(TESTS),
                       help="brazilian: 2F/(pi D t); ucs: F/(W t)")
    curve.add_argument("--load-region", required=True,
                       help="region with the prescribed motion whose force F = "
                            "|REGION_force_y| loads the specimen, e.g. platen_top")
    curve.add_argument("--support-region", default=None,
                       help="the opposite platen; strain = |disp_y(load) - disp_y(support)| "
                            "/ size (left out: a fixed support, |disp_y(load)| / size)")
    curve.add_argument("--size", type=float, required=True,
                       help="disc diameter D (brazilian) or specimen height H (ucs) [m]")
    curve.add_argument("--thickness", type=float, required=True,
                       help="out-of-plane thickness t of the model (mesh.thickness) [m]")
    curve.add_argument("--width", type=float, default=None,
                       help="specimen width W [m] (ucs only)")
    curve.add_argument("--mark-times", type=float, nargs="+", metavar="T",
                       help="mark the points nearest to these times [s] as A, B, C...")
    curve.add_argument("--title", default="", help="plot title")
    curve.add_argument("--csv", default=None,
                       help="also write time, displacement, strain, force, stress as CSV")
    curve.add_argument("-o", "--output", required=True, help="image file to write")
    curve.set_defaults(run=plot_stress_strain)

    cracks = sub.add_parser("cracks", help="mesh outline and broken CE4s by failure mode")
    cracks.add_argument("file", help="Exodus file (.exo) written by fdem-cl")
    which = cracks.add_mutually_exclusive_group()
    which.add_argument("--frame", type=int, default=-1,
                       help="frame index, negative counts from the end (default -1)")
    which.add_argument("--time", type=float, default=None,
                       help="the frame nearest to this time [s]")
    cracks.add_argument("--deformed-scale", type=float, default=None,
                        help="displacement magnification (default 1; 0 = undeformed)")
    cracks.add_argument("--rose", action="store_true",
                        help="crack-orientation roses instead of the map: the mesh's CE4s, "
                             "all broken CE4s and each mode (reference directions)")
    cracks.add_argument("--events", default=None, metavar="EVENTS.nc",
                        help="with --rose: the broken CE4s and their modes from this break "
                             "catalogue (breaks up to the frame's time) instead of the frame; "
                             "FILE then only gives the mesh (any frame of the same mesh)")
    cracks.add_argument("--bins", type=int, default=12, help="rose bins over 180 degrees (12)")
    cracks.add_argument("--title", default="", help="plot title (--rose)")
    cracks.add_argument("-o", "--output", required=True, help="image file to write")
    cracks.set_defaults(run=plot_cracks)

    rose = sub.add_parser("mesh-rose", help="edge-orientation roses of the fracturable "
                                            "regions' CE4s of one or more meshes")
    rose.add_argument("files", nargs="+", metavar="EXO[:LABEL]",
                      help="Exodus files (any frame; a run with time.steps = 1 will do)")
    rose.add_argument("--bins", type=int, default=12, help="bins over 180 degrees (12)")
    rose.add_argument("--title", default="", help="plot title")
    rose.add_argument("-o", "--output", required=True, help="image file to write")
    rose.set_defaults(run=plot_mesh_rose)

    compare = sub.add_parser("compare", help="one history variable from several runs")
    compare.add_argument("var", help="history variable, e.g. kinetic_energy")
    compare.add_argument("runs", nargs="+", metavar="FILE[:LABEL]", help="history files, each with an optional label")
    compare.add_argument("--normalize", action="store_true", help="divide each curve by its first value")
    compare.add_argument("--ms", dest="time_scale", action="store_const", const=1e3, default=1.0,
                         help="time axis in milliseconds")
    compare.add_argument("--title", default="", help="plot title")
    compare.add_argument("-o", "--output", required=True, help="image file to write")
    compare.set_defaults(run=plot_compare)

    bench = sub.add_parser("bench", help="ms per step against TRI3 from `fdem bench --csv` files")
    bench.add_argument("csv", nargs="+", metavar="FILE[:LABEL]", help="bench CSV files, each with an optional label")
    bench.add_argument("--title", default="", help="plot title")
    bench.add_argument("-o", "--output", required=True, help="image file to write")
    bench.set_defaults(run=plot_bench)

    events = sub.add_parser("events", help="breaks by time and mode; magnitude-frequency "
                                           "with the Gutenberg-Richter b-value")
    events.add_argument("out", metavar="OUT",
                        help="output folder (or OUT/NAME, or one of the run's files)")
    events.add_argument("--mc", type=float, default=None,
                        help="magnitude of completeness (default: maximum curvature)")
    events.add_argument("--dm", type=float, default=0.0,
                        help="bin width the magnitudes are rounded to (0: continuous, default)")
    events.add_argument("--bin-width", type=float, default=0.1,
                        help="magnitude bins of the plot and of the maximum curvature (0.1)")
    events.add_argument("--breaks", action="store_true",
                        help="magnitude-frequency of the single breaks (magnitude of each "
                             "break's break_energy by the events' rule) instead of the events")
    events.add_argument("--title", default="", help="plot title")
    events.add_argument("-o", "--output", default=None,
                        help="image file to write (default OUT/NAME_events.png)")
    events.set_defaults(run=plot_events)

    frag = sub.add_parser("fragments", help="fragment size distribution (mass passing) "
                                            "with P50, P80 and the fits")
    frag.add_argument("out", metavar="OUT",
                      help="output folder (or OUT/NAME, or one of the run's files)")
    frag.add_argument("--frame", type=int, default=-1,
                      help="frame index, negative counts from the end (default -1)")
    frag.add_argument("--without-largest", action="store_true",
                      help="leave the largest piece (by mass) out of each frame: the "
                           "body the fragments broke off")
    frag.add_argument("--include-unfracturable", action="store_true",
                      help="count the pieces of non-fracturable materials (platens, "
                           "blocks) too; by default only the rock's pieces count")
    frag.add_argument("--title", default="", help="plot title")
    frag.add_argument("-o", "--output", default=None,
                      help="image file to write (default OUT/NAME_fragments.png, "
                           "OUT/NAME_fragments_frameK.png with --frame)")
    frag.set_defaults(run=plot_fragments)

    args = parser.parse_args(argv)
    if getattr(args, "cmap", None) is not None and args.cmap not in plt.colormaps():
        parser.error(f"unknown colormap {args.cmap!r}")
    if getattr(args, "range", None) is not None and not args.range[0] < args.range[1]:
        parser.error("--range needs LO < HI")
    if args.command == "events":
        if not args.bin_width > 0:
            parser.error(f"--bin-width must be > 0 (got {args.bin_width:g})")
        if args.dm < 0:
            parser.error(f"--dm must be >= 0 (got {args.dm:g})")
    if getattr(args, "bins", None) is not None and not 1 <= args.bins <= 360:
        parser.error(f"--bins must be 1 to 360 (got {args.bins})")
    if args.command == "stress-strain":
        for key in ("size", "thickness") + (("width",) if args.test == "ucs" else ()):
            value = getattr(args, key)
            if value is None:
                parser.error(f"--test {args.test} needs --{key}")
            if not value > 0:
                parser.error(f"--{key} must be > 0 (got {value:g})")
        if args.test == "brazilian" and args.width is not None:
            print("fdem-plot: note: --width is not used by --test brazilian", file=sys.stderr)
    return args


def main(argv=None):
    args = parse_args(argv)
    try:
        args.run(args)
    except PlotError as exc:
        print(f"fdem-plot: error: {exc}", file=sys.stderr)
        return 2
    return 0

