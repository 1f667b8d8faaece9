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

Rock and the other bodies. The file counts every connected piece of the model, the
steel platens of a Brazilian or UCS test as much as the rock: a platen is a piece from
the first frame, and being heavy it would be the P50 of every frame. The fragments file
does not say which material a piece is of; the Exodus file of the same run does.
`label_materials` reads its element blocks (one per material, named after it) and adds
to every record `fragment_material` (the block of the piece's first triangle, whose
element number is the piece's id) and `fragment_fracturable` (1 when that block's
triangles are joined by CE4s: their nodes are nodes of the `cohesive` block. A piece
is all of fracturable triangles or all of others, since fracturable triangles own their
nodes and join nothing but CE4s). `fdem.open(OUT).fragments` is labelled when the run's
`.exo` is there, and the statistics here (`sizes_and_masses`, `summary`) leave the
pieces of non-fracturable materials out by default (`include_unfracturable=True` keeps
them). Without the labels (a fragments file read on its own) every piece counts.
"""

from typing import List, Tuple

import numpy as np

from . import analytics

__all__ = ["frames", "frame_of_records", "at_frame", "sizes_and_masses", "summary",
           "fracturable_blocks", "label_materials", "is_labelled", "left_out"]

COHESIVE_BLOCK = "cohesive"


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


def fracturable_blocks(blocks) -> List[Tuple[str, int, int, bool]]:
    """(name, first id, last id, fracturable) of every TRI3 block of an Exodus file's
    blocks (fdem.load.Block list, file order); ids are 1-based element numbers in the
    file's order, as fragment ids are. A block is fracturable when its triangles' nodes
    are nodes of the `cohesive` block's CE4s."""
    cohesive = [b for b in blocks if b.name == COHESIVE_BLOCK]
    ce4_nodes = (np.unique(np.concatenate([b.connectivity.ravel() for b in cohesive]))
                 if cohesive else np.zeros(0, dtype=np.int64))
    out, first = [], 1
    for b in blocks:
        if b.name != COHESIVE_BLOCK and b.num_elem:
            fracturable = bool(np.isin(b.connectivity.ravel(), ce4_nodes).any())
            out.append((b.name, first, first + b.num_elem - 1, fracturable))
        first += b.num_elem
    return out


def label_materials(ds, blocks):
    """`ds` (a fragments dataset) with the record variables `fragment_material` (the
    name of the block holding the piece's first triangle) and `fragment_fracturable`
    (1 or 0) from the run's Exodus blocks (a path, or fdem.load.Block list). Raises
    ValueError when an id lies in no TRI3 block (the files of two different runs)."""
    if isinstance(blocks, (str, bytes)) or hasattr(blocks, "__fspath__"):
        from . import load
        blocks = load.load_blocks(blocks)
    table = fracturable_blocks(blocks)
    dim = _record_dim(ds)
    if "fragment_id" not in ds.variables:
        raise ValueError("the fragments file has no fragment_id: its pieces cannot be "
                         "matched to materials")
    ids = np.asarray(ds["fragment_id"].values, dtype=np.int64)
    material = np.full(len(ids), "", dtype=object)
    fracturable = np.zeros(len(ids), dtype=np.int8)
    found = np.zeros(len(ids), dtype=bool)
    for name, lo, hi, frac in table:
        inside = (ids >= lo) & (ids <= hi)
        material[inside], fracturable[inside], found[inside] = name, int(frac), True
    if not found.all():
        bad = int(ids[np.flatnonzero(~found)[0]])
        last = max((hi for _, _, hi, _ in table), default=0)
        raise ValueError(f"fragment id {bad} is no triangle of the Exodus file (TRI3 "
                         f"elements 1 to {last}): the two files are not of the same run")
    return ds.assign(
        fragment_material=(dim, material.astype(str),
                           {"long_name": "material (Exodus block) of the piece"}),
        fragment_fracturable=(dim, fracturable,
                              {"long_name": "1: a piece of a fracturable material"}))


def is_labelled(ds) -> bool:
    """Whether `ds` carries label_materials' variables."""
    return "fragment_fracturable" in ds.variables


def _rock_only(records, include_unfracturable):
    if include_unfracturable or not is_labelled(records):
        return records
    dim = _record_dim(records)
    keep = np.asarray(records["fragment_fracturable"].values) != 0
    return records.isel({dim: np.flatnonzero(keep)})


def left_out(records) -> List[str]:
    """Materials of the records that the statistics leave out by default (sorted)."""
    if not is_labelled(records):
        return []
    keep = np.asarray(records["fragment_fracturable"].values) != 0
    return sorted(set(np.asarray(records["fragment_material"].values)[~keep].tolist()))


def sizes_and_masses(records, include_unfracturable: bool = False):
    """(size [m], mass) per fragment of a frame's records: fragment_diameter (else the
    equivalent diameter of fragment_area) and fragment_mass (else area, else 1). Pieces
    of non-fracturable materials (platens) are left out when the records are labelled
    (label_materials), unless `include_unfracturable`."""
    records = _rock_only(records, include_unfracturable)
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


def summary(ds, without_largest: bool = False, include_unfracturable: bool = False):
    """Per frame: time, fragments, P50 and P80 [m] (mass passing), as an xarray.Dataset
    on the dimension `frame`; with `without_largest`, each frame's largest piece (by
    mass: the body the others broke off) left out (P50, P80 NaN where none is left).
    Pieces of non-fracturable materials are left out of a labelled dataset
    (label_materials) unless `include_unfracturable`."""
    import xarray as xr
    rows = []
    for k, t in frames(ds):
        size, mass = sizes_and_masses(at_frame(ds, k), include_unfracturable)
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
