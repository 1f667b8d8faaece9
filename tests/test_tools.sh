#!/bin/bash
# Plots files written by the C++ writers with tools/fdem-plot and checks the images.
# Usage: tests/test_tools.sh PATH_TO_TEST_BINARY
# The test binary (tests/test_exodus.cpp) writes tiny.exo and tiny_history.nc into
# $FDEM_TOOLS_TEST_DIR, so the tools are checked on the real writers' output rather than
# on files made by the same Python library that reads them.
set -euo pipefail

if [ $# -ne 1 ] || [ ! -x "$1" ]; then
  echo "usage: $0 PATH_TO_TEST_BINARY (built from tests/test_exodus.cpp)" >&2
  exit 2
fi
test_binary=$(realpath "$1")
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
plot="$repo/tools/fdem-plot"
work=$(mktemp -d /tmp/fdem_tools_test.XXXXXX)
trap 'rm -rf "$work"' EXIT

failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }

# A PNG of more than 5 kB: a plot with axes and colors, not an empty figure.
check_png() {
  local png=$1
  if [ ! -f "$png" ]; then fail "$png not written"; return; fi
  local size
  size=$(stat -c %s "$png")
  [ "$size" -gt 5000 ] || fail "$png is only $size bytes"
  file "$png" | grep -q "PNG image data" || fail "$png is not a PNG: $(file -b "$png")"
}

# Runs a command that must fail with exit code 2 and a message matching a pattern.
expect_error() {
  local pattern=$1; shift
  local rc=0
  "$@" >"$work/out.txt" 2>&1 || rc=$?
  [ "$rc" -eq 2 ] || fail "exit code $rc (want 2): $*"
  grep -q -- "$pattern" "$work/out.txt" || fail "no '$pattern' in the message of: $*"
}

FDEM_TOOLS_TEST_DIR="$work" "$test_binary" --test-suite=exodus >"$work/doctest.txt" 2>&1 ||
  { cat "$work/doctest.txt" >&2; echo "FAIL: $test_binary failed" >&2; exit 1; }
exo="$work/tiny.exo"
hist="$work/tiny_history.nc"
[ -f "$exo" ] && [ -f "$hist" ] || { echo "FAIL: the test binary wrote no files" >&2; exit 1; }

"$plot" field "$exo" --var SXX -o "$work/field.png" || fail "field SXX"
check_png "$work/field.png"
"$plot" field "$exo" --var SXY --frame 0 --deformed-scale 10 --cmap coolwarm \
  --range -5 0 -o "$work/field_options.png" || fail "field with options"
check_png "$work/field_options.png"
"$plot" field "$exo" --var SYY --time 1e-3 -o "$work/field_time.png" || fail "field --time"
check_png "$work/field_time.png"
"$plot" history "$hist" kinetic_energy top_force_y bottom_force_y -o "$work/hist.png" ||
  fail "history, two units"
check_png "$work/hist.png"
"$plot" history "$hist" kinetic_energy --log -o "$work/hist_log.png" || fail "history --log"
check_png "$work/hist_log.png"

expect_error "available: SXX, SYY, SXY" "$plot" field "$exo" --var NOPE -o "$work/x.png"
expect_error "available: kinetic_energy" "$plot" history "$hist" nope -o "$work/x.png"
expect_error "out of range" "$plot" field "$exo" --var SXX --frame 7 -o "$work/x.png"
expect_error "no such file" "$plot" field "$work/missing.exo" --var SXX -o "$work/x.png"
expect_error "usage" "$plot" field "$exo" -o "$work/x.png"  # --var missing

