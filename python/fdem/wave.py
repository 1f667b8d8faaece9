"""Stress-wave diagnostics of fdem-cl output: arrival times, apparent P-wave speed and
reflected amplitudes.

  fdem-wave arrival FILE --centre X Y [--radii R ...] [--angles DEG ...] [--point X Y]...
            [--probes NAME ...] [--var PS1] [--level 0.5] [--threshold 1e-3]
            [--snr 10] [--min-amplitude A] [--until T] [--csv F] [--png F]
  fdem-wave reflection FILE (--probe NAME | --point X Y) (--split T | --boundary-distance D
            --speed V) [--var PS1] [--level 0.5] [--until T] [--csv F] [--png F]

FILE is an Exodus file (.exo: the element variable at each frame of the element that
contains each point) or a history file (_history.nc: the [[probe]] variables, written
every history row, so with a much finer time resolution than frames).

Arrival of the first compressive front at a point: with s(t) the variable there and
d(t) = s(t0) - s(t) its compressive change since the first sample (tension is positive),
A = max d over the samples up to --until (default: all) is the peak compressive
amplitude, and the arrival time is the first time d reaches --level x A (default one
half), interpolated linearly between the two samples around the crossing. The first
sample must precede the wave. A point has a front only when A is at least --threshold
(default 1e-3) times the signal's peak, the largest compressive change of the variable
anywhere in the file over the whole record, --until aside (Exodus: over every TRI3
element; history: over every probe), and at least --min-amplitude (default 0, in the
variable's units): the dispersive precursor and round-off ahead of a front that has
not arrived yet (tens of Pa against MPa) are no front. For the same reason A must be
at least a tenth of the point's own largest compressive change over the whole record:
a window (--until) that ends before the front holds only its precursor. Nor is noise: A must also be at
least --snr (default 10) times the record's noise, sigma = median |s(i+1) - s(i)| / 0.954
(the standard deviation of white noise; a front's few steep samples do not move the
median). A point without a front is listed as "no front" and left
out of the fit; when no point has one the command stops with "no front found" and
exit 2. The apparent speed V is the least-squares fit of radius = V t + c over the
points with a front (radius: distance from --centre).

Reflection at a point near a boundary: the samples are split at --split T, or at
arrival + D/V given the distance D from the point to the boundary and the wave speed V
(the reflected front then arrives D/V after the split). The incident amplitude is the
extreme change of s from its first sample before the split, the reflected amplitude the
extreme change of s after the split from its mean over the last quarter of the time
between arrival and split (the plateau behind a step front, the tail of a pulse); their
ratio is about -1 at a free boundary, +1 at a fixed one and 0 at a perfectly absorbing
one.

Exit codes: 0 success, 2 bad input (missing file or variable, point outside the mesh,
no front found).
"""

import argparse
import os
import sys

import numpy as np  # noqa: E402

import netCDF4  # noqa: E402

from . import figures  # noqa: E402
from . import load as fdem_load  # noqa: E402

COHESIVE_BLOCK = "cohesive"


class WaveError(Exception):
    """Bad input from the user: reported in one line, exit code 2."""


# ---------------------------------------------------------------------------------------
# Series at points: (label, x, y, times, values, where) per point.

class Series:
    """A variable over time at one point. `peak_change` (over `times`) is the largest
    compressive change from the first sample of the same variable anywhere in the file
    at each sample (`peak_where` says over what): the signal the point's front is
    measured against."""

    def __init__(self, label, x, y, times, values, where, peak_change=None, peak_where=""):
        self.label, self.x, self.y = label, float(x), float(y)
        self.times, self.values, self.where = times, values, where
        self.peak_change = (np.maximum(values[0] - values, 0.0) if peak_change is None
                            else peak_change)
        self.peak_where = peak_where or "this point"


class NoFront(WaveError):
    """No compressive front at a point (a point of several is skipped; none is an error)."""


