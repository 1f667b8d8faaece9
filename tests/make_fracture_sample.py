#!/usr/bin/python3
"""Writes a small fracture run's output for tests/test_tools.sh, until the engine does.

  make_fracture_sample.py DIR   ->  DIR/fracture.exo, DIR/fracture_history.nc

fracture.exo follows the layout of the C++ writer's tiny.exo (tests/test_exodus.cpp:
CDF-2, the same dimensions, variables and attributes) with the blocks an engine run with
cohesive fracture writes: TRI3 blocks "rock" (split: every triangle owns its three
nodes) and "steel" (a platen, shared nodes), then a QUAD4 block "cohesive" with one CE4
(i, j, j', i') per interior rock edge. Element variables SXX SYY SXY PS1 PS2 DAMAGE
BROKEN MODE OPENING SLIP on every block, nodal DISPLX DISPLY VELX VELY.

Three frames, t = 0, 1 ms, 2 ms: a vertical crack at x = 20 mm opens (the right half
moves +x); frame 1 has the middle 4 of its 8 CE4s broken in mode I, frame 2 all 8 in
mode I plus two diagonal CE4s in mode II and one in mixed mode (BROKEN_AT_LAST below).

fracture_history.nc: a Brazilian-like platen force with a known peak. With the values in
PEAK below, the indirect tensile stress 2F/(pi D t) peaks at exactly PEAK["sigma_t"] and
the UCS stress F/(W t) at PEAK["ucs"].
"""

import sys

import numpy as np
import netCDF4

LEN_NAME = 33
SIDE, N = 0.04, 8                     # rock square [m], squares per side
H = SIDE / N
TIMES = [0.0, 1.0e-3, 2.0e-3]
OPENING = [0.0, 0.2e-3, 0.6e-3]        # crack opening per frame [m]
D, THICKNESS, WIDTH = 0.0517, 0.02595, 0.0517
PEAK = {"sigma_t": 1.77e6, "row": 60, "rows": 101, "dt": 2.0e-5, "v": 0.025}
PEAK["force"] = PEAK["sigma_t"] * np.pi * D * THICKNESS / 2.0
PEAK["ucs"] = PEAK["force"] / (WIDTH * THICKNESS)
BROKEN_AT_LAST = {"mode1": 8, "mode2": 2, "mixed": 1}


def rock_mesh():
    """Split TRI3 mesh of the square and its CE4s (i, j, j', i')."""
    xy, tris, edge_owner = [], [], {}
    for iy in range(N):
        for ix in range(N):
            corners = [(ix, iy), (ix + 1, iy), (ix + 1, iy + 1), (ix, iy + 1)]
            for tri in ((0, 1, 2), (0, 2, 3)):
                ids = []
                for c in tri:
                    ids.append(len(xy))
                    xy.append((corners[c][0] * H, corners[c][1] * H))
                tris.append(ids)
                grid = [corners[c] for c in tri]
                for k in range(3):
                    a, b = k, (k + 1) % 3
                    key = tuple(sorted((grid[a], grid[b])))
                    edge_owner.setdefault(key, []).append(
                        {grid[a]: ids[a], grid[b]: ids[b]})
    ce4, keys = [], []
    for key, owners in edge_owner.items():
        if len(owners) == 2:
            p, q = key
            ce4.append([owners[0][p], owners[0][q], owners[1][q], owners[1][p]])
            keys.append(key)
    return np.array(xy), np.array(tris), np.array(ce4), keys


def write_names(var, names):
    data = np.zeros((len(names), LEN_NAME), dtype="S1")
    for r, name in enumerate(names):
        data[r, :len(name)] = np.array(list(name), dtype="S1")
    var[:] = data