# The loader gives str names, 0-based connectivity and per-frame arrays.
PYTHONPATH="$repo/tools" /usr/bin/python3 - "$exo" "$hist" <<'PY' || fail "fdem_load checks"
import sys
import numpy as np
from fdem_load import load_exodus, load_history
exo = load_exodus(sys.argv[1])
assert [b.name for b in exo.blocks] == ["granite", "steel"], exo.blocks
assert all(b.elem_type == "TRI3" for b in exo.blocks)
assert exo.blocks[0].connectivity.tolist() == [[0, 1, 2], [0, 2, 3]]
assert exo.blocks[1].connectivity.tolist() == [[1, 4, 2]]
assert list(exo.nodal) == ["DISPLX", "DISPLY"] and list(exo.element) == ["SXX", "SYY", "SXY"]
assert np.allclose(exo.times, [0.0, 1.5e-3, 3.0e-3])
assert exo.nodal["DISPLX"].shape == (3, 5)
assert exo.element_values("SXX", 1).tolist() == [-2e6, -4e6, -8e6]
assert exo.coordinates.shape == (5, 2)
hist = load_history(sys.argv[2])
assert hist.units == {"kinetic_energy": "J", "top_force_y": "N", "bottom_force_y": "N"}
assert hist.times.shape == (5,) and hist.values["top_force_y"][2] == -4e4
PY

# Fracture output (cohesive QUAD4 block, BROKEN/MODE, platen history): written by
# tests/make_fracture_sample.py in the C++ writer's layout until the engine writes it.
sample=$(/usr/bin/python3 "$repo/tests/make_fracture_sample.py" "$work") ||
  { echo "FAIL: tests/make_fracture_sample.py" >&2; exit 1; }
fexo="$work/fracture.exo"
fhist="$work/fracture_history.nc"
value_of() { echo "$sample" | tr ' ' '\n' | sed -n "s/^$1=//p"; }
peak_sigma_t=$(value_of peak_sigma_t)
peak_ucs=$(value_of peak_ucs)

"$plot" field "$fexo" --var PS1 --cracks -o "$work/frac_field.png" || fail "field --cracks"
check_png "$work/frac_field.png"
"$plot" field "$fexo" --var SXX --cracks --frames 0 1 -1 --deformed-scale 5 \
  -o "$work/frac_frames.png" || fail "field --frames --cracks"
check_png "$work/frac_frames.png"
"$plot" field "$fexo" --var SYY --times 0 1e-3 -o "$work/frac_times.png" || fail "field --times"
check_png "$work/frac_times.png"
"$plot" cracks "$fexo" -o "$work/cracks.png" >"$work/cracks.txt" || fail "cracks"
check_png "$work/cracks.png"
grep -q "11 broken CE4s (mode I 8, mode II 2, mixed 1)" "$work/cracks.txt" ||
  fail "cracks counts: $(cat "$work/cracks.txt")"
"$plot" cracks "$fexo" --frame 1 -o "$work/cracks1.png" >"$work/cracks1.txt" || fail "cracks --frame 1"
check_png "$work/cracks1.png"
grep -q "4 broken CE4s (mode I 4, mode II 0, mixed 0)" "$work/cracks1.txt" ||
  fail "cracks --frame 1 counts: $(cat "$work/cracks1.txt")"

"$plot" stress-strain "$fhist" --test brazilian --load-region platen_top \
  --support-region platen_bottom --size 0.0517 --thickness 0.02595 \
  --mark-times 8e-4 1.2e-3 1.6e-3 -o "$work/bd.png" --csv "$work/bd.csv" >"$work/bd.txt" ||
  fail "stress-strain brazilian"
check_png "$work/bd.png"
"$plot" stress-strain "$fhist" --test ucs --load-region platen_top \
  --support-region platen_bottom --size 0.1295 --width 0.0517 --thickness 0.02595 \
  -o "$work/ucs.png" --csv "$work/ucs.csv" >"$work/ucs.txt" || fail "stress-strain ucs"
check_png "$work/ucs.png"
/usr/bin/python3 - "$work" "$peak_sigma_t" "$peak_ucs" <<'PY' || fail "stress-strain peaks"
import csv, re, sys
work, expected = sys.argv[1], {"bd": float(sys.argv[2]), "ucs": float(sys.argv[3])}
for name, want in expected.items():
    with open(f"{work}/{name}.csv") as f:
        rows = list(csv.DictReader(f))
    peak = max(float(r["stress_Pa"]) for r in rows)
    assert abs(peak - want) <= 1e-9 * want, (name, peak, want)
    printed = open(f"{work}/{name}.txt").read()
    m = re.search(r"peak stress: ([0-9.eE+-]+) MPa", printed)
    assert m and abs(float(m.group(1)) * 1e6 - want) <= 1e-5 * want, (name, printed, want)
    # strain at the peak: relative platen displacement (2 x 0.025 m/s x 1.2 ms) / size
    size = 0.0517 if name == "bd" else 0.1295
    peak_row = max(rows, key=lambda r: float(r["stress_Pa"]))
    assert abs(float(peak_row["strain"]) - 0.05 * 1.2e-3 / size) < 1e-12, peak_row
