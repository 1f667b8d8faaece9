#!/usr/bin/python3
"""Tests of the fdem Python package (python/fdem), imported from the source tree.

  /usr/bin/python3 tests/test_python.py [-v]          (ctest: `python`, label unit)

- analytics: the b-value on synthetic Gutenberg-Richter catalogues of known b, P50/P80
  by mass passing on hand-made sets, Rosin-Rammler and Swebrec fits on samples drawn
  from known parameters (fixed seeds);
- fdem.open on synthetic output folders (history, events and fragments files written
  here with netCDF4 in the layouts of docs/case-format.md) and on a real run of
  tests/data/cases/blast_small.toml by the fdem binary named in $FDEM_BINARY (ctest sets
  it; without it those tests are skipped);
- the new `fdem-plot events` and `fdem-plot fragments` commands through tools/fdem-plot.
"""

import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.realpath(__file__)))
sys.path.insert(0, os.path.join(REPO, "python"))

import netCDF4  # noqa: E402

import fdem  # noqa: E402
from fdem import analytics, fragments  # noqa: E402

PLOT = os.path.join(REPO, "tools", "fdem-plot")
LN10 = np.log(10.0)


def gutenberg_richter(rng, b, mc, n):
    """n continuous magnitudes >= mc with N(>= M) proportional to 10^(-b M)."""
    return mc + rng.exponential(1.0 / (b * LN10), n)


# ---------------------------------------------------------------------------------------
# Synthetic output files, in the writers' layouts.

def write_history(path, times, values):
    """values: name -> (array, units)."""
    with netCDF4.Dataset(path, "w", format="NETCDF3_64BIT_OFFSET") as ds:
        ds.title = "synthetic"
        ds.createDimension("time", None)
        t = ds.createVariable("time", "f8", ("time",))
        t.units = "s"
        t[:] = times
        for name, (v, units) in values.items():
            var = ds.createVariable(name, "f8", ("time",))
            var.units = units
            var.long_name = name.replace("_", " ")
            var[:] = v


def write_events(path, breaks=None, events=None):
    """breaks / events: name -> (array, units); the writer's dimensions `break`, `event`."""
    with netCDF4.Dataset(path, "w", format="NETCDF3_64BIT_OFFSET") as ds:
        ds.title = "synthetic events"
        ds.createDimension("break", None)
        if events is not None:
            ds.createDimension("event", len(next(iter(events.values()))[0]))
        for dim, table in (("break", breaks), ("event", events)):
            for name, (v, units) in (table or {}).items():
                v = np.asarray(v)
                var = ds.createVariable(name, "i4" if v.dtype.kind == "i" else "f8", (dim,))
                if units:
                    var.units = units
                var[:] = v


def write_fragments(path, frames, with_frame=True, with_diameter=True, with_mass=True):
    """frames: list of (time, areas, masses); the fragments writer's ragged layout."""
    with netCDF4.Dataset(path, "w", format="NETCDF3_64BIT_OFFSET") as ds:
        ds.title = "synthetic fragments"
        ds.createDimension("fragment_record", None)

        def var(name, kind, units):
            v = ds.createVariable(name, kind, ("fragment_record",))
            if units:
                v.units = units
            return v
        cols = {"fragment_time": ("f8", "s"), "fragment_id": ("i4", ""),
                "fragment_area": ("f8", "m2")}
        if with_frame:
            cols["fragment_frame"] = ("i4", "")
        if with_diameter:
            cols["fragment_diameter"] = ("f8", "m")
        if with_mass:
            cols["fragment_mass"] = ("f8", "kg")
        data = {name: [] for name in cols}
        for k, (t, areas, masses) in enumerate(frames):
            n = len(areas)
            row = {"fragment_time": np.full(n, t), "fragment_id": np.arange(1, n + 1),
                   "fragment_area": areas, "fragment_frame": np.full(n, k),
                   "fragment_diameter": np.sqrt(4 * np.asarray(areas) / np.pi),
                   "fragment_mass": masses}
            for name in cols:
                data[name].append(np.asarray(row[name]))
        for name, (kind, units) in cols.items():
            var(name, kind, units)[:] = np.concatenate(data[name])