def largest_compression(values):
    """(samples,) largest compressive change from the first sample over the columns of
    a (samples, columns) array."""
    if values.size == 0:
        return np.zeros(values.shape[0])
    return np.max(np.maximum(values[:1] - values, 0.0), axis=1)


def file_kind(path):
    """'exodus' or 'history', from the variables the file holds."""
    if not os.path.exists(path):
        raise WaveError(f"{path}: no such file")
    try:
        with netCDF4.Dataset(path, "r") as ds:
            names = set(ds.variables)
    except OSError as exc:
        raise WaveError(f"{path}: cannot read it as netCDF ({exc})")
    if "coordx" in names:
        return "exodus"
    if "time" in names:
        return "history"
    raise WaveError(f"{path}: neither an Exodus file (no coordx) nor an fdem-cl history "
                    f"file (no time)")


def triangle_elements(exo):
    """Corner nodes (k, 3) of every TRI3 element and its index in the block-concatenated
    element order (the order of ExodusData.element_values)."""
    conn, index, first = [], [], 0
    for blk in exo.blocks:
        if blk.name.lower() != COHESIVE_BLOCK and blk.elem_type.startswith("TRI") \
                and blk.connectivity.shape[1] >= 3:
            conn.append(blk.connectivity[:, :3])
            index.append(np.arange(first, first + blk.num_elem))
        first += blk.num_elem
    if not conn:
        raise WaveError(f"{exo.path} has no TRI3 element block")
    return np.concatenate(conn), np.concatenate(index)


def containing_element(exo, tris, index, x, y):
    """Element index (concatenated order) of the triangle containing (x, y) in the
    reference configuration (the lowest one on a shared edge), or None."""
    ax, ay = exo.x[tris[:, 0]], exo.y[tris[:, 0]]
    bx, by = exo.x[tris[:, 1]], exo.y[tris[:, 1]]
    cx, cy = exo.x[tris[:, 2]], exo.y[tris[:, 2]]
    area2 = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    tol = -1e-9 * np.abs(area2)
    w0 = (bx - x) * (cy - y) - (by - y) * (cx - x)
    w1 = (cx - x) * (ay - y) - (cy - y) * (ax - x)
    w2 = (ax - x) * (by - y) - (ay - y) * (bx - x)
    sign = np.sign(area2)
    inside = (w0 * sign >= tol) & (w1 * sign >= tol) & (w2 * sign >= tol)
    hits = np.nonzero(inside)[0]
    return int(index[hits[0]]) if len(hits) else None


def exodus_series(path, var, points):
    """The element variable `var` over the frames at each (label, x, y) point; points
    outside the mesh are reported and skipped."""
    try:
        exo = fdem_load.load_exodus(path)
    except (OSError, KeyError, ValueError) as exc:
        raise WaveError(f"{path}: cannot read it as fdem-cl output ({exc})")
    name = var.upper()
    if name not in exo.element:
        raise WaveError(f"no element variable {name!r} in {path}; available: "
                        f"{', '.join(exo.element) or 'none'}")
    if exo.num_frames < 2:
        raise WaveError(f"{path} has {exo.num_frames} frame(s): a time series needs at least 2")
    tris, index = triangle_elements(exo)
    values = np.concatenate(exo.element[name], axis=1)  # (frames, elements)
    peak = largest_compression(values[:, index])
    peak_where = f"{name} over the {len(index)} TRI3 elements"
    out = []
    for label, x, y in points:
        e = containing_element(exo, tris, index, x, y)
        if e is None:
            print(f"fdem-wave: note: point {label} ({x:g}, {y:g}) is outside the mesh; skipped",
                  file=sys.stderr)
            continue
        out.append(Series(label, x, y, exo.times, values[:, e], f"element {e + 1}", peak,
                          peak_where))
    if not out:
        raise WaveError(f"none of the points lies in the mesh of {path}")
    return out


