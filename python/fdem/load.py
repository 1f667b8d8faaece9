"""Load fdem-cl output into numpy arrays.

Exodus files are plain netCDF, but read raw they are awkward: names are NUL-padded char
arrays that come back as bytes, connectivity is 1-based and split over one variable per
block, and variables are numbered rather than named. `load_exodus` undoes all that;
`load_history` reads the CF time-history file. Needs the netCDF4 and numpy modules
(Debian: python3-netcdf4, for /usr/bin/python3).

    from fdem.load import load_exodus   # tools/fdem_load.py: the same, for old scripts
    exo = load_exodus("out.exo")
    exo.times, exo.x, exo.blocks[0].connectivity, exo.nodal["DISPLX"][-1]
    exo.element_values("SXX", frame=-1)   # all blocks, concatenated

Part of the `fdem` package (python/fdem); `fdem.open` builds its xarray views on these.
"""

from dataclasses import dataclass, field
from typing import Dict, List

import re

import numpy as np

try:
    import netCDF4
except ImportError as exc:  # pragma: no cover - depends on the interpreter
    raise ImportError(
        "fdem_load needs the netCDF4 module; on Debian install python3-netcdf4 and "
        "run with /usr/bin/python3") from exc

__all__ = ["Block", "ExodusData", "HistoryData", "load_exodus", "load_blocks", "load_history",
           "to_xarray", "exodus_units"]

# Exodus files carry no units: those of fdem-cl's variable names (SI, as the engine
# computes; "1" for dimensionless and for flags and codes).
_EXODUS_UNITS = [
    (re.compile(r"^(S(XX|YY|XY)|PS[12]|FLUID_PRESSURE)$"), "Pa"),
    (re.compile(r"^DISPL[XY]$|^(OPENING|SLIP|FLUID_APERTURE)$"), "m"),
    (re.compile(r"^VEL[XY]$"), "m/s"),
    (re.compile(r"^CONTACT_F[XY]$"), "N"),
    (re.compile(r"^(DAMAGE|BROKEN|MODE|FRAGMENT|JOINT|GRAIN)$"), "1"),
]


def exodus_units(name: str) -> str:
    """SI units of an fdem-cl Exodus variable, "" when the name is not one of the
    engine's."""
    for pattern, unit in _EXODUS_UNITS:
        if pattern.match(name):
            return unit
    return ""


@dataclass
class Block:
    """One element block: its name, Exodus id and type, and 0-based connectivity."""
    name: str
    id: int
    elem_type: str
    connectivity: np.ndarray  # (num_elem, nodes_per_elem), 0-based node indices

    @property
    def num_elem(self) -> int:
        return int(self.connectivity.shape[0])


@dataclass
class ExodusData:
    path: str
    title: str
    x: np.ndarray  # (num_nodes,)
    y: np.ndarray
    blocks: List[Block]
    times: np.ndarray  # (num_frames,)
    nodal: Dict[str, np.ndarray] = field(default_factory=dict)  # name -> (frames, nodes)
    # name -> one (frames, num_elem of the block) array per block; all NaN where the
    # truth table says the variable does not exist on that block.
    element: Dict[str, List[np.ndarray]] = field(default_factory=dict)

    @property
    def num_frames(self) -> int:
        return int(self.times.shape[0])

    @property
    def coordinates(self) -> np.ndarray:
        """(num_nodes, 2) array of x, y."""
        return np.column_stack([self.x, self.y])

    def element_values(self, name: str, frame: int = -1) -> np.ndarray:
        """Values of element variable `name` at `frame`, blocks concatenated in order."""
        if name not in self.element:
            raise KeyError(f"no element variable {name!r} in {self.path}; available: "
                           f"{', '.join(self.element) or 'none'}")
        return np.concatenate([v[frame] for v in self.element[name]])


