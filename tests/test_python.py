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
- the new `fdem-plot events` and `fdem-plot fragments` commands through tools/fdem-plot;
- issue 28, row 15 (analytics on bad input), each on synthetic data of known answer:
  the fragment statistics leave the steel platens out (a synthetic Exodus file tells
  the materials), a Swebrec fit on the bound of its x_max search warns and says which,
  `fdem-wave arrival` finds no front in precursor noise (exit 2, "no front found")
  and leaves such points out of the speed fit, `b_value` of one event says why there
  is no b instead of raising.
"""

import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest
import warnings

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.realpath(__file__)))
sys.path.insert(0, os.path.join(REPO, "python"))

import netCDF4  # noqa: E402

import fdem  # noqa: E402
from fdem import analytics, fragments  # noqa: E402

PLOT = os.path.join(REPO, "tools", "fdem-plot")
WAVE = os.path.join(REPO, "tools", "fdem-wave")
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


def write_exodus(path, x, y, blocks):
    """A minimal Exodus file as the engine writes one (mesh only, no frames): blocks is a
    list of (name, elem_type, 0-based connectivity rows)."""
    with netCDF4.Dataset(path, "w", format="NETCDF3_64BIT_OFFSET") as ds:
        ds.title = "synthetic mesh"
        ds.createDimension("len_name", 33)
        ds.createDimension("time_step", None)
        ds.createDimension("num_dim", 2)
        ds.createDimension("num_nodes", len(x))
        ds.createDimension("num_elem", sum(len(b[2]) for b in blocks))
        ds.createDimension("num_el_blk", len(blocks))
        ds.createVariable("time_whole", "f8", ("time_step",))
        ds.createVariable("coordx", "f8", ("num_nodes",))[:] = x
        ds.createVariable("coordy", "f8", ("num_nodes",))[:] = y
        names = ds.createVariable("eb_names", "S1", ("num_el_blk", "len_name"))
        names[:] = netCDF4.stringtochar(np.array([b[0] for b in blocks], dtype="S33"))
        ds.createVariable("eb_prop1", "i4", ("num_el_blk",))[:] = np.arange(1, len(blocks) + 1)
        for k, (name, kind, conn) in enumerate(blocks, start=1):
            conn = np.asarray(conn)
            ds.createDimension(f"num_el_in_blk{k}", conn.shape[0])
            ds.createDimension(f"num_nod_per_el{k}", conn.shape[1])
            var = ds.createVariable(f"connect{k}", "i4", (f"num_el_in_blk{k}", f"num_nod_per_el{k}"))
            var.elem_type = kind
            var[:] = conn + 1


def write_probes(path, times, probes, var="ps1"):
    """A history file with [[probe]] variables NAME_<var> (Pa) and their attributes:
    probes is a list of (name, (x, y), values)."""
    with netCDF4.Dataset(path, "w", format="NETCDF3_64BIT_OFFSET") as ds:
        ds.title = "synthetic probes"
        ds.createDimension("time", None)
        t = ds.createVariable("time", "f8", ("time",))
        t.units = "s"
        t[:] = times
        for k, (name, point, values) in enumerate(probes):
            v = ds.createVariable(f"{name}_{var}", "f8", ("time",))
            v.units = "Pa"
            v.probe_point = np.asarray(point, dtype=float)
            v.probe_element = np.int32(k + 1)
            v[:] = values


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
        # Issue 28 row 15: a catalogue of one event raised ValueError from inside the
        # estimator; now every short catalogue gives a result that says why b is NaN.
        one = analytics.b_value([1.3])
        self.assertFalse(one.ok)
        self.assertEqual((one.n, one.mc), (1, 1.3))
        self.assertTrue(np.isnan(one.b) and np.isnan(one.b_error) and np.isnan(one.a))
        self.assertIn("too few events at or above Mc = 1.3 (1; a b-value needs 2 or more)",
                      one.note)
        fit = analytics.b_value([0.1, 0.2, 2.0], mc=1.0)
        self.assertEqual((fit.ok, fit.n), (False, 1))
        self.assertIn("too few events", fit.note)
        fit = analytics.b_value([1.0, 1.0, 1.0], mc=1.0)
        self.assertEqual((fit.ok, fit.n), (False, 3))
        self.assertIn("every event sits at Mc = 1", fit.note)
        none = analytics.b_value([])
        self.assertEqual((none.ok, none.n, none.note), (False, 0, "no events: no b-value"))
        self.assertTrue(analytics.b_value([1.0, 1.5], mc=1.0).ok)
        # Bad arguments are still errors.
        with self.assertRaisesRegex(ValueError, "dm must be >= 0"):
            analytics.b_value([1.0, 2.0], dm=-0.1)


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
        with warnings.catch_warnings():
            warnings.simplefilter("error", analytics.FitWarning)  # inside its range: no warning
            fit = analytics.swebrec_fit(sizes)
        self.assertEqual(fit.bound, "")
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

    def test_swebrec_on_its_bound_warns(self):
        # A lognormal sample has no largest size: the best x_max runs to the upper end of
        # the search (ten times the largest fragment).
        rng = np.random.default_rng(1)
        sizes = np.exp(rng.normal(0.0, 1.0, 2000))
        with self.assertWarnsRegex(analytics.FitWarning, "sits on the upper bound of its "
                                   "search, ten times the largest fragment"):
            fit = analytics.swebrec_fit(sizes)
        self.assertEqual(fit.bound, "upper")
        self.assertAlmostEqual(fit.xmax / sizes.max(), 10.0, places=6)
        # A Swebrec sample of b = 0.7 whose largest fragments come within 1e-5 of x_max:
        # the best x_max is the lower end, the largest fragment itself.
        u = rng.random(5000)
        sizes = np.exp(-np.log(1 / 0.2) * (1 / u - 1) ** (1 / 0.7))
        with self.assertWarnsRegex(analytics.FitWarning, "sits on the lower bound of its "
                                   "search, the largest fragment"):
            fit = analytics.swebrec_fit(sizes)
        self.assertEqual(fit.bound, "lower")
        self.assertLess(fit.xmax / sizes.max() - 1, 2e-4)
        # size_distribution passes the warning on; a fixed x_max is no search.
        with self.assertWarns(analytics.FitWarning):
            self.assertEqual(analytics.size_distribution(sizes).swebrec.bound, "lower")
        with warnings.catch_warnings():
            warnings.simplefilter("error", analytics.FitWarning)
            self.assertEqual(analytics.swebrec_fit(sizes, xmax=1.0).bound, "")

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


class PlatensAreNoFragments(TempDirCase):
    """A Brazilian test in miniature: a rock block of four fracturable triangles (each
    with its own nodes, joined by CE4s) between two steel platens of two triangles each
    (shared nodes, no CE4s). Frame 0: the rock whole (one piece, 1 kg) and the platens
    (4 kg each, larger); frame 1: the rock in two pieces of 0.25 and 0.75 kg. Issue 28
    row 15: the platens were counted as fragments, so P50 was a platen's size."""

    ROCK_SIZES = (0.1, 0.05, 0.08)  # frame 0: the whole rock; frame 1: its two pieces

    def make_run(self, with_exodus=True):
        # Nodes: rock triangles 0-3 own nodes 0-11; platen triangles share 12-15, 16-19.
        x = np.arange(20.0)
        y = np.zeros(20)
        rock = [[0, 1, 2], [3, 4, 5], [6, 7, 8], [9, 10, 11]]
        top = [[12, 13, 14], [13, 15, 14]]
        bottom = [[16, 17, 18], [17, 19, 18]]
        ce4 = [[1, 2, 4, 3], [4, 5, 7, 6], [7, 8, 10, 9]]
        if with_exodus:
            write_exodus(os.path.join(self.dir, "disc.exo"), x, y,
                         [("rock", "TRI3", rock), ("steel", "TRI3", top + bottom),
                          ("cohesive", "QUAD4", ce4)])
        # Element numbers: rock 1-4, steel 5-8 (top 5-6, bottom 7-8), cohesive 9-11.
        d_rock, d_a, d_b = self.ROCK_SIZES
        d_platen = 0.3
        area = lambda d: np.pi * d * d / 4  # noqa: E731
        frames = [(0.0, [1, 5, 7], [d_rock, d_platen, d_platen], [1.0, 4.0, 4.0]),
                  (1e-4, [1, 3, 5, 7], [d_a, d_b, d_platen, d_platen], [0.25, 0.75, 4.0, 4.0])]
        with netCDF4.Dataset(os.path.join(self.dir, "disc_fragments.nc"), "w",
                             format="NETCDF3_64BIT_OFFSET") as ds:
            ds.createDimension("fragment_record", None)
            cols = {"fragment_frame": "i4", "fragment_time": "f8", "fragment_id": "i4",
                    "fragment_area": "f8", "fragment_mass": "f8", "fragment_diameter": "f8"}
            data = {c: [] for c in cols}
            for k, (t, ids, d, m) in enumerate(frames):
                data["fragment_frame"] += [k] * len(ids)
                data["fragment_time"] += [t] * len(ids)
                data["fragment_id"] += ids
                data["fragment_area"] += [area(v) for v in d]
                data["fragment_mass"] += m
                data["fragment_diameter"] += d
            for c, kind in cols.items():
                ds.createVariable(c, kind, ("fragment_record",))[:] = np.asarray(data[c])
        write_history(os.path.join(self.dir, "disc_history.nc"), [0.0, 1e-4], {})

    def test_statistics_leave_the_platens_out(self):
        self.make_run()
        frag = fdem.open(self.dir).fragments
        self.assertTrue(fragments.is_labelled(frag))
        self.assertEqual(frag["fragment_material"].values.tolist(),
                         ["rock", "steel", "steel", "rock", "rock", "steel", "steel"])
        self.assertEqual(frag["fragment_fracturable"].values.tolist(), [1, 0, 0, 1, 1, 0, 0])
        self.assertEqual(fragments.left_out(frag), ["steel"])
        d_rock, d_a, d_b = self.ROCK_SIZES
        size, mass = fragments.sizes_and_masses(fragments.at_frame(frag, 1))
        self.assertEqual((size.tolist(), mass.tolist()), ([d_a, d_b], [0.25, 0.75]))
        table = fragments.summary(frag)
        self.assertEqual(table["fragments"].values.tolist(), [1, 2])
        # P50 by mass: the rock itself, then its 0.75 kg piece (not the 0.3 m platens).
        self.assertEqual(table["p50"].values.tolist(), [d_rock, d_b])
        # With every body: the platens hold 8 of 9 kg and are the P50 of every frame.
        everything = fragments.summary(frag, include_unfracturable=True)
        self.assertEqual(everything["fragments"].values.tolist(), [3, 4])
        self.assertEqual(everything["p50"].values.tolist(), [0.3, 0.3])
        size, _ = fragments.sizes_and_masses(fragments.at_frame(frag, 1), True)
        self.assertEqual(len(size), 4)
        # The same through fdem-plot, with and without the option.
        out = os.path.join(self.dir, "f.png")
        rc, text = run_plot("fragments", self.dir, "-o", out)
        self.assertEqual(rc, 0, text)
        self.assertIn(f"frame 1, t = 0.0001 s: 2 fragments of fracturable material (steel "
                      f"left out: not fracturable; --include-unfracturable counts them), "
                      f"P50 = {d_b:.6g} m", text)
        rc, text = run_plot("fragments", self.dir, "--include-unfracturable", "-o", out)
        self.assertEqual(rc, 0, text)
        self.assertIn("4 fragments (all bodies, non-fracturable ones included), P50 = 0.3 m",
                      text)

    def test_unlabelled_and_mismatched_files(self):
        # Without the Exodus file the pieces cannot be told apart: all count, with a note.
        self.make_run(with_exodus=False)
        frag = fdem.open(self.dir).fragments
        self.assertFalse(fragments.is_labelled(frag))
        self.assertEqual(fragments.summary(frag)["fragments"].values.tolist(), [3, 4])
        rc, text = run_plot("fragments", self.dir, "-o", os.path.join(self.dir, "f.png"))
        self.assertEqual(rc, 0, text)
        self.assertIn("note: no disc.exo beside disc_fragments.nc: rock cannot be told from "
                      "other bodies", text)
        # An Exodus file of another mesh (too few triangles for the ids): refused.
        write_exodus(os.path.join(self.dir, "disc.exo"), np.arange(3.0), np.zeros(3),
                     [("rock", "TRI3", [[0, 1, 2]])])
        with self.assertRaisesRegex(ValueError, "fragment id 5 is no triangle of the Exodus "
                                    "file \\(TRI3 elements 1 to 1\\)"):
            fdem.open(self.dir).fragments
        rc, text = run_plot("fragments", self.dir, "-o", os.path.join(self.dir, "f.png"))
        self.assertEqual(rc, 2, text)
        self.assertIn("not of the same run", text)