def history_probes(path, var, names=None):
    """The [[probe]] variable <name>_<var> of each probe in a history file."""
    try:
        hist = fdem_load.load_history(path)
    except (OSError, KeyError, ValueError) as exc:
        raise WaveError(f"{path}: cannot read it as an fdem-cl history file ({exc})")
    suffix = "_" + var.lower()
    found = {}
    for vname, attrs in hist.attributes.items():
        if vname.endswith(suffix) and "probe_point" in attrs:
            element = attrs["probe_element"][0] if "probe_element" in attrs else None
            found[vname[:-len(suffix)]] = (attrs["probe_point"], element)
    if not found:
        probe_vars = sorted(n for n in hist.values if n.endswith("_ps1"))
        hint = (f"; probes there: {', '.join(p[:-4] for p in probe_vars)}" if probe_vars else
                " (the case has no [[probe]] entries)")
        raise WaveError(f"no probe variable '*{suffix}' in {path}{hint}")
    if names:
        missing = [n for n in names if n not in found]
        if missing:
            raise WaveError(f"no probe {', '.join(map(repr, missing))} with '{suffix}' in {path}; "
                            f"probes: {', '.join(sorted(found))}")
        chosen = list(names)
    else:
        chosen = sorted(found, key=lambda n: list(hist.values).index(n + suffix))
    if len(hist.times) < 2:
        raise WaveError(f"{path} has {len(hist.times)} row(s): a time series needs at least 2")
    peak = largest_compression(np.column_stack([hist.values[n + suffix] for n in found]))
    peak_where = f"*{suffix} over the {len(found)} probes"
    out = []
    for n in chosen:
        point, element = found[n]
        where = f"element {int(element)}" if element is not None else "probe"
        out.append(Series(n, point[0], point[1], hist.times, hist.values[n + suffix], where,
                          peak, peak_where))
    return out


# ---------------------------------------------------------------------------------------
# Arrival and reflection.

def window(series, until):
    keep = series.times <= until if until is not None else np.ones(len(series.times), bool)
    if keep.sum() < 2:
        raise WaveError(f"{series.label}: fewer than 2 samples up to --until {until:g} s")
    return series.times[keep], series.values[keep]


def crossing_time(t, d, level):
    """First time the increasing crossing of `level` by d happens (linear between
    samples), or None."""
    above = np.nonzero(d >= level)[0]
    if len(above) == 0:
        return None
    i = int(above[0])
    if i == 0:
        return float(t[0])
    return float(t[i - 1] + (level - d[i - 1]) / (d[i] - d[i - 1]) * (t[i] - t[i - 1]))


def noise_level(values):
    """Standard deviation of the record's noise from its sample-to-sample changes: the
    median |change| is 0.954 sigma for white noise (the median of |N(0, 2 sigma^2)|)."""
    if len(values) < 2:
        return 0.0
    return float(np.median(np.abs(np.diff(values)))) / 0.954


def arrival(series, level, until, threshold=1e-3, min_amplitude=0.0, snr=10.0):
    """(arrival time, peak compressive amplitude A, time of A) of the first compressive
    front; raises NoFront when there is none (module docstring: A below --threshold
    times the signal's peak or below --min-amplitude)."""
    t, s = window(series, until)
    d = s[0] - s  # compressive change, positive
    k = int(np.argmax(d))
    amplitude = float(d[k])
    where = f"{series.label} ({series.where})"
    if not amplitude > 0:
        raise NoFront(f"{where}: no compressive change after the first sample")
    # Round-off before the wave arrives is not a front: a change below 0.1% of the
    # largest change of the whole record (--until aside) counts as noise.
    if not amplitude > 1e-3 * float(np.max(np.abs(series.values - series.values[0]))):
        raise NoFront(f"{where}: peak compressive change {amplitude:.3g} is round-off against "
                      f"the record's largest change")
    # The whole record, --until aside: a window that ends before the front holds only
    # its precursor, whose peak is no measure of the signal.
    own = float(np.max(series.values[0] - series.values))
    if until is not None and amplitude < 0.1 * own:
        raise NoFront(f"{where}: peak compressive change {amplitude:.3g} up to --until {until:g} s "
                      f"is below a tenth of the point's own peak {own:.4g} later in the record: "
                      f"the front arrives after --until")
    signal = float(np.max(series.peak_change))
    if amplitude < threshold * signal:
        raise NoFront(f"{where}: peak compressive change {amplitude:.3g} is below --threshold "
                      f"{threshold:g} x the signal's peak {signal:.4g} ({series.peak_where})")
    noise = noise_level(s)
    if amplitude < snr * noise:
        raise NoFront(f"{where}: peak compressive change {amplitude:.3g} is below --snr {snr:g} "
                      f"x the record's noise {noise:.3g} (median sample-to-sample change "
                      f"/ 0.954): noise, not a front")
    if amplitude < min_amplitude:
        raise NoFront(f"{where}: peak compressive change {amplitude:.3g} is below "
                      f"--min-amplitude {min_amplitude:g}")
    return crossing_time(t, d, level * amplitude), amplitude, float(t[k])