@dataclass
class HistoryData:
    path: str
    title: str
    times: np.ndarray
    values: Dict[str, np.ndarray]
    units: Dict[str, str]
    long_names: Dict[str, str]
    # Numeric attributes per variable, e.g. a probe's {"probe_point": array([x, y]),
    # "probe_element": array([e])}; empty for most variables.
    attributes: Dict[str, Dict[str, np.ndarray]] = field(default_factory=dict)


def _names(ds, var: str) -> List[str]:
    """Rows of a (count, len) char variable as str, NUL padding removed."""
    if var not in ds.variables:
        return []
    raw = np.asarray(ds.variables[var][:])
    names = []
    for row in raw.reshape(raw.shape[0], -1):
        text = np.asarray(row, dtype="S1").tobytes()
        names.append(text.split(b"\0", 1)[0].decode("utf-8", errors="replace").strip())
    return names


def _dim(ds, name: str) -> int:
    return len(ds.dimensions[name]) if name in ds.dimensions else 0


def _text_attr(obj, name: str, default: str = "") -> str:
    try:
        value = obj.getncattr(name)
    except AttributeError:
        return default
    if isinstance(value, bytes):
        value = value.decode("utf-8", errors="replace")
    return str(value)


def _blocks(ds) -> List[Block]:
    """The element blocks of an open Exodus dataset (raw mode), in file order."""
    num_blocks = _dim(ds, "num_el_blk")
    block_names = _names(ds, "eb_names")
    ids = (np.asarray(ds.variables["eb_prop1"][:]).tolist()
           if "eb_prop1" in ds.variables else list(range(1, num_blocks + 1)))
    blocks = []
    for b in range(num_blocks):
        n = b + 1
        var = ds.variables.get(f"connect{n}")
        if var is None:  # a block with no elements has no connectivity variable
            conn = np.zeros((0, max(_dim(ds, f"num_nod_per_el{n}"), 1)), dtype=np.int64)
            elem_type = ""
        else:
            conn = np.asarray(var[:], dtype=np.int64).reshape(
                _dim(ds, f"num_el_in_blk{n}"), -1) - 1
            elem_type = _text_attr(var, "elem_type")
        name = block_names[b] if b < len(block_names) and block_names[b] else f"block_{ids[b]}"
        blocks.append(Block(name=name, id=int(ids[b]), elem_type=elem_type.upper(),
                            connectivity=conn))
    return blocks


def load_blocks(path: str) -> List[Block]:
    """The element blocks of an Exodus file (names, types, connectivity) without its
    frames: cheap on a large file."""
    with netCDF4.Dataset(path, "r") as ds:
        ds.set_auto_mask(False)
        ds.set_auto_chartostring(False)
        return _blocks(ds)


def load_exodus(path: str) -> ExodusData:
    """Reads a whole Exodus II file (every frame) into an ExodusData."""
    with netCDF4.Dataset(path, "r") as ds:
        # Raw arrays: no masking (NUL name padding would be masked) and no char->str.
        ds.set_auto_mask(False)
        ds.set_auto_chartostring(False)
        x = np.asarray(ds.variables["coordx"][:], dtype=float)
        y = (np.asarray(ds.variables["coordy"][:], dtype=float)
             if "coordy" in ds.variables else np.zeros_like(x))
        blocks = _blocks(ds)

        times = (np.asarray(ds.variables["time_whole"][:], dtype=float)
                 if "time_whole" in ds.variables else np.zeros(0))
        num_frames = times.shape[0]

        nodal = {}
        for k, name in enumerate(_names(ds, "name_nod_var"), start=1):
            nodal[name] = np.asarray(ds.variables[f"vals_nod_var{k}"][:], dtype=float)

        element = {}
        for k, name in enumerate(_names(ds, "name_elem_var"), start=1):
            per_block = []
            for b, blk in enumerate(blocks, start=1):
                var = ds.variables.get(f"vals_elem_var{k}eb{b}")
                if var is None:
                    per_block.append(np.full((num_frames, blk.num_elem), np.nan))
                else:
                    per_block.append(np.asarray(var[:], dtype=float).reshape(num_frames, -1))
            element[name] = per_block

        return ExodusData(path=str(path), title=_text_attr(ds, "title"), x=x, y=y,
                          blocks=blocks, times=times, nodal=nodal, element=element)


