"""`fdem.open`: one fdem-cl run's output files as xarray objects.

A run named NAME (the case's `output.name`) writes into its output folder OUT:

    OUT/NAME.exo            frames: Exodus II mesh, displacements, element variables
    OUT/NAME_history.nc     history: one variable per quantity on `time`
    OUT/NAME_events.nc      breaks and events (fracture runs)
    OUT/NAME_fragments.nc   fragments per frame (fracture runs)

`open(OUT)` finds NAME when the folder holds one run; `open("OUT/NAME")` (or the path
of any of the four files) picks one run of a folder that holds several. Every file is
read when first asked for, and kept.
"""

import os
from typing import Dict, List, Optional

import numpy as np

from . import load

__all__ = ["Run", "open", "run_files"]

# Suffix of each output file after NAME.
SUFFIXES = {"frames": ".exo", "history": "_history.nc", "events": "_events.nc",
            "fragments": "_fragments.nc"}


def _xarray():
    try:
        import xarray as xr
    except ImportError as exc:
        raise ImportError("fdem.open needs the xarray module: on Debian install "
                          "python3-xarray and run with /usr/bin/python3") from exc
    return xr


def _split(path: str):
    """(folder, NAME) when `path` is one of a run's files, else None."""
    base = os.path.basename(path)
    # Longest suffix first: NAME_history.nc before a bare .nc.
    for suffix in sorted(SUFFIXES.values(), key=len, reverse=True):
        if base.endswith(suffix) and len(base) > len(suffix):
            return os.path.dirname(path) or ".", base[:-len(suffix)]
    return None


def run_names(folder: str) -> List[str]:
    """NAMEs of the runs whose files are in `folder`, sorted."""
    names = set()
    for entry in os.listdir(folder):
        split = _split(os.path.join(folder, entry))
        if split is not None:
            names.add(split[1])
    return sorted(names)


def run_files(path: str, name: Optional[str] = None) -> Dict[str, str]:
    """Paths of the four output files of one run ({"frames": ..., "history": ...,
    "events": ..., "fragments": ...}), present or not; FileNotFoundError when none is."""
    path = os.fspath(path)
    if os.path.isdir(path):
        folder = path
        if name is None:
            names = run_names(folder)
            if not names:
                raise FileNotFoundError(f"{folder}: no fdem-cl output in it (no NAME.exo or "
                                        f"NAME_history.nc)")
            if len(names) > 1:
                raise ValueError(f"{folder} holds the output of several runs "
                                 f"({', '.join(names)}): open {os.path.join(folder, names[0])} "
                                 f"or pass name=")
            name = names[0]
    else:
        split = _split(path) if os.path.isfile(path) else None
        folder, name = split if split else (os.path.dirname(path) or ".", os.path.basename(path))
    files = {kind: os.path.join(folder, name + suffix) for kind, suffix in SUFFIXES.items()}
    if not any(os.path.isfile(f) for f in files.values()):
        raise FileNotFoundError(f"{path}: no such fdem-cl output (looked for "
                                f"{', '.join(os.path.basename(f) for f in files.values())} "
                                f"in {folder})")
    return files


def open_netcdf(path: str):
    """A netCDF file as an xarray.Dataset read into memory (the file is closed again, so a
    run still writing it is not disturbed). Times stay in seconds (no date decoding)."""
    xr = _xarray()
    with xr.open_dataset(path, engine="netcdf4", decode_times=False) as ds:
        return ds.load()


def _dims_of(ds, dim: str) -> List[str]:
    return [name for name, var in ds.data_vars.items() if var.dims and var.dims[0] == dim]