def fit_speed(radii, times):
    """Least squares radius = V t + c: (V, c, rms residual [m])."""
    A = np.column_stack([times, np.ones_like(times)])
    (v, c), *_ = np.linalg.lstsq(A, radii, rcond=None)
    residual = radii - (v * times + c)
    return float(v), float(c), float(np.sqrt(np.mean(residual ** 2)))


def arrival_points(args):
    """(label, x, y) of the points of the `arrival` command for an Exodus file."""
    points = []
    if args.radii:
        for angle in args.angles:
            a = np.radians(angle)
            for r in args.radii:
                label = f"r={r:g}" + (f",a={angle:g}" if len(args.angles) > 1 else "")
                points.append((label, args.centre[0] + r * np.cos(a), args.centre[1] + r * np.sin(a)))
    for k, (x, y) in enumerate(args.point or []):
        points.append((f"p{k}", x, y))
    if not points:
        raise WaveError("an Exodus file needs points: --radii (with --centre, --angles) or --point X Y")
    return points


def load_series(args, points=None):
    kind = file_kind(args.file)
    if kind == "exodus":
        if args.probes:
            raise WaveError("--probes selects probes of a history file; with an Exodus file give "
                            "--radii or --point")
        return kind, exodus_series(args.file, args.var, points if points is not None
                                   else arrival_points(args))
    if getattr(args, "radii", None) or args.point:
        raise WaveError("a history file holds its [[probe]] points: select them with --probes "
                        "(--radii and --point are for Exodus files)")
    return kind, history_probes(args.file, args.var, args.probes)


def command_arrival(args):
    kind, series = load_series(args)
    cx, cy = args.centre
    rows, missed = [], []
    for s in series:
        try:
            t_arr, amplitude, t_peak = arrival(s, args.level, args.until, args.threshold,
                                               args.min_amplitude, args.snr)
        except NoFront as exc:
            missed.append((s, exc))
            continue
        rows.append((s, float(np.hypot(s.x - cx, s.y - cy)), t_arr, amplitude, t_peak))
    if not rows:
        raise WaveError(f"no front found: none of the {len(series)} points has a compressive "
                        f"front (" + "; ".join(str(e) for _, e in missed[:3]) +
                        ("; ..." if len(missed) > 3 else "") + ")")
    for s, exc in missed:
        print(f"fdem-wave: note: no front at {exc}; left out", file=sys.stderr)

    print(f"first compressive front of {args.var.upper() if kind == 'exodus' else '*_' + args.var.lower()} "
          f"in {args.file} ({kind}, {len(series[0].times)} samples): arrival = first time the "
          f"compressive change reaches {args.level:g} x its peak")
    print(f"{'point':>14} {'x [m]':>10} {'y [m]':>10} {'radius [m]':>11} {'where':>14} "
          f"{'arrival [s]':>13} {'peak [Pa]':>12} {'at [s]':>11}")
    for s, r, t_arr, amplitude, t_peak in rows:
        print(f"{s.label:>14} {s.x:10.5g} {s.y:10.5g} {r:11.5g} {s.where:>14} {t_arr:13.6g} "
              f"{-amplitude:12.5g} {t_peak:11.5g}")
    for s, _ in missed:
        r = float(np.hypot(s.x - cx, s.y - cy))
        print(f"{s.label:>14} {s.x:10.5g} {s.y:10.5g} {r:11.5g} {s.where:>14} {'no front':>13}")
    radii = np.array([r[1] for r in rows])
    times = np.array([r[2] for r in rows])
    fit = None
    if len(rows) >= 2 and np.ptp(times) > 0:
        fit = fit_speed(radii, times)
        v, c, rms = fit
        print(f"apparent P-wave speed V = {v:.6g} m/s (least squares radius = V t + c over "
              f"{len(rows)} points: c = {c:.5g} m, rms residual {rms:.3g} m)")
    else:
        print("apparent P-wave speed: needs at least two points with a front and different "
              "arrival times")

    if args.csv:
        write_csv(args.csv, "point,x_m,y_m,radius_m,where,arrival_s,peak_compression_Pa,peak_time_s",
                  [(s.label, s.x, s.y, r, s.where, t_arr, -a, tp) for s, r, t_arr, a, tp in rows])
    if args.png:
        plot_arrival(args, rows, fit)
    return 0