def load_history(path: str) -> HistoryData:
    """Reads a time-history file written by fdem-cl (one variable per quantity)."""
    with netCDF4.Dataset(path, "r") as ds:
        ds.set_auto_mask(False)
        if "time" not in ds.variables:
            raise ValueError(f"{path} has no 'time' variable: not an fdem-cl history file")
        times = np.asarray(ds.variables["time"][:], dtype=float)
        values, units, long_names, attributes = {}, {}, {}, {}
        for name, var in ds.variables.items():
            if name == "time" or var.dimensions != ("time",):
                continue
            values[name] = np.asarray(var[:], dtype=float)
            units[name] = _text_attr(var, "units")
            long_names[name] = _text_attr(var, "long_name", name)
            attributes[name] = {a: np.asarray(var.getncattr(a), dtype=float).ravel()
                                for a in var.ncattrs()
                                if not isinstance(var.getncattr(a), (str, bytes))}
        return HistoryData(path=str(path), title=_text_attr(ds, "title"), times=times,
                           values=values, units=units, long_names=long_names,
                           attributes=attributes)


def to_xarray(path_or_exo):
    """An xarray.Dataset of an Exodus file (a path or an ExodusData) with readable names.

    Dimensions: time, node, elem (all blocks concatenated in block order). Coordinates:
    time (s), x and y (per node, m), block (name per element) and block_elem (index of
    the element in its block). Data: each nodal variable on (time, node), each element
    variable on (time, elem) (NaN on blocks that do not have it), and connectivity on
    (elem, corner) 0-based, padded with -1 where blocks have fewer nodes per element.
    Each variable's `units` attribute is from exodus_units (Exodus stores none).
    """
    try:
        import xarray as xr
    except ImportError as exc:
        raise ImportError("to_xarray needs the xarray module (Debian: python3-xarray); "
                          "load_exodus works without it") from exc
    exo = path_or_exo if isinstance(path_or_exo, ExodusData) else load_exodus(path_or_exo)
    width = max((b.connectivity.shape[1] for b in exo.blocks), default=0)
    conn = np.full((sum(b.num_elem for b in exo.blocks), width), -1, dtype=np.int64)
    row = 0
    for b in exo.blocks:
        conn[row:row + b.num_elem, :b.connectivity.shape[1]] = b.connectivity
        row += b.num_elem
    if exo.blocks:
        block_of_elem = np.concatenate([np.full(b.num_elem, b.name, dtype=object)
                                        for b in exo.blocks])
        index_in_block = np.concatenate([np.arange(b.num_elem) for b in exo.blocks])
    else:
        block_of_elem, index_in_block = np.zeros(0, dtype=object), np.zeros(0, dtype=np.int64)

    def attrs(name):
        unit = exodus_units(name)
        return {"units": unit} if unit else {}

    data = {name: (("time", "node"), v, attrs(name)) for name, v in exo.nodal.items()}
    for name, per_block in exo.element.items():
        data[name] = (("time", "elem"), np.concatenate(per_block, axis=1), attrs(name))
    data["connectivity"] = (("elem", "corner"), conn,
                            {"long_name": "0-based node indices, -1 padding"})
    coords = {
        "time": ("time", exo.times, {"units": "s", "standard_name": "time"}),
        "x": ("node", exo.x, {"units": "m", "long_name": "initial x"}),
        "y": ("node", exo.y, {"units": "m", "long_name": "initial y"}),
        "block": ("elem", block_of_elem),
        "block_elem": ("elem", index_in_block),
    }
    element_types = {b.name: b.elem_type for b in exo.blocks}
    return xr.Dataset(data, coords=coords,
                      attrs={"title": exo.title, "source": exo.path,
                             "blocks": ", ".join(f"{k} ({v})" for k, v in element_types.items())})