class WaveArrival(TempDirCase):
    """fdem-wave arrival on synthetic probe records: a compressive step of 6 MPa that
    travels at 3000 m/s from x = 0 (arrival at x / c, a linear rise over 20 us), and
    points the front never reaches within the record, where only +-44 Pa of precursor
    and round-off are seen. Issue 28 row 15: such points gave arrivals of their own and
    a speed of 17,147 m/s instead of "no front found"."""

    C = 3000.0

    def records(self, reached, unreached, seed=4):
        rng = np.random.default_rng(seed)
        t = np.linspace(0.0, 1e-3, 501)
        probes = []
        for x in reached:
            rise = np.clip((t - x / self.C) / 2e-5, 0.0, 1.0)
            probes.append((f"x{x:g}", (x, 0.0), -6e6 * rise + rng.normal(0.0, 15.0, len(t))))
        for x in unreached:
            probes.append((f"x{x:g}", (x, 0.0), rng.uniform(-44.0, 44.0, len(t))))
        path = os.path.join(self.dir, "w_history.nc")
        write_probes(path, t, probes)
        return path

    def wave(self, *args):
        proc = subprocess.run([sys.executable, WAVE, *args], capture_output=True, text=True)
        return proc.returncode, proc.stdout + proc.stderr

    def test_noise_is_no_front(self):
        path = self.records([0.3, 0.6, 0.9, 1.2], [4.0, 5.0])
        rc, text = self.wave("arrival", path, "--centre", "0", "0")
        self.assertEqual(rc, 0, text)
        v = float(text.split("apparent P-wave speed V = ")[1].split()[0])
        # The half-peak crossing is 10 us after the start of the rise at every point.
        self.assertAlmostEqual(v / self.C, 1.0, delta=1e-3)
        self.assertIn("over 4 points", text)
        self.assertIn("note: no front at x4 (element 5): peak compressive change", text)
        self.assertIn("is below --threshold 0.001 x the signal's peak", text)
        self.assertRegex(text, r"x5 +5 +0 +5 +element 6 +no front")

    def test_no_front_found(self):
        # Only noise at every probe (the record ends before the front): exit 2.
        path = self.records([], [2.0, 3.0, 4.0])
        rc, text = self.wave("arrival", path, "--centre", "0", "0")
        self.assertEqual(rc, 2, text)
        self.assertIn("fdem-wave: error: no front found: none of the 3 points has a "
                      "compressive front", text)
        self.assertNotIn("apparent P-wave speed V", text)
        # A window that ends before the front: its precursor is measured against the
        # whole record's peak, so it is no front either.
        path = self.records([0.9, 1.2], [])
        rc, text = self.wave("arrival", path, "--centre", "0", "0", "--until", "2e-4")
        self.assertEqual(rc, 2, text)
        self.assertIn("no front found", text)
        # An absolute floor: 6 MPa fronts are below a 1e7 Pa minimum.
        path = self.records([0.3, 0.6], [])
        rc, text = self.wave("arrival", path, "--centre", "0", "0", "--min-amplitude", "1e7")
        self.assertEqual(rc, 2, text)
        self.assertIn("below --min-amplitude 1e+07", text)
        rc, text = self.wave("arrival", path, "--centre", "0", "0", "--threshold", "1.5")
        self.assertEqual(rc, 2, text)
        self.assertIn("--threshold must be in [0, 1)", text)