def command_reflection(args):
    if args.point:
        kind = file_kind(args.file)
        if kind != "exodus":
            raise WaveError("--point is for Exodus files; in a history file name a --probe")
        series = exodus_series(args.file, args.var, [("point", args.point[0][0], args.point[0][1])])[0]
    else:
        kind = file_kind(args.file)
        if kind != "history":
            raise WaveError("--probe names a [[probe]] of a history file; in an Exodus file give --point X Y")
        series = history_probes(args.file, args.var, [args.probe])[0]
    t_arr, _, _ = arrival(series, args.level, args.until, args.threshold, args.min_amplitude,
                          args.snr)
    split = args.split if args.split is not None else t_arr + args.boundary_distance / args.speed
    t, s = window(series, args.until)
    before = t < split
    if before.sum() < 2 or (~before).sum() < 2:
        raise WaveError(f"the split at {split:g} s leaves fewer than 2 samples on one side "
                        f"(samples {t[0]:g} to {t[-1]:g} s)")
    change_in = s[before] - s[0]
    incident = float(change_in[np.argmax(np.abs(change_in))])
    # The level the reflected wave starts from: the mean over the last quarter of the
    # time from arrival to split, so the ringing behind a step front averages out (for a
    # short pulse that stretch is its tail, back at the initial level).
    settle = (t >= split - 0.25 * max(split - t_arr, 0.0)) & before
    at_split = float(np.mean(s[settle])) if settle.any() else float(np.interp(split, t, s))
    change_out = s[~before] - at_split
    reflected = float(change_out[np.argmax(np.abs(change_out))])
    if incident == 0:
        raise WaveError(f"{series.label}: no incident wave before the split at {split:g} s")
    ratio = reflected / incident
    name = args.var.upper() if kind == "exodus" else f"{series.label}_{args.var.lower()}"
    print(f"reflection of {name} at {series.label} ({series.x:g}, {series.y:g}; {series.where}) "
          f"in {args.file}")
    print(f"  arrival of the incident front  {t_arr:.6g} s")
    print(f"  split (incident | reflected)   {split:.6g} s")
    print(f"  incident amplitude             {incident:.6g} Pa")
    print(f"  reflected amplitude            {reflected:.6g} Pa")
    print(f"  reflected / incident           {ratio:.4f}")
    if args.csv:
        write_csv(args.csv, "point,x_m,y_m,arrival_s,split_s,incident_Pa,reflected_Pa,ratio",
                  [(series.label, series.x, series.y, t_arr, split, incident, reflected, ratio)])
    if args.png:
        plot_reflection(args, series, name, t_arr, split, incident, reflected, at_split)
    return 0