class Run:
    """The output of one run. Attributes are read on first use:

    history    xarray.Dataset on `time` [s], one variable per history quantity, each
               with its `units` and `long_name` from the file
    frames     xarray.Dataset of the Exodus file (fdem.load.to_xarray): dimensions time,
               node, elem (blocks concatenated; coordinates `block`, `block_elem`);
               DISPLX... on (time, node), SXX... on (time, elem), `connectivity`;
               block(name) / blocks: the same for one element block's elements;
               positions(frame): the current node coordinates;
               network(frame): with [fluid], the segments carrying fluid (FLUID_PRESSURE,
               FLUID_APERTURE on the cohesive block) and their midpoints
    events     xarray.Dataset of NAME_events.nc (dimension `break`: break_time, break_x,
               break_y, break_length, break_mode, break_energy...; dimension `event`:
               event_start, event_end, event_x, event_y, event_breaks, event_energy,
               event_magnitude), or None when the run wrote no events file
    fragments  xarray.Dataset of NAME_fragments.nc, or None when absent; with the
               run's NAME.exo beside it, each record also carries fragment_material
               and fragment_fracturable (fdem.fragments.label_materials), so that the
               fragment statistics leave the platens and other non-fracturable
               bodies out
    """

    def __init__(self, path, name: Optional[str] = None):
        self.files = run_files(path, name)
        first = next(iter(self.files.values()))
        self.folder = os.path.dirname(first)
        self.name = os.path.basename(self.files["frames"])[:-len(SUFFIXES["frames"])]
        self._cache = {}

    def __repr__(self):
        have = [k for k, f in self.files.items() if os.path.isfile(f)]
        return f"<fdem.Run {self.name!r} in {self.folder}: {', '.join(have)}>"

    def has(self, kind: str) -> bool:
        return os.path.isfile(self.files[kind])

    def _need(self, kind: str) -> str:
        path = self.files[kind]
        if not os.path.isfile(path):
            raise FileNotFoundError(f"{path}: no such file (run {self.name!r} in {self.folder} "
                                    f"has no {kind})")
        return path

    def _cached(self, key, make):
        if key not in self._cache:
            self._cache[key] = make()
        return self._cache[key]

    @property
    def history(self):
        return self._cached("history", lambda: read_history(self._need("history")))

    @property
    def exodus(self) -> load.ExodusData:
        """The frames as numpy arrays (fdem.load.ExodusData), per block."""
        return self._cached("exodus", lambda: load.load_exodus(self._need("frames")))

    @property
    def frames(self):
        return self._cached("frames", lambda: load.to_xarray(self.exodus))

    def block(self, name: str):
        """The frames restricted to the elements of one block (e.g. "rock", "cohesive"),
        with the connectivity as wide as that block's elements."""
        frames = self.frames
        names = [b.name for b in self.exodus.blocks]
        if name not in names:
            raise KeyError(f"no block {name!r} in {self.files['frames']}; blocks: "
                           f"{', '.join(names) or 'none'}")
        width = next(b.connectivity.shape[1] for b in self.exodus.blocks if b.name == name)
        mask = np.asarray(frames["block"].values == name)
        part = frames.isel(elem=np.flatnonzero(mask), corner=slice(0, width))
        # Element variables the truth table leaves out of this block are all NaN there.
        drop = [v for v, da in part.data_vars.items()
                if "elem" in da.dims and "time" in da.dims and da.size
                and bool(np.all(np.isnan(da.values)))]
        return part.drop_vars(drop)

    @property
    def blocks(self):
        """{block name: run.block(name)} for every element block, in file order."""
        return self._cached("blocks", lambda: {b.name: self.block(b.name)
                                               for b in self.exodus.blocks})

    def network(self, frame: int = -1):
        """The fluid network of a [fluid] run at a frame: the cohesive block's segments
        that carry fluid (FLUID_APERTURE > 0), with FLUID_PRESSURE [Pa] (the mean of the
        segment's two vertices), FLUID_APERTURE [m] (its mean aperture, residual included)
        and each segment's current midpoint `segment_x`, `segment_y` [m] (mean of its four
        nodes), on the dimension `elem`."""
        ce4 = self.block("cohesive")
        if "FLUID_PRESSURE" not in ce4:
            raise KeyError(f"{self.files['frames']} has no FLUID_PRESSURE: the run had no [fluid]")
        f = ce4.isel(time=frame)
        keep = np.flatnonzero(f["FLUID_APERTURE"].values > 0)
        f = f.isel(elem=keep)
        x, y = self.positions(frame)
        corners = f["connectivity"].values
        mid_x = x.values[corners].mean(axis=1)
        mid_y = y.values[corners].mean(axis=1)
        return f[["FLUID_PRESSURE", "FLUID_APERTURE"]].assign(
            segment_x=("elem", mid_x, {"units": "m"}), segment_y=("elem", mid_y, {"units": "m"}))

    def positions(self, frame: int = -1):
        """Current node coordinates at a frame: x + DISPLX, y + DISPLY (DataArrays on
        `node`, m)."""
        f = self.frames.isel(time=frame)
        x, y = f["x"] + f["DISPLX"], f["y"] + f["DISPLY"]
        return (x.rename("x_current").assign_attrs(units="m"),
                y.rename("y_current").assign_attrs(units="m"))

    @property
    def events(self):
        if not self.has("events"):
            return None
        return self._cached("events", lambda: read_events(self.files["events"]))

    @property
    def breaks(self):
        """The `break` part of events (None without an events file)."""
        ev = self.events
        return None if ev is None else ev[_dims_of(ev, "break")]

    @property
    def fragments(self):
        if not self.has("fragments"):
            return None
        return self._cached("fragments", lambda: read_fragments(
            self.files["fragments"], self.files["frames"] if self.has("frames") else None))