def run_plot(*args):
    proc = subprocess.run([sys.executable, PLOT, *args], capture_output=True, text=True)
    return proc.returncode, proc.stdout + proc.stderr


class TempDirCase(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="fdem_python_test.")

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def assertPng(self, path):
        self.assertTrue(os.path.isfile(path), f"{path} not written")
        with open(path, "rb") as f:
            self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG")
        # A plot with axes, points and lines, not an empty figure.
        self.assertGreater(os.path.getsize(path), 5000, path)


# ---------------------------------------------------------------------------------------

class BValue(unittest.TestCase):
    def test_continuous_catalogue_of_known_b(self):
        rng = np.random.default_rng(14)
        for b in (0.7, 1.0, 1.4):
            m = gutenberg_richter(rng, b, 0.5, 20000)
            fit = analytics.b_value(m, mc=0.5)
            self.assertLess(abs(fit.b - b), 0.05, (b, fit))
            self.assertEqual(fit.n, 20000)
            # The standard error is about b / sqrt(n).
            self.assertAlmostEqual(fit.b_error / (fit.b / np.sqrt(fit.n)), 1.0, delta=0.1)
            # a: the fitted line counts every event at Mc.
            self.assertAlmostEqual(fit.count_at_least(0.5), 20000, delta=1e-6 * 20000)

    def test_events_below_mc_are_left_out(self):
        rng = np.random.default_rng(3)
        complete = gutenberg_richter(rng, 1.0, 1.0, 20000)
        # An incomplete tail below Mc: few small events, uniformly spread.
        tail = rng.uniform(0.0, 1.0, 500)
        fit = analytics.b_value(np.concatenate([tail, complete]), mc=1.0)
        self.assertEqual(fit.n, 20000)
        self.assertLess(abs(fit.b - 1.0), 0.05, fit)
        # Taken by maximum curvature: the most populated 0.1 bin is the one at 1.0.
        self.assertAlmostEqual(analytics.completeness_magnitude(np.concatenate([tail, complete])),
                               1.0, places=12)
        fit_auto = analytics.b_value(np.concatenate([tail, complete]))
        self.assertAlmostEqual(fit_auto.mc, 1.0, places=12)
        self.assertEqual(fit_auto.n, 20000)

    def test_binned_magnitudes_need_the_bin_correction(self):
        rng = np.random.default_rng(7)
        # Magnitudes from 0.95 up rounded to 0.1: the bin 1.0 holds [0.95, 1.05).
        m = np.round(gutenberg_richter(rng, 1.0, 0.95, 20000), 1)
        fit = analytics.b_value(m, mc=1.0, dm=0.1)
        self.assertEqual(fit.n, 20000)
        self.assertLess(abs(fit.b - 1.0), 0.05, fit)
        # Without Utsu's correction the same catalogue gives b about 13% too large.
        naive = analytics.b_value(m, mc=1.0, dm=0.0)
        self.assertGreater(naive.b - 1.0, 0.1, naive)

    def test_hand_made_catalogue(self):
        # mean - Mc = 0.5: b = log10(e) / 0.5.
        fit = analytics.b_value([1.0, 1.25, 1.5, 1.75, 2.0, 0.3], mc=1.0)
        self.assertEqual(fit.n, 5)
        self.assertAlmostEqual(fit.b, np.log10(np.e) / 0.5, places=12)
        edges, counts, cumulative = analytics.magnitude_frequency([0.31, 0.35, 0.52, 0.9], 0.1)
        self.assertTrue(np.allclose(edges, [0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9]))
        self.assertEqual(counts.tolist(), [2, 0, 1, 0, 0, 0, 1])
        self.assertEqual(cumulative.tolist(), [4, 2, 2, 1, 1, 1, 1])

    def test_magnitude_from_energy(self):
        # log10 E = 1.5 M + 4.8: E = 10^4.8 J is magnitude 0, each factor 10^1.5 one more.
        m = analytics.magnitude_from_energy([10 ** 4.8, 10 ** 6.3, 0.0, -1.0, np.inf])
        self.assertAlmostEqual(m[0], 0.0, places=12)
        self.assertAlmostEqual(m[1], 1.0, places=12)
        self.assertTrue(np.all(np.isnan(m[2:])))

    def test_too_few_events(self):
        with self.assertRaisesRegex(ValueError, "too few events"):
            analytics.b_value([0.1, 0.2, 2.0], mc=1.0)
        with self.assertRaisesRegex(ValueError, "every event sits at Mc"):
            analytics.b_value([1.0, 1.0, 1.0], mc=1.0)