@unittest.skipUnless(os.environ.get("FDEM_BINARY"), "FDEM_BINARY (the fdem binary) not set")
class OpenFluidRun(unittest.TestCase):
    """cases/sneddon coarse (10 edges along the crack) to 0.5 ms: the fluid held at the
    ramp's p(t) = 1 MPa t / 2 ms on every crack vertex; the frames carry the network."""

    def test_network_in_the_frames(self):
        out = tempfile.mkdtemp(prefix="fdem_python_fluid.")
        self.addCleanup(shutil.rmtree, out, True)
        case = os.path.join(REPO, "cases", "sneddon", "case.toml")
        proc = subprocess.run([os.environ["FDEM_BINARY"], "run", case, "--set", "mesh.size=0.2",
                               "--set", "time.end=5e-4", "--set", f"output.dir={out}"],
                              capture_output=True, text=True)
        self.assertEqual(proc.returncode, 0, proc.stdout + proc.stderr)
        run = fdem.open(out)
        frames = run.frames
        self.assertEqual(frames["FLUID_PRESSURE"].attrs["units"], "Pa")
        self.assertEqual(frames["FLUID_APERTURE"].attrs["units"], "m")
        ce4 = run.block("cohesive")
        self.assertIn("FLUID_PRESSURE", ce4)
        rock = run.block("rock")
        self.assertTrue(np.all(np.nan_to_num(rock["FLUID_PRESSURE"].values) == 0))
        net = run.network(-1)
        self.assertEqual(net.sizes["elem"], 10)  # the crack's 10 segments, nothing else
        t = float(frames["time"].values[-1])
        np.testing.assert_allclose(net["FLUID_PRESSURE"].values, 1e6 * t / 2e-3, rtol=1e-6)
        self.assertTrue(np.all(net["FLUID_APERTURE"].values >= 1e-7))  # at least the residual
        self.assertTrue(np.all(np.abs(net["segment_y"].values) < 1e-3))
        self.assertLess(float(np.max(np.abs(net["segment_x"].values))), 1.0)
        # The frame at t = 0 comes before the first step's flow: no segment carries fluid.
        self.assertEqual(run.network(0).sizes["elem"], 0)


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