def write_exodus(path):
    rock_xy, rock_tris, ce4, keys = rock_mesh()
    # The platen: a 40 x 5 mm steel plate on top, two triangles with shared nodes.
    steel_xy = np.array([[0.0, SIDE], [SIDE, SIDE], [SIDE, SIDE + 0.005], [0.0, SIDE + 0.005]])
    steel_tris = np.array([[0, 1, 2], [0, 2, 3]]) + len(rock_xy)
    xy = np.vstack([rock_xy, steel_xy])
    blocks = [("rock", "TRI3", rock_tris), ("steel", "TRI3", steel_tris),
              ("cohesive", "QUAD4", ce4)]
    nodal_names = ["DISPLX", "DISPLY", "VELX", "VELY"]
    elem_names = ["SXX", "SYY", "SXY", "PS1", "PS2", "DAMAGE", "BROKEN", "MODE",
                  "OPENING", "SLIP"]

    # Which rock CE4s are the crack (vertical edges at x = SIDE/2), which break in mode II
    # and mixed at the last frame (diagonals near the top right).
    crack = [k for k, ((x0, y0), (x1, y1)) in enumerate(keys) if x0 == x1 == N // 2]
    crack.sort(key=lambda k: keys[k][0][1])
    diagonals = [k for k, ((x0, y0), (x1, y1)) in enumerate(keys)
                 if x1 - x0 == 1 and y1 - y0 == 1 and x0 >= N // 2 + 1 and y0 >= N - 3]
    assert len(crack) == N and len(diagonals) >= 3, (len(crack), len(diagonals))

    rock_centroid_x = rock_xy[rock_tris].mean(axis=1)[:, 0]
    right_nodes = rock_tris[rock_centroid_x > SIDE / 2].ravel()

    ds = netCDF4.Dataset(path, "w", format="NETCDF3_64BIT_OFFSET")
    for name, size in [("len_string", 33), ("len_line", 81), ("four", 4),
                       ("len_name", LEN_NAME), ("time_step", None), ("num_dim", 2),
                       ("num_nodes", len(xy)),
                       ("num_elem", sum(len(b[2]) for b in blocks)),
                       ("num_el_blk", len(blocks)), ("num_nod_var", len(nodal_names)),
                       ("num_elem_var", len(elem_names))]:
        ds.createDimension(name, size)
    for b, (_, _, conn) in enumerate(blocks, start=1):
        ds.createDimension(f"num_el_in_blk{b}", conn.shape[0])
        ds.createDimension(f"num_nod_per_el{b}", conn.shape[1])

    time_whole = ds.createVariable("time_whole", "f8", ("time_step",))
    eb_names = ds.createVariable("eb_names", "S1", ("num_el_blk", "len_name"))
    eb_status = ds.createVariable("eb_status", "i4", ("num_el_blk",))
    eb_prop1 = ds.createVariable("eb_prop1", "i4", ("num_el_blk",))
    eb_prop1.setncattr("name", "ID")
    coordx = ds.createVariable("coordx", "f8", ("num_nodes",))
    coordy = ds.createVariable("coordy", "f8", ("num_nodes",))
    coor_names = ds.createVariable("coor_names", "S1", ("num_dim", "len_name"))
    connect = []
    for b, (_, kind, _) in enumerate(blocks, start=1):
        var = ds.createVariable(f"connect{b}", "i4",
                                (f"num_el_in_blk{b}", f"num_nod_per_el{b}"))
        var.elem_type = kind
        connect.append(var)
    name_nod_var = ds.createVariable("name_nod_var", "S1", ("num_nod_var", "len_name"))
    nod_vars = [ds.createVariable(f"vals_nod_var{k}", "f8", ("time_step", "num_nodes"))
                for k in range(1, len(nodal_names) + 1)]
    name_elem_var = ds.createVariable("name_elem_var", "S1", ("num_elem_var", "len_name"))
    elem_var_tab = ds.createVariable("elem_var_tab", "i4", ("num_el_blk", "num_elem_var"))
    elem_vars = {}
    for k in range(1, len(elem_names) + 1):
        for b in range(1, len(blocks) + 1):
            elem_vars[k, b] = ds.createVariable(f"vals_elem_var{k}eb{b}", "f8",
                                                ("time_step", f"num_el_in_blk{b}"))
    ds.setncatts({"api_version": np.float32(5.0), "version": np.float32(5.0),
                  "floating_point_word_size": np.int32(8), "file_size": np.int32(1),
                  "maximum_name_length": np.int32(32), "int64_status": np.int32(0),
                  "title": "fdem-cl fracture sample (tests/make_fracture_sample.py)"})

    write_names(eb_names, [b[0] for b in blocks])
    eb_status[:] = 1
    eb_prop1[:] = np.arange(1, len(blocks) + 1)
    coordx[:] = xy[:, 0]
    coordy[:] = xy[:, 1]
    write_names(coor_names, ["x", "y"])
    for var, (_, _, conn) in zip(connect, blocks):
        var[:] = conn + 1
    write_names(name_nod_var, nodal_names)
    write_names(name_elem_var, elem_names)
    elem_var_tab[:] = 1

    for f, (t, opening) in enumerate(zip(TIMES, OPENING)):
        time_whole[f] = t
        dx = np.zeros(len(xy))
        dy = -0.05 * opening * (xy[:, 1] / SIDE)       # slight compression from the top
        dx[right_nodes] = opening
        dy[len(rock_xy):] = -0.05 * opening
        rate = (opening - OPENING[f - 1]) / (t - TIMES[f - 1]) if f else 0.0
        for var, values in zip(nod_vars, [dx, dy, dx / max(opening, 1e-30) * rate,
                                          np.zeros(len(xy))]):
            var[f, :] = values

        # Continuum stresses: tension across the crack plane, growing then released near it.
        values = {}
        for name, (_, kind, conn) in zip(["rock", "steel", "cohesive"], blocks):
            cx = xy[conn].mean(axis=1)[:, 0]
            cy = xy[conn].mean(axis=1)[:, 1]
            sxx = 1.77e6 * (f + 1) / 3 * np.exp(-((cx - SIDE / 2) / 0.01) ** 2) * (1 - cy / SIDE)
            syy = -5.0e6 * (f + 1) / 3 * (0.5 + cy / SIDE)
            sxy = 0.5e6 * np.sin(np.pi * cx / SIDE)
            if kind == "QUAD4":
                sxx = syy = sxy = np.zeros(len(conn))
            centre, radius = (sxx + syy) / 2, np.hypot((sxx - syy) / 2, sxy)
            values[name] = {"SXX": sxx, "SYY": syy, "SXY": sxy, "PS1": centre + radius,
                            "PS2": centre - radius}
            for extra in ("DAMAGE", "BROKEN", "MODE", "OPENING", "SLIP"):
                values[name][extra] = np.zeros(len(conn))
        coh = values["cohesive"]
        broken1 = crack[2:6] if f == 1 else crack if f == 2 else []
        coh["DAMAGE"][crack] = 0.3 * f
        coh["DAMAGE"][broken1] = 1.0
        coh["BROKEN"][broken1] = 1.0
        coh["MODE"][broken1] = 1.0
        coh["OPENING"][crack] = opening
        if f == 2:
            for k, mode in zip(diagonals[:3], (2.0, 2.0, 3.0)):
                coh["DAMAGE"][k] = coh["BROKEN"][k] = 1.0
                coh["MODE"][k] = mode
                coh["SLIP"][k] = 1.0e-5
        for k, name in enumerate(elem_names, start=1):
            for b, block in enumerate(["rock", "steel", "cohesive"], start=1):
                elem_vars[k, b][f, :] = values[block][name]
    ds.close()


def write_history(path):
    rows, peak_row, dt, v = PEAK["rows"], PEAK["row"], PEAK["dt"], PEAK["v"]
    t = np.arange(rows) * dt
    # Linear loading to the peak, then a drop to 20% and a residual tail.
    force = np.where(np.arange(rows) <= peak_row, np.arange(rows) / peak_row,
                     0.2 + 0.8 * np.exp(-(np.arange(rows) - peak_row) / 3.0)) * PEAK["force"]
    broken = np.minimum(np.maximum(np.arange(rows) - peak_row + 5, 0), 40).astype(float)
    columns = {
        "kinetic_energy": ("J", "kinetic energy of all elements", 1e-4 * (t / t[-1]) ** 2),
        "platen_top_force_x": ("N", "reaction on platen_top", 0.0 * t),
        "platen_top_force_y": ("N", "reaction on platen_top", -force),
        "platen_bottom_force_x": ("N", "reaction on platen_bottom", 0.0 * t),
        "platen_bottom_force_y": ("N", "reaction on platen_bottom", force),
        "platen_top_disp_x": ("m", "mean displacement of platen_top", 0.0 * t),
        "platen_top_disp_y": ("m", "mean displacement of platen_top", -v * t),
        "platen_bottom_disp_x": ("m", "mean displacement of platen_bottom", 0.0 * t),
        "platen_bottom_disp_y": ("m", "mean displacement of platen_bottom", v * t),
        "broken_ce4": ("1", "broken CE4s", broken),
        "broken_mode1": ("1", "broken CE4s in mode I", np.floor(0.8 * broken)),
        "broken_mode2": ("1", "broken CE4s in mode II", np.floor(0.1 * broken)),
        "broken_mixed": ("1", "broken CE4s in mixed mode",
                         broken - np.floor(0.8 * broken) - np.floor(0.1 * broken)),
        "crack_length": ("m", "total length of broken CE4s", broken * 0.7e-3),
    }
    ds = netCDF4.Dataset(path, "w", format="NETCDF3_64BIT_OFFSET")
    ds.createDimension("time", None)
    time = ds.createVariable("time", "f8", ("time",))
    time.setncatts({"units": "s", "standard_name": "time", "long_name": "simulated time",
                    "axis": "T"})
    time[:] = t
    for name, (units, long_name, values) in columns.items():
        var = ds.createVariable(name, "f8", ("time",))
        var.setncatts({"units": units, "long_name": long_name})
        var[:] = values
    ds.setncatts({"title": "fdem-cl fracture sample history", "Conventions": "CF-1.8",
                  "source": "tests/make_fracture_sample.py"})
    ds.close()


def main(argv):
    if len(argv) != 2:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    write_exodus(f"{argv[1]}/fracture.exo")
    write_history(f"{argv[1]}/fracture_history.nc")
    print(f"peak_sigma_t={PEAK['sigma_t']:.17g} peak_ucs={PEAK['ucs']:.17g} "
          f"peak_time={PEAK['row'] * PEAK['dt']:.17g} "
          f"broken_last={sum(BROKEN_AT_LAST.values())}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