PY

# What the Makefile's demo and validate targets run: its own plot flags (make prints
# them), on the sample's frames. The sample has t = 0.02595 m and the cases t = 1 m, so
# the Makefile's curves peak at the sample's peak × 0.02595.
make_var() {
  make -s --no-print-directory -C "$repo" -f Makefile -f - "print-$1" <<'MK'
print-%: ; @echo '$($*)'
MK
}
cracks_flags=$(make_var CRACKS) && brazilian_flags=$(make_var BRAZILIAN_CURVE) &&
  ucs_flags=$(make_var UCS_CURVE) && [ -n "$cracks_flags" ] && [ -n "$brazilian_flags" ] &&
  [ -n "$ucs_flags" ] || { echo "FAIL: cannot read the plot flags from the Makefile" >&2; exit 1; }
grep -q "fdem-fracture" "$repo/Makefile" && fail "the Makefile still calls tools/fdem-fracture"
# shellcheck disable=SC2086  # the flags are words
"$plot" $cracks_flags "$fexo" --frames 0 1 2 --range -5 2 -o "$work/make_cracks.png" ||
  fail "Makefile cracks: $cracks_flags"
check_png "$work/make_cracks.png"
"$plot" $cracks_flags "$fexo" --frames 2 --range -20 10 -o "$work/make_cracks1.png" ||
  fail "Makefile cracks, one frame: $cracks_flags"
check_png "$work/make_cracks1.png"
"$plot" $brazilian_flags "$fhist" -o "$work/make_bd.png" >"$work/make_bd.txt" ||
  fail "Makefile Brazilian curve: $brazilian_flags"
check_png "$work/make_bd.png"
"$plot" $ucs_flags "$fhist" -o "$work/make_ucs.png" >"$work/make_ucs.txt" ||
  fail "Makefile UCS curve: $ucs_flags"
check_png "$work/make_ucs.png"
/usr/bin/python3 - "$work" "$peak_sigma_t" "$peak_ucs" <<'PY' || fail "Makefile curves' peaks"
import re, sys
work, expected = sys.argv[1], {"make_bd": float(sys.argv[2]), "make_ucs": float(sys.argv[3])}
for name, want in expected.items():
    printed = open(f"{work}/{name}.txt").read()
    m = re.search(r"peak stress: ([0-9.eE+-]+) MPa", printed)
    assert m and abs(float(m.group(1)) * 1e6 - want * 0.02595) <= 1e-5 * want, (name, printed, want)
PY

expect_error "available: kinetic_energy, platen_top_force_x" "$plot" stress-strain "$fhist" \
  --test brazilian --load-region top --size 0.05 --thickness 1 -o "$work/x.png"
expect_error "platen_side_disp_y" "$plot" stress-strain "$fhist" --test brazilian \
  --load-region platen_top --support-region platen_side --size 0.05 --thickness 1 -o "$work/x.png"
expect_error "needs --width" "$plot" stress-strain "$fhist" --test ucs \
  --load-region platen_top --size 0.1 --thickness 1 -o "$work/x.png"
expect_error "available: kinetic_energy, top_force_y" "$plot" stress-strain "$hist" \
  --test brazilian --load-region top_platen --size 0.05 --thickness 1 -o "$work/x.png"
expect_error "no 'cohesive' element block" "$plot" cracks "$exo" -o "$work/x.png"
expect_error "no 'cohesive' element block" "$plot" field "$exo" --var SXX --cracks -o "$work/x.png"
expect_error "out of range" "$plot" field "$fexo" --var SXX --frames 0 3 -o "$work/x.png"