# ---------------------------------------------------------------------------------------
# Issue 34: edge and crack orientation roses, the UCS study driver.

STUDY = os.path.join(REPO, "tools", "ucs-study")


def load_study():
    import importlib.machinery
    import importlib.util
    loader = importlib.machinery.SourceFileLoader("ucs_study", STUDY)
    spec = importlib.util.spec_from_loader("ucs_study", loader)
    module = importlib.util.module_from_spec(spec)
    loader.exec_module(module)
    return module


def lattice_exodus(path, n=6, times=(0.0, 1.0)):
    """A strip of equilateral triangles (edges at 0, 60, 120 degrees) with a CE4 on each
    interior edge, in the engine's layout (each triangle its own nodes); one frame per time."""
    h = np.sqrt(3) / 2
    x, y, tris = [], [], []
    for i in range(n):
        for corners in (((i, 0), (i + 1, 0), (i + 0.5, h)), ((i + 1, 0), (i + 1.5, h), (i + 0.5, h))):
            base = len(x)
            for cx, cy in corners:
                x.append(cx)
                y.append(cy)
            tris.append([base, base + 1, base + 2])
    x, y = np.array(x, float), np.array(y, float)
    ce4 = []
    edges = {}
    for t in tris:
        for a, b in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
            key = tuple(sorted([(x[a], y[a]), (x[b], y[b])]))
            if key in edges:
                a2, b2 = edges[key]
                ce4.append([a, b, a2, b2])
            else:
                edges[key] = (b, a)
    write_exodus(path, x, y, [("rock", "TRI3", np.array(tris)), ("cohesive", "QUAD4", np.array(ce4))])
    with netCDF4.Dataset(path, "a") as ds:
        ds.variables["time_whole"][:] = np.array(times)
    return x, y, np.array(ce4)