# ---------------------------------------------------------------------------------------
# Output files.

def write_csv(path, header, rows):
    try:
        with open(path, "w") as out:
            out.write(header + "\n")
            for row in rows:
                out.write(",".join(v if isinstance(v, str) else f"{v:.17g}" for v in row) + "\n")
    except OSError as exc:
        raise WaveError(f"cannot write {path}: {exc.strerror or exc}")


def pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def plot_arrival(args, rows, fit):
    plt = pyplot()
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.8))
    for s, r, t_arr, amplitude, _ in rows:
        line, = left.plot(s.times * 1e3, s.values / 1e6, lw=1.0, label=f"{s.label} (r = {r:.3g} m)")
        level = s.values[0] - args.level * amplitude
        left.plot([t_arr * 1e3], [level / 1e6], "o", color=line.get_color(), ms=5)
    left.set_xlabel("time [ms]")
    left.set_ylabel(f"{args.var} [MPa]")
    left.set_title(f"dots: arrival ({args.level:g} x peak compressive change)", fontsize="medium")
    left.grid(True, alpha=0.3)
    left.legend(fontsize="x-small", loc="best")
    times = np.array([r[2] for r in rows])
    radii = np.array([r[1] for r in rows])
    right.plot(times * 1e3, radii, "o", label="arrivals")
    if fit is not None:
        v, c, rms = fit
        tt = np.linspace(times.min(), times.max(), 2)
        right.plot(tt * 1e3, v * tt + c, "-", label=f"V = {v:.5g} m/s (rms {rms:.2g} m)")
    right.set_xlabel("arrival time [ms]")
    right.set_ylabel("radius [m]")
    right.grid(True, alpha=0.3)
    right.legend(fontsize="small", loc="best")
    fig.suptitle(os.path.basename(args.file))
    fig.tight_layout()
    figures.save(fig, args.png, WaveError)


def plot_reflection(args, series, name, t_arr, split, incident, reflected, at_split):
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8, 4.5))
    ax.plot(series.times * 1e3, series.values / 1e6, lw=1.2, label=name)
    ax.axvline(t_arr * 1e3, color="0.5", ls=":", label=f"arrival {t_arr:.4g} s")
    ax.axvline(split * 1e3, color="k", ls="--", label=f"split {split:.4g} s")
    ax.axhline((series.values[0] + incident) / 1e6, color="tab:red", lw=0.8,
               label=f"incident {incident / 1e6:.4g} MPa")
    ax.axhline((at_split + reflected) / 1e6, color="tab:green", lw=0.8,
               label=f"reflected {reflected / 1e6:.4g} MPa (ratio {reflected / incident:.3f})")
    ax.set_xlabel("time [ms]")
    ax.set_ylabel(f"{name} [MPa]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small", loc="best")
    fig.tight_layout()
    figures.save(fig, args.png, WaveError)


# ---------------------------------------------------------------------------------------