class FragmentSizes(unittest.TestCase):
    def test_passing_and_percentiles_by_hand(self):
        x, p = analytics.passing([4.0, 1.0, 3.0, 2.0], [1, 1, 1, 1])
        self.assertEqual(x.tolist(), [1, 2, 3, 4])
        self.assertEqual(p.tolist(), [0.25, 0.5, 0.75, 1.0])
        self.assertEqual(analytics.percentile_size(x, [1] * 4, 0.5), 2.0)
        # 75% of the mass is at 3 or finer, all of it at 4: P80 is 4.
        self.assertEqual(analytics.percentile_size(x, [1] * 4, 0.8), 4.0)
        self.assertEqual(analytics.percentile_size(x, [1] * 4, 0.75), 3.0)
        # By mass, not by count: a quarter of the mass at 1, three quarters at 10; nine
        # small pieces and one that holds 91% of the mass.
        self.assertEqual(analytics.percentile_size([1.0, 10.0], [1.0, 3.0], 0.5), 10.0)
        self.assertEqual(analytics.percentile_size([0.1] * 9 + [5.0], [1.0] * 9 + [91.0],
                                                   0.5), 5.0)
        # The finest fragment alone holds more than half the mass.
        self.assertEqual(analytics.percentile_size([1.0, 10.0], [3.0, 1.0], 0.5), 1.0)
        # Twelve equal masses of 0.1: the sixth running sum over the total is 0.5 less
        # one unit of round-off, and must still count as half.
        self.assertEqual(analytics.percentile_size(np.arange(1.0, 13.0), [0.1] * 12, 0.5), 6.0)
        # Fragments of zero mass or size do not count.
        self.assertEqual(analytics.passing([0.0, 1.0, 2.0], [5.0, 1.0, 0.0])[0].tolist(), [1.0])

    def test_rosin_rammler_sample(self):
        rng = np.random.default_rng(11)
        xc, n = 0.2, 1.3
        sizes = xc * rng.weibull(n, 20000)  # equal masses: mass passing = count passing
        self.assertLess(abs(analytics.percentile_size(sizes, None, 0.5) /
                            (xc * np.log(2.0) ** (1 / n)) - 1), 0.02)
        self.assertLess(abs(analytics.percentile_size(sizes, None, 0.8) /
                            (xc * np.log(5.0) ** (1 / n)) - 1), 0.02)
        fit = analytics.rosin_rammler_fit(sizes)
        self.assertLess(abs(fit.xc / xc - 1), 0.03, fit)
        self.assertLess(abs(fit.n / n - 1), 0.05, fit)
        self.assertLess(fit.rms, 0.01, fit)

    def test_rosin_rammler_by_mass(self):
        # Few large and many small fragments whose masses follow the curve exactly:
        # each size class carries the mass between its neighbours' curve values.
        xc, n = 0.05, 0.9
        x = np.geomspace(1e-4, 0.5, 400)
        cdf = 1 - np.exp(-(x / xc) ** n)
        mass = np.diff(np.concatenate([[0.0], cdf]))
        fit = analytics.rosin_rammler_fit(x, mass)
        self.assertLess(abs(fit.xc / xc - 1), 0.02, fit)
        self.assertLess(abs(fit.n / n - 1), 0.02, fit)
        # P50 is the first size class at which the curve reaches one half.
        p50 = analytics.percentile_size(x, mass, 0.5)
        step = x[1] / x[0]
        self.assertTrue(xc * np.log(2.0) ** (1 / n) <= p50 < xc * np.log(2.0) ** (1 / n) * step,
                        p50)

    def test_swebrec_sample(self):
        rng = np.random.default_rng(5)
        xmax, x50, b = 1.0, 0.2, 2.0
        u = rng.random(20000)
        sizes = xmax * np.exp(-np.log(xmax / x50) * (1 / u - 1) ** (1 / b))
        fit = analytics.swebrec_fit(sizes)
        self.assertLess(abs(fit.x50 / x50 - 1), 0.03, fit)
        self.assertLess(abs(fit.b / b - 1), 0.05, fit)
        self.assertLess(abs(fit.xmax / xmax - 1), 0.1, fit)
        self.assertLess(abs(analytics.percentile_size(sizes, None, 0.5) / x50 - 1), 0.02)
        # Given x_max, only x50 and b are fitted.
        fixed = analytics.swebrec_fit(sizes, xmax=1.0)
        self.assertEqual(fixed.xmax, 1.0)
        self.assertLess(abs(fixed.x50 / x50 - 1), 0.03, fixed)
        self.assertLess(abs(fixed.b / b - 1), 0.05, fixed)
        self.assertAlmostEqual(float(fixed.cdf(np.array([fixed.x50]))[0]), 0.5, places=12)
        self.assertAlmostEqual(fixed.size(0.5), fixed.x50, places=12)
        with self.assertRaisesRegex(ValueError, "must exceed the largest fragment"):
            analytics.swebrec_fit(sizes, xmax=0.5)

    def test_one_fragment(self):
        dist = analytics.size_distribution([0.3], [2.0])
        self.assertEqual((dist.n, dist.p50, dist.p80), (1, 0.3, 0.3))
        self.assertIsNone(dist.rosin_rammler)
        self.assertIsNone(dist.swebrec)