class Roses(TempDirCase):
    def test_directions_histogram_and_lattice_share(self):
        from fdem import orientation
        a = orientation.directions([0, 0, 0, 0], [0, 0, 0, 0], [1, -1, 0, 1], [0, 0, 1, -1])
        np.testing.assert_allclose(a, [0, 0, 90, 135])
        np.testing.assert_allclose(orientation.histogram([0, 14.9, 15, 179.9]),
                                   [0.5, 0.25] + [0] * 9 + [0.25])
        self.assertAlmostEqual(orientation.lattice_share(np.linspace(0, 180, 1200, endpoint=False)), 0.5)
        self.assertAlmostEqual(orientation.lattice_share([1, 61, 121, 29, 89, 149]), 1.0)
        self.assertTrue(np.isnan(orientation.lattice_share([])))

    def test_mesh_rose_and_crack_rose(self):
        exo = os.path.join(self.dir, "ucs.exo")
        x, y, ce4 = lattice_exodus(exo)
        code, out = run_plot("mesh-rose", f"{exo}:strip", "-o", os.path.join(self.dir, "m.png"))
        self.assertEqual(code, 0, out)
        self.assertIn(f"strip: {len(ce4)} CE4s", out)
        self.assertIn("lattice share 100.0 %", out)
        self.assertPng(os.path.join(self.dir, "m.png"))
        # Breaks: the first three CE4s, modes I, II, mixed, at t = 0.5, 0.5 and 2.
        write_events(os.path.join(self.dir, "ucs_events.nc"), breaks={
            "break_time": (np.array([0.5, 0.5, 2.0]), "s"), "break_x": (np.zeros(3), "m"),
            "break_y": (np.zeros(3), "m"), "break_mode": (np.array([1, 2, 3], dtype=np.int32), ""),
            "break_ce4": (np.array([0, 1, 2], dtype=np.int32), "")})
        code, out = run_plot("cracks", exo, "--rose", "--events", os.path.join(self.dir, "ucs_events.nc"),
                             "-o", os.path.join(self.dir, "c.png"))
        self.assertEqual(code, 0, out)
        # Up to the last frame (t = 1): two breaks, one mode I and one mode II.
        self.assertIn("all broken CE4s (2)", out)
        self.assertIn("mode I (1)", out)
        self.assertIn("mixed (0)", out)
        self.assertPng(os.path.join(self.dir, "c.png"))
        code, out = run_plot("cracks", exo, "--events", os.path.join(self.dir, "ucs_events.nc"),
                             "-o", os.path.join(self.dir, "d.png"))
        self.assertEqual(code, 2)
        self.assertIn("--events goes with --rose", out)


