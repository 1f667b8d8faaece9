"""Fragments per frame out of NAME_fragments.nc (as fdem.open(...).fragments reads it).

The file is a contiguous ragged array: one record per fragment per frame along the
unlimited dimension `fragment_record`, a frame's records together, with the variables
fragment_frame (0-based frame index, as the Exodus time steps), fragment_time [s],
fragment_id, fragment_triangles, fragment_area [m2], fragment_mass [kg], fragment_x,
fragment_y [m] (centre of mass) and fragment_diameter [m] (sqrt(4 area / pi)); the
layout is in docs/case-format.md ("Fragments file"). The reader is tolerant: without
fragment_frame the frames are told apart by fragment_time, without fragment_diameter
the size is the equivalent diameter of fragment_area, and without fragment_mass the
area (then the count) weighs the fragments.
"""

from typing import List, Tuple

import numpy as np

from . import analytics

__all__ = ["frames", "frame_of_records", "at_frame", "sizes_and_masses", "summary"]


def _record_dim(ds) -> str:
    for name in ("fragment_frame", "fragment_time", "fragment_area", "fragment_diameter"):
        if name in ds.variables and ds[name].dims:
            return ds[name].dims[0]
    raise ValueError("not a fragments file: none of fragment_frame, fragment_time, "
                     "fragment_area, fragment_diameter in it")


def frame_of_records(ds) -> np.ndarray:
    """Frame index of every record."""
    if "fragment_frame" in ds.variables:
        return np.asarray(ds["fragment_frame"].values, dtype=np.int64)
    if "fragment_time" in ds.variables:
        t = np.asarray(ds["fragment_time"].values, dtype=float)
        _, index = np.unique(t, return_inverse=True)
        return index.astype(np.int64)
    return np.zeros(ds.sizes[_record_dim(ds)], dtype=np.int64)


def frames(ds) -> List[Tuple[int, float]]:
    """(frame index, time [s]) of every frame the file has records for, in order."""
    frame = frame_of_records(ds)
    time = (np.asarray(ds["fragment_time"].values, dtype=float)
            if "fragment_time" in ds.variables else np.full(len(frame), np.nan))
    out = []
    for k in np.unique(frame):
        first = int(np.flatnonzero(frame == k)[0])
        out.append((int(k), float(time[first])))
    return out


def at_frame(ds, frame: int = -1):
    """The records of one frame (an xarray.Dataset along the record dimension). `frame`
    is a frame index as in the Exodus file; negative counts from the last frame that has
    records (-1: the last)."""
    present = frames(ds)
    if not present:
        raise ValueError("the fragments file has no records yet")
    indices = [k for k, _ in present]
    if frame < 0:
        if -frame > len(indices):
            raise ValueError(f"frame {frame}: the fragments file has {len(indices)} frames")
        frame = indices[frame]
    if frame not in indices:
        shown = ", ".join(map(str, indices[:12])) + (", ..." if len(indices) > 12 else "")
        raise ValueError(f"no fragments recorded at frame {frame}; frames: {shown}")
    dim = _record_dim(ds)
    return ds.isel({dim: np.flatnonzero(frame_of_records(ds) == frame)})


def sizes_and_masses(records):
    """(size [m], mass) per fragment of a frame's records: fragment_diameter (else the
    equivalent diameter of fragment_area) and fragment_mass (else area, else 1)."""
    if "fragment_diameter" in records.variables:
        size = np.asarray(records["fragment_diameter"].values, dtype=float)
    elif "fragment_area" in records.variables:
        size = analytics.equivalent_diameter(records["fragment_area"].values)
    else:
        raise ValueError("the fragments file has neither fragment_diameter nor fragment_area")
    for name in ("fragment_mass", "fragment_area"):
        if name in records.variables:
            return size, np.asarray(records[name].values, dtype=float)
    return size, np.ones_like(size)


def summary(ds, without_largest: bool = False):
    """Per frame: time, fragments, P50 and P80 [m] (mass passing), as an xarray.Dataset
    on the dimension `frame`; with `without_largest`, each frame's largest piece (by
    mass: the body the others broke off) left out (P50, P80 NaN where none is left)."""
    import xarray as xr
    rows = []
    for k, t in frames(ds):
        size, mass = sizes_and_masses(at_frame(ds, k))
        if without_largest and len(size):
            largest = int(np.argmax(mass))
            size, mass = np.delete(size, largest), np.delete(mass, largest)
        try:
            p50 = analytics.percentile_size(size, mass, 0.5)
            p80 = analytics.percentile_size(size, mass, 0.8)
        except ValueError:
            p50 = p80 = np.nan
        rows.append((k, t, len(size), p50, p80))
    k, t, n, p50, p80 = (np.array(c) for c in zip(*rows)) if rows else [np.zeros(0)] * 5
    return xr.Dataset(
        {"time": ("frame", t, {"units": "s"}),
         "fragments": ("frame", n.astype(np.int64), {"long_name": "fragments"}),
         "p50": ("frame", p50, {"units": "m", "long_name": "size with 50% of the mass finer"}),
         "p80": ("frame", p80, {"units": "m", "long_name": "size with 80% of the mass finer"})},
        coords={"frame": ("frame", k.astype(np.int64))})