def parse_args(argv):
    paragraphs = __doc__.split("\n\n")
    raw = argparse.RawDescriptionHelpFormatter
    parser = argparse.ArgumentParser(prog="fdem-wave", description="\n\n".join(paragraphs[:3]),
                                     epilog=paragraphs[-1], formatter_class=raw)
    sub = parser.add_subparsers(dest="command", required=True)

    def common(p):
        p.add_argument("file", help="Exodus file (.exo) or history file (_history.nc) of fdem-cl")
        p.add_argument("--var", default="PS1",
                       help="element variable of an Exodus file (PS1, SXX, ...) or probe "
                            "quantity of a history file (ps1, sxx, syy, sxy, vx, vy); default PS1")
        p.add_argument("--level", type=float, default=0.5,
                       help="fraction of the peak compressive change that marks the arrival "
                            "(default 0.5)")
        p.add_argument("--threshold", type=float, default=1e-3,
                       help="a front's peak compressive change must be at least this fraction "
                            "of the signal's peak, the largest anywhere in the file "
                            "(default 1e-3)")
        p.add_argument("--min-amplitude", type=float, default=0.0,
                       help="a front's peak compressive change must be at least this, in the "
                            "variable's units (default 0)")
        p.add_argument("--snr", type=float, default=10.0,
                       help="a front's peak compressive change must be at least this many "
                            "times the record's noise (default 10)")
        p.add_argument("--until", type=float, default=None,
                       help="use samples up to this time [s] only (leave out reflections)")
        p.add_argument("--csv", default=None, help="also write the table as CSV")
        p.add_argument("--png", default=None, help="also plot to this image file")

    arr = sub.add_parser("arrival", help="arrival times of the first compressive front and the "
                                         "apparent P-wave speed",
                         description=paragraphs[2] + "\n\n" + paragraphs[3], formatter_class=raw)
    common(arr)
    arr.add_argument("--centre", "--center", type=float, nargs=2, metavar=("X", "Y"),
                     default=None, help="source centre [m]: radii are measured from it (required)")
    arr.add_argument("--radii", type=float, nargs="+", metavar="R",
                     help="radii [m] of points on radial lines from --centre (Exodus file)")
    arr.add_argument("--angles", type=float, nargs="+", metavar="DEG",
                     default=[0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0],
                     help="directions of the radial lines [deg, counter-clockwise from x] "
                          "(default every 45; points outside the mesh are skipped)")
    arr.add_argument("--point", type=float, nargs=2, action="append", metavar=("X", "Y"),
                     help="an explicit point [m] (Exodus file; repeat for more)")
    arr.add_argument("--probes", nargs="+", metavar="NAME",
                     help="[[probe]] names to use from a history file (default: all)")
    arr.set_defaults(run=command_arrival)

    ref = sub.add_parser("reflection", help="reflected over incident amplitude at a point near "
                                            "a boundary",
                         description=paragraphs[2] + "\n\n" + paragraphs[4], formatter_class=raw)
    common(ref)
    where = ref.add_mutually_exclusive_group(required=True)
    where.add_argument("--probe", help="[[probe]] name in a history file")
    where.add_argument("--point", type=float, nargs=2, action="append", metavar=("X", "Y"),
                       help="a point [m] in an Exodus file")
    ref.add_argument("--split", type=float, default=None,
                     help="time [s] separating the incident from the reflected wave")
    ref.add_argument("--boundary-distance", type=float, default=None,
                     help="distance D [m] from the point to the reflecting boundary "
                          "(split = arrival + D/V)")
    ref.add_argument("--speed", type=float, default=None, help="wave speed V [m/s] for the split")
    ref.set_defaults(run=command_reflection, probes=None)

    args = parser.parse_args(argv)
    if not 0 < args.level < 1:
        parser.error(f"--level must be between 0 and 1 (got {args.level:g})")
    if not 0 <= args.threshold < 1:
        parser.error(f"--threshold must be in [0, 1) (got {args.threshold:g})")
    if not args.snr >= 0:
        parser.error(f"--snr must be >= 0 (got {args.snr:g})")
    if not args.min_amplitude >= 0:
        parser.error(f"--min-amplitude must be >= 0 (got {args.min_amplitude:g})")
    if args.command == "arrival":
        if args.centre is None:
            parser.error("arrival needs --centre X Y (radii are measured from it)")
        if args.radii and min(args.radii) < 0:
            parser.error("--radii must be >= 0")
    else:
        if args.point and len(args.point) > 1:
            parser.error("reflection takes one --point")
        if args.split is None and (args.boundary_distance is None or args.speed is None):
            parser.error("reflection needs --split T, or --boundary-distance D and --speed V")
        if args.split is None and not (args.boundary_distance > 0 and args.speed > 0):
            parser.error("--boundary-distance and --speed must be > 0")
    return args


def main(argv=None):
    args = parse_args(argv)
    try:
        return args.run(args)
    except WaveError as exc:
        print(f"fdem-wave: error: {exc}", file=sys.stderr)
        return 2