class OpenSynthetic(TempDirCase):
    def make_run(self, name="syn", n_events=5000, seed=1):
        rng = np.random.default_rng(seed)
        write_history(os.path.join(self.dir, f"{name}_history.nc"), np.linspace(0, 1e-3, 11),
                      {"kinetic_energy": (np.linspace(0, 5, 11), "J"),
                       "broken_ce4": (np.arange(11.0), "1")})
        nb = 3 * n_events
        r, a = 0.05 + rng.exponential(0.3, nb), rng.uniform(0, 2 * np.pi, nb)
        mags = gutenberg_richter(rng, 1.0, -1.0, n_events)
        write_events(os.path.join(self.dir, f"{name}_events.nc"),
                     breaks={"break_time": (np.sort(rng.uniform(0, 1e-3, nb)), "s"),
                             "break_x": (r * np.cos(a), "m"), "break_y": (r * np.sin(a), "m"),
                             "break_length": (np.full(nb, 0.01), "m"),
                             "break_mode": (rng.integers(1, 4, nb).astype(np.int32), ""),
                             "break_energy": (rng.uniform(1, 2, nb), "J")},
                     events={"event_start": (np.linspace(0, 1e-3, n_events), "s"),
                             "event_end": (np.linspace(0, 1e-3, n_events) + 1e-6, "s"),
                             "event_x": (np.zeros(n_events), "m"),
                             "event_y": (np.zeros(n_events), "m"),
                             "event_breaks": (np.full(n_events, 3, dtype=np.int32), ""),
                             "event_energy": (10 ** (1.5 * mags + 4.8), "J"),
                             "event_magnitude": (mags, "")})
        frames = [(0.0, [1.0], [2600.0])]
        for t in (5e-4, 1e-3):
            sizes = 0.1 * rng.weibull(1.2, 400)
            areas = np.pi * sizes ** 2 / 4
            frames.append((t, areas, 2600 * areas))
        write_fragments(os.path.join(self.dir, f"{name}_fragments.nc"), frames)
        return mags

    def test_open_a_folder(self):
        self.make_run()
        run = fdem.open(self.dir)
        self.assertEqual(run.name, "syn")
        hist = run.history
        self.assertEqual(hist.sizes["time"], 11)
        self.assertEqual(hist["time"].attrs["units"], "s")
        self.assertEqual(hist["kinetic_energy"].attrs["units"], "J")
        self.assertEqual(float(hist["kinetic_energy"][-1]), 5.0)
        ev = run.events
        self.assertEqual(ev.sizes["break"], 15000)
        self.assertEqual(ev.sizes["event"], 5000)
        self.assertEqual(ev["break_time"].attrs["units"], "s")
        self.assertEqual(ev["break_x"].attrs["units"], "m")
        self.assertEqual(set(run.breaks.data_vars), {"break_time", "break_x", "break_y",
                                                     "break_length", "break_mode",
                                                     "break_energy"})
        self.assertIn(ev["break_mode"].dtype.kind, "iu")
        frag = run.fragments
        self.assertEqual(frag["fragment_diameter"].attrs["units"], "m")
        self.assertEqual(fragments.frames(frag), [(0, 0.0), (1, 5e-4), (2, 1e-3)])
        self.assertEqual(fragments.at_frame(frag, 0).sizes["fragment_record"], 1)
        last = fragments.at_frame(frag, -1)
        self.assertEqual(last.sizes["fragment_record"], 400)
        self.assertEqual(float(last["fragment_time"][0]), 1e-3)
        table = fragments.summary(frag)
        self.assertEqual(table["fragments"].values.tolist(), [1, 400, 400])
        self.assertAlmostEqual(float(table["p50"][0]), np.sqrt(4 / np.pi), places=12)
        with self.assertRaisesRegex(ValueError, "no fragments recorded at frame 7"):
            fragments.at_frame(frag, 7)
        # No Exodus file in this folder: frames say which file is missing.
        with self.assertRaisesRegex(FileNotFoundError, "syn.exo"):
            run.frames
        # The same run by NAME prefix and by one of its files.
        self.assertEqual(fdem.open(os.path.join(self.dir, "syn")).name, "syn")
        self.assertEqual(fdem.open(os.path.join(self.dir, "syn_events.nc")).events.sizes["event"],
                         5000)

    def test_folders_with_several_runs_or_none(self):
        self.make_run("a")
        self.make_run("b")
        with self.assertRaisesRegex(ValueError, r"several runs \(a, b\)"):
            fdem.open(self.dir)
        self.assertEqual(fdem.open(self.dir, name="b").name, "b")
        self.assertEqual(fdem.open(os.path.join(self.dir, "a")).name, "a")
        with self.assertRaisesRegex(FileNotFoundError, "no such fdem-cl output"):
            fdem.open(os.path.join(self.dir, "c"))
        empty = os.path.join(self.dir, "empty")
        os.mkdir(empty)
        with self.assertRaisesRegex(FileNotFoundError, "no fdem-cl output"):
            fdem.open(empty)

    def test_absent_and_partial_files(self):
        write_history(os.path.join(self.dir, "h_history.nc"), [0.0, 1.0], {})
        run = fdem.open(self.dir)
        self.assertIsNone(run.events)
        self.assertIsNone(run.fragments)
        self.assertIsNone(run.breaks)
        # An events file with breaks only: the event variables are there, empty.
        write_events(os.path.join(self.dir, "h_events.nc"),
                     breaks={"break_time": ([1e-4, 2e-4], "s"), "break_x": ([0, 1], "m"),
                             "break_y": ([0, 0], "m")})
        ev = fdem.open(self.dir).events
        self.assertEqual(ev.sizes["break"], 2)
        self.assertEqual(ev["event_magnitude"].size, 0)
        # A fragments file with neither frame index, diameter nor mass: frames by time,
        # size from the area, mass = area.
        write_fragments(os.path.join(self.dir, "h_fragments.nc"),
                        [(0.0, [np.pi / 4], [1.0]), (1.0, [np.pi / 4, np.pi], [1.0, 1.0])],
                        with_frame=False, with_diameter=False, with_mass=False)
        frag = fdem.open(self.dir).fragments
        self.assertEqual([k for k, _ in fragments.frames(frag)], [0, 1])
        size, mass = fragments.sizes_and_masses(fragments.at_frame(frag, 1))
        self.assertTrue(np.allclose(size, [1.0, 2.0]))
        self.assertTrue(np.allclose(mass, [np.pi / 4, np.pi]))

    def test_plots_of_empty_files(self):
        # A run that broke nothing yet: an events file with no records plots empty maps;
        # a fragments file with its header only is refused, naming the file.
        write_history(os.path.join(self.dir, "e_history.nc"), [0.0], {})
        write_events(os.path.join(self.dir, "e_events.nc"),
                     breaks={"break_time": (np.zeros(0), "s"), "break_x": (np.zeros(0), "m"),
                             "break_y": (np.zeros(0), "m"),
                             "break_mode": (np.zeros(0, dtype=np.int32), "1")})
        rc, text = run_plot("events", self.dir, "-o", os.path.join(self.dir, "e.png"))
        self.assertEqual(rc, 0, text)
        self.assertIn("0 breaks (mode I 0, mode II 0, mixed 0), 0 events", text)
        with netCDF4.Dataset(os.path.join(self.dir, "e_fragments.nc"), "w",
                             format="NETCDF3_64BIT_OFFSET") as ds:
            ds.createDimension("fragment_record", None)
            for name in ("fragment_frame", "fragment_time", "fragment_diameter"):
                ds.createVariable(name, "f8", ("fragment_record",))
        rc, text = run_plot("fragments", self.dir, "-o", os.path.join(self.dir, "f.png"))
        self.assertEqual(rc, 2, text)
        self.assertIn("e_fragments.nc: the fragments file has no records yet", text)
        self.assertEqual(fragments.summary(fdem.open(self.dir).fragments).sizes["frame"], 0)

    def test_plot_events_and_fragments(self):
        mags = self.make_run()
        out = os.path.join(self.dir, "ev.png")
        rc, text = run_plot("events", self.dir, "--mc", "-1", "-o", out)
        self.assertEqual(rc, 0, text)
        self.assertPng(out)
        self.assertIn("15000 breaks", text)
        b = float(text.split("Gutenberg-Richter b = ")[1].split()[0])
        self.assertAlmostEqual(b, analytics.b_value(mags, mc=-1.0).b, places=3)
        self.assertLess(abs(b - 1.0), 0.05, text)
        # The single breaks' magnitudes from break_energy (uniform in [1, 2] J here).
        rc, text = run_plot("events", self.dir, "--breaks", "-o", out)
        self.assertEqual(rc, 0, text)
        self.assertIn("15000 breaks; Gutenberg-Richter b = ", text)
        # Default output name, Mc by maximum curvature.
        rc, text = run_plot("events", os.path.join(self.dir, "syn"))
        self.assertEqual(rc, 0, text)
        self.assertPng(os.path.join(self.dir, "syn_events.png"))
        rc, text = run_plot("fragments", self.dir, "--frame", "1", "-o",
                            os.path.join(self.dir, "fr.png"))
        self.assertEqual(rc, 0, text)
        self.assertPng(os.path.join(self.dir, "fr.png"))
        self.assertIn("frame 1, t = 0.0005 s: 400 fragments, P50 = ", text)
        rc, text = run_plot("fragments", self.dir)
        self.assertEqual(rc, 0, text)
        self.assertIn("frame 2, ", text)
        self.assertPng(os.path.join(self.dir, "syn_fragments.png"))
        # Without the largest piece of each frame.
        rc, text = run_plot("fragments", self.dir, "--frame", "1", "--without-largest", "-o",
                            os.path.join(self.dir, "fr1.png"))
        self.assertEqual(rc, 0, text)
        self.assertIn("frame 1, t = 0.0005 s: 399 fragments (the largest, ", text)
        self.assertPng(os.path.join(self.dir, "fr1.png"))
        table = fragments.summary(fdem.open(self.dir).fragments, without_largest=True)
        self.assertEqual(table["fragments"].values.tolist(), [0, 399, 399])
        self.assertTrue(np.isnan(float(table["p50"][0])))
        # A frame with one fragment: no fit, still a plot.
        rc, text = run_plot("fragments", self.dir, "--frame", "0", "-o",
                            os.path.join(self.dir, "fr0.png"))
        self.assertEqual(rc, 0, text)
        self.assertIn("no fit", text)
        # Bad input: exit 2 and one line naming the problem.
        rc, text = run_plot("fragments", self.dir, "--frame", "9", "-o",
                            os.path.join(self.dir, "x.png"))
        self.assertEqual(rc, 2, text)
        self.assertIn("no fragments recorded at frame 9", text)
        rc, text = run_plot("events", os.path.join(self.dir, "nope"))
        self.assertEqual(rc, 2, text)
        self.assertIn("no such fdem-cl output", text)
        rc, text = run_plot("events", self.dir, "--bin-width", "0")
        self.assertEqual(rc, 2, text)
        self.assertIn("--bin-width must be > 0", text)