def open(path, name: Optional[str] = None) -> Run:  # noqa: A001 - fdem.open reads well
    """The output of one run: `path` is its output folder (with `name` when the folder
    holds several runs), OUT/NAME, or the path of one of its files."""
    return Run(path, name)


def read_history(path: str):
    """NAME_history.nc as an xarray.Dataset on `time` [s]."""
    ds = open_netcdf(path)
    if "time" not in ds.variables:
        raise ValueError(f"{path} has no 'time' variable: not an fdem-cl history file")
    return ds


BREAK_VARS = ["break_time", "break_x", "break_y", "break_length", "break_mode",
              "break_energy"]
EVENT_VARS = ["event_start", "event_end", "event_x", "event_y", "event_breaks",
              "event_energy", "event_magnitude"]


def read_events(path: str):
    """NAME_events.nc as one xarray.Dataset with the dimensions `break` and `event`.
    A file without one of the two dimensions gets it empty, so code that reads
    break_time or event_magnitude finds zero-length arrays rather than a KeyError."""
    ds = open_netcdf(path)
    xr = _xarray()
    for dim, names in (("break", BREAK_VARS), ("event", EVENT_VARS)):
        missing = [v for v in names if v not in ds.variables]
        if dim not in ds.dims and len(missing) == len(names):
            ds = ds.assign({v: xr.DataArray(np.zeros(0), dims=(dim,)) for v in names})
    return ds


def read_fragments(path: str, exodus: Optional[str] = None):
    """NAME_fragments.nc as an xarray.Dataset (fdem.fragments reads sizes out of it),
    labelled with the materials of the run's Exodus file `exodus` when given
    (fdem.fragments.label_materials)."""
    ds = open_netcdf(path)
    if exodus is not None and ds.sizes.get("fragment_record", 0) and "fragment_id" in ds:
        from . import fragments
        try:
            ds = fragments.label_materials(ds, exodus)
        except (OSError, KeyError) as exc:
            raise ValueError(f"cannot read the element blocks of {exodus} to tell rock "
                             f"from other bodies ({exc})") from exc
        except ValueError as exc:
            raise ValueError(f"{path} and {exodus}: {exc}") from exc
    return ds