class UcsStudy(TempDirCase):
    def test_curve_points_of_a_known_curve(self):
        study = load_study()
        strain = np.linspace(0, 6e-3, 601)
        # Linear (13 GPa) to 3e-3, a parabola to the peak at 4e-3, then down 20 GPa.
        stress = np.where(strain <= 3e-3, 13e9 * strain,
                          np.where(strain <= 4e-3, 39e6 + 13e9 * (strain - 3e-3) - 6.5e12 * (strain - 3e-3) ** 2,
                                   45.5e6 - 20e9 * (strain - 4e-3)))
        stress = np.maximum(stress, 0)
        p = study.curve_points(stress, strain, strain, None)
        self.assertAlmostEqual(p["peak"] / 1e6, 45.5, places=3)
        self.assertAlmostEqual(p["peak_strain"], 4e-3, places=9)
        self.assertAlmostEqual(p["modulus"] / 1e9, 13.0, places=6)
        # 1% below the line: 6.5e12 d^2 = 0.01 * (39e6 + 13e9 d - ...), d about 0.25e-3.
        self.assertTrue(3.2e-3 <= strain[p["a"]] <= 3.3e-3, strain[p["a"]])
        self.assertAlmostEqual(p["slope"] / 1e9, -20.0, places=6)
        self.assertAlmostEqual(strain[p["c"]], 4e-3 + 0.8 * 45.5e6 / 20e9, delta=1e-5)

    def test_summary_keeps_points_modes_and_breaks(self):
        """A run's summary (kept in the repository when its outputs are gone) gives the
        report the same points, modes and breaks as the run, on a thinned curve."""
        study = load_study()
        n = 10001
        strain = np.linspace(0, 6e-3, n)
        stress = np.where(strain <= 4e-3, 1e10 * strain, np.maximum(40e6 - 3e10 * (strain - 4e-3), 0))
        pts = study.curve_points(stress, strain, strain * 1e-3, None)
        breaks = dict(ce4=np.array([3, 9]), mode=np.array([1, 3]), time=np.array([1e-6, 2e-6]))
        d = dict(run={"name": "m-v0.1", "mesh": "m", "speed": 0.1, "frames": False}, status="done",
                 times=strain * 1e-3, strain=strain, stress=stress, points=pts,
                 modes={"A": None, "B": (1, 0, 0), "C": (1, 0, 1), "end": (1, 0, 1)}, breaks=breaks)
        study.write_summary(d, self.dir)
        s = study.read_summary(os.path.join(self.dir, "m-v0.1.json"))
        self.assertLessEqual(len(s["stress"]), study.SUMMARY_POINTS + 3)
        self.assertLess(len(s["stress"]), n)
        for key in ("a", "b", "c"):
            self.assertEqual(s["strain"][s["points"][key]], strain[pts[key]], key)
            self.assertEqual(s["stress"][s["points"][key]], stress[pts[key]], key)
        self.assertEqual(s["points"]["peak"], pts["peak"])
        self.assertEqual(s["modes"]["C"], (1, 0, 1))
        self.assertIsNone(s["modes"]["A"])
        np.testing.assert_array_equal(s["breaks"]["ce4"], [3, 9])
        np.testing.assert_array_equal(s["breaks"]["mode"], [1, 3])
        self.assertEqual(s["status"], "done")

    def test_plan_writes_a_script_bash_accepts(self):
        script = os.path.join(self.dir, "s.sh")
        proc = subprocess.run([sys.executable, STUDY, "plan", "--preset", "x8", "--dt", "1e-9", "-o", script],
                              capture_output=True, text=True)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        self.assertIn("delaunay-v0.025", proc.stdout)
        self.assertEqual(subprocess.run(["bash", "-n", script]).returncode, 0)
        with open(script) as f:
            text = f.read()
        self.assertIn("--max-wall", text)
        self.assertIn("'boundary.0.velocity=[0.0,-0.025]'", text)
        self.assertIn("'mesh.algorithm=\"delaunay\"'", text)
        with open(os.path.join(self.dir, "s.json")) as f:
            manifest = json.load(f)
        frames = [r["name"] for r in manifest["runs"] if r["frames"]]
        self.assertEqual(frames, ["delaunay-v0.025"])
        # 0.025 m/s each to strain 5.5e-3: t = 5.5e-3 * 0.1295 / 0.05 = 14.245 ms.
        run = next(r for r in manifest["runs"] if r["name"] == "delaunay-v0.025")
        self.assertAlmostEqual(run["t_end"], 14.245e-3, places=9)
        self.assertEqual(run["steps"], 14245000)
        proc = subprocess.run([sys.executable, STUDY, "plan", "--runs", "hexagons-v0.1", "--dt", "1e-9",
                               "-o", script], capture_output=True, text=True)
        self.assertEqual(proc.returncode, 2)
        self.assertIn("not MESH-vSPEED", proc.stderr)

    def test_report_on_synthetic_runs(self):
        study = load_study()
        runs = []
        for speed, gain in ((0.025, 1.0), (0.05, 1.03), (0.25, 1.1)):
            name = f"delaunay-v{speed:g}"
            folder = os.path.join(self.dir, name)
            os.makedirs(folder)
            strain = np.linspace(0, 6e-3, 301)
            peak = 45e6 * gain
            stress = np.where(strain <= 4e-3, peak * strain / 4e-3, np.maximum(peak - 30e9 * (strain - 4e-3), 0))
            closure = strain * study.HEIGHT
            times = np.linspace(0, 1e-2, 301)
            write_history(os.path.join(folder, "ucs_history.nc"), times, {
                "platen_top_force_y": (stress * study.WIDTH, "N"),
                "platen_top_disp_y": (-closure / 2, "m"), "platen_bottom_disp_y": (closure / 2, "m")})
            write_events(os.path.join(folder, "ucs_events.nc"), breaks={
                "break_time": (np.array([5e-3, 6e-3, 9e-3]), "s"), "break_x": (np.zeros(3), "m"),
                "break_y": (np.zeros(3), "m"), "break_mode": (np.array([1, 2, 2], dtype=np.int32), ""),
                "break_ce4": (np.array([0, 1, 2], dtype=np.int32), "")})
            lattice_exodus(os.path.join(folder, "ucs.exo"))
            open(os.path.join(folder, "done"), "w").close()
            runs.append(dict(name=name, mesh="delaunay", variant="", speed=speed, frames=False))
        # A slower run still on its way up: its largest stress is no peak, and the others
        # are not compared with it.
        folder = os.path.join(self.dir, "delaunay-v0.01")
        os.makedirs(folder)
        strain = np.linspace(0, 2e-3, 101)
        write_history(os.path.join(folder, "ucs_history.nc"), np.linspace(0, 1e-2, 101), {
            "platen_top_force_y": (45e6 * strain / 4e-3 * study.WIDTH, "N"),
            "platen_top_disp_y": (-strain * study.HEIGHT / 2, "m"),
            "platen_bottom_disp_y": (strain * study.HEIGHT / 2, "m")})
        runs.append(dict(name="delaunay-v0.01", mesh="delaunay", variant="", speed=0.01, frames=False))
        with open(os.path.join(self.dir, "manifest.json"), "w") as f:
            json.dump(dict(case="cases/ucs/case.toml", scale="full", runs=runs), f)
        out = os.path.join(self.dir, "report")
        proc = subprocess.run([sys.executable, STUDY, "report", self.dir, "-o", out], capture_output=True, text=True)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        with open(os.path.join(out, "report.md")) as f:
            text = f.read()
        self.assertIn("| delaunay-v0.025 | delaunay | 0.025 | done | 45 | 4 |", text)
        self.assertIn("delaunay-v0.25: peak +10.0% from the slowest with a peak (delaunay-v0.025)", text)
        self.assertIn("delaunay-v0.05: peak +3.0% from the slowest with a peak (delaunay-v0.025) "
                      "(quasi-static: within 5%)", text)
        self.assertNotIn("+10.0% from the slowest with a peak (delaunay-v0.025) (quasi-static", text)
        self.assertIn("| delaunay-v0.01 | delaunay | 0.01 | unfinished | ≥ 22.5 (so far) | – |", text)
        self.assertIn("- delaunay-v0.01: unfinished, before its peak (largest stress so far 22.5 MPa", text)
        self.assertNotIn("(delaunay-v0.01)", text)
        self.assertPng(os.path.join(out, "rate_delaunay.png"))


if __name__ == "__main__":
    unittest.main()