@unittest.skipUnless(os.environ.get("FDEM_BINARY"), "FDEM_BINARY (the fdem binary) not set")
class OpenRealRun(TempDirCase):
    """tests/data/cases/blast_small.toml run by the fdem binary: 0.2 ms of a blast on a
    coarse mesh, about 700 steps, CE4s breaking around the hole."""

    @classmethod
    def setUpClass(cls):
        cls.out = tempfile.mkdtemp(prefix="fdem_python_run.")
        case = os.path.join(REPO, "tests", "data", "cases", "blast_small.toml")
        proc = subprocess.run([os.environ["FDEM_BINARY"], "run", case, "--set",
                               f"output.dir={cls.out}"], capture_output=True, text=True)
        if proc.returncode != 0:
            raise RuntimeError(f"fdem run {case} failed:\n{proc.stdout}{proc.stderr}")
        cls.output = fdem.open(cls.out)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.out, ignore_errors=True)

    def test_history_and_frames(self):
        run = self.output
        self.assertEqual(run.name, "blast")
        hist = run.history
        self.assertEqual(hist["time"].attrs["units"], "s")
        self.assertEqual(hist["kinetic_energy"].attrs["units"], "J")
        self.assertAlmostEqual(float(hist["time"][-1]), 2e-4, delta=1e-6)  # the last step
        self.assertGreater(float(hist["broken_ce4"][-1]), 0)
        frames = run.frames
        self.assertEqual(frames["DISPLX"].attrs["units"], "m")
        self.assertEqual(frames["SXX"].attrs["units"], "Pa")
        self.assertEqual(frames["time"].attrs["units"], "s")
        self.assertEqual(sorted(set(frames["block"].values)), ["cohesive", "rock"])
        rock, ce4 = run.block("rock"), run.block("cohesive")
        self.assertEqual(rock.sizes["corner"], 3)
        self.assertEqual(ce4.sizes["corner"], 4)
        self.assertEqual(rock.sizes["elem"] + ce4.sizes["elem"], frames.sizes["elem"])
        # The xarray view holds the same numbers as the plain loader.
        exo = fdem.load.load_exodus(run.files["frames"])
        self.assertTrue(np.array_equal(frames["SXX"].values[-1], exo.element_values("SXX", -1)))
        self.assertTrue(np.array_equal(rock["connectivity"].values, exo.blocks[0].connectivity))
        self.assertEqual(list(run.blocks), ["rock", "cohesive"])
        self.assertEqual(run.blocks["rock"].sizes["elem"], exo.blocks[0].num_elem)
        x, y = run.positions(-1)
        self.assertTrue(np.array_equal(x.values, exo.x + exo.nodal["DISPLX"][-1]))
        self.assertTrue(np.array_equal(y.values, exo.y + exo.nodal["DISPLY"][-1]))
        self.assertEqual(x.attrs["units"], "m")
        broken = int(np.sum(ce4["BROKEN"].values[-1] > 0.5))
        self.assertGreater(broken, 0)
        with self.assertRaisesRegex(KeyError, "blocks: rock, cohesive"):
            run.block("granite")

    def test_events(self):
        ev = self.output.events
        if ev is None:  # a build that writes no events file
            rc, text = run_plot("events", self.out, "-o", os.path.join(self.dir, "x.png"))
            self.assertEqual(rc, 2, text)
            self.assertIn("blast_events.nc: no such file", text)
            return
        t_end = float(self.output.history["time"][-1])
        self.assertGreater(ev.sizes["break"], 0)
        self.assertEqual(ev["break_time"].attrs.get("units"), "s")
        self.assertTrue(np.all((ev["break_time"].values >= 0) &
                               (ev["break_time"].values <= t_end * (1 + 1e-9))))
        self.assertTrue(set(np.unique(ev["break_mode"].values)) <= {1, 2, 3})
        # The catalogue holds every CE4 broken in the last frame (the run's end), once.
        broken = np.flatnonzero(self.output.block("cohesive")["BROKEN"].values[-1] > 0.5)
        self.assertEqual(ev.sizes["break"], len(broken))
        if "break_ce4" in ev:
            self.assertEqual(sorted(ev["break_ce4"].values.tolist()), broken.tolist())
        modes = self.output.block("cohesive")["MODE"].values[-1][broken].round()
        for value in (1, 2, 3):
            self.assertEqual(int(np.sum(ev["break_mode"].values == value)),
                             int(np.sum(modes == value)), f"mode {value}")
        out = os.path.join(self.dir, "events.png")
        rc, text = run_plot("events", self.out, "-o", out)
        self.assertEqual(rc, 0, text)
        self.assertPng(out)
        self.assertIn(f"{ev.sizes['break']} breaks", text)
        # Magnitude-frequency of the single breaks: the printed b is the package's.
        rc, text = run_plot("events", self.out, "--breaks", "-o", out)
        self.assertEqual(rc, 0, text)
        mags = analytics.magnitude_from_energy(ev["break_energy"].values)
        fit = analytics.b_value(mags)
        self.assertIn(f"Gutenberg-Richter b = {fit.b:.4g} ", text)

    def test_fragments(self):
        frag = self.output.fragments
        if frag is None:  # a build that writes no fragments file
            rc, text = run_plot("fragments", self.out, "-o", os.path.join(self.dir, "x.png"))
            self.assertEqual(rc, 2, text)
            self.assertIn("blast_fragments.nc: no such file", text)
            return
        present = fragments.frames(frag)
        self.assertGreater(len(present), 0)
        size, mass = fragments.sizes_and_masses(fragments.at_frame(frag, -1))
        self.assertTrue(np.all(size > 0) and np.all(mass > 0))
        # The pieces hold the whole mass of the disc at every frame.
        total0 = np.sum(fragments.sizes_and_masses(fragments.at_frame(frag, present[0][0]))[1])
        self.assertAlmostEqual(float(np.sum(mass)) / float(total0), 1.0, delta=1e-9)
        out = os.path.join(self.dir, "fragments.png")
        rc, text = run_plot("fragments", self.out, "-o", out)
        self.assertEqual(rc, 0, text)
        self.assertPng(out)
        dist = analytics.size_distribution(size, mass)
        self.assertIn(f"{len(size)} fragments, P50 = {dist.p50:.6g} m, P80 = {dist.p80:.6g} m",
                      text)
        if len(size) > 2:
            rc, text = run_plot("fragments", self.out, "--without-largest", "-o", out)
            self.assertEqual(rc, 0, text)
            self.assertIn(f"{len(size) - 1} fragments (the largest", text)


if __name__ == "__main__":
    unittest.main()