# The cohesive block is not filled; broken faces and the outline come from the right nodes.
/usr/bin/python3 - "$repo/tools/fdem-plot" "$fexo" <<'PY' || fail "fdem-plot fracture helpers"
import importlib.machinery, importlib.util, sys
loader = importlib.machinery.SourceFileLoader("fdem_plot", sys.argv[1])
spec = importlib.util.spec_from_loader("fdem_plot", loader)
plot = importlib.util.module_from_spec(spec)
loader.exec_module(plot)
exo = plot.fdem_load.load_exodus(sys.argv[2])
assert [(b.name, b.elem_type) for b in exo.blocks] == \
    [("rock", "TRI3"), ("steel", "TRI3"), ("cohesive", "QUAD4")]
tris, owner, skipped = plot.triangles_of(exo.blocks)
assert len(tris) == 130 and owner.max() == 129 and not skipped, (len(tris), skipped)
pairs, modes = plot.broken_faces(exo, -1, "sample")
assert len(pairs) == 22 and sorted(modes.tolist()) == [1] * 16 + [2] * 4 + [3] * 2
pairs, modes = plot.broken_faces(exo, 0, "sample")
assert len(pairs) == 0
# outline: 4 x 8 rock edges + 4 platen edges
assert len(plot.outline_edges(exo)) == 36, len(plot.outline_edges(exo))
PY

# bench: a CSV in the form `fdem bench --csv` writes (engine/bench.cpp), points on a line.
cat >"$work/bench.csv" <<'CSV'
h_ave_mm,tri3,ce4,nodes,initial_couples,touching,rebuilds,ms_per_step,paper_ms_per_step,speedup,device_mib,bytes_per_tri3,roofline_ms,roofline_fraction
0.6,60000,90000,180000,420000,63000,0,0.2,12.6,63,176,3037,0.04,0.2
0.15,1080000,1600000,3230000,7500000,1100000,0,2.24,84.6,37.8,3147,3048,0.68,0.3
0.3,240000,360000,720000,1680000,250000,0,0.56,21.4,38.2,700,3040,0.15,0.27
CSV
"$plot" bench "$work/bench.csv:H200" -o "$work/bench.png" >"$work/bench.txt" || fail "fdem-plot bench"
check_png "$work/bench.png"
grep -q "largest miss of the linear fit 0.0%" "$work/bench.txt" || fail "bench linear fit: $(cat "$work/bench.txt")"
echo "x,y" >"$work/notbench.csv"
expect_error "not an fdem bench CSV" "$plot" bench "$work/notbench.csv" -o "$work/x.png"

# tools/compare-outputs: a tree against a copy of itself, then against a copy with one
# history value changed and one variable added.
mkdir -p "$work/cmp_old/run" "$work/cmp_new/run"
cp "$work/tiny_history.nc" "$work/cmp_old/run/"
cp "$work/tiny_history.nc" "$work/cmp_new/run/"
"$repo/tools/compare-outputs" "$work/cmp_old" "$work/cmp_new" >"$work/cmp.txt" || fail "compare-outputs: identical trees: $(cat "$work/cmp.txt")"
[ ! -s "$work/cmp.txt" ] || fail "compare-outputs printed for identical trees: $(cat "$work/cmp.txt")"
/usr/bin/python3 - "$work/cmp_new/run/tiny_history.nc" <<'PY'
import sys, netCDF4
with netCDF4.Dataset(sys.argv[1], "a") as d:
    v = d["kinetic_energy"]
    v[-1] = v[-1] * 1.5 + 1.0
    d.createVariable("added", "f8", ("time",))[:] = 0.0
PY
status=0
"$repo/tools/compare-outputs" "$work/cmp_old" "$work/cmp_new" >"$work/cmp.txt" || status=$?
[ "$status" -eq 1 ] || fail "compare-outputs: exit $status for differing trees, not 1"
grep -q "kinetic_energy: max |difference|" "$work/cmp.txt" || fail "compare-outputs did not name kinetic_energy: $(cat "$work/cmp.txt")"
grep -q "new variables: added" "$work/cmp.txt" || fail "compare-outputs did not name the new variable: $(cat "$work/cmp.txt")"
if grep -q "strain_energy" "$work/cmp.txt"; then fail "compare-outputs named an unchanged variable: $(cat "$work/cmp.txt")"; fi

if [ "$failures" -ne 0 ]; then
  echo "test_tools.sh: $failures failure(s)" >&2
  exit 1
fi
echo "test_tools.sh: all checks passed"
