#!/bin/bash
# tools/fdem-wave on a real run: a P-wave in an elastic strip (tests/data/cases/wave_strip.toml:
# velocity step of 2 m/s at the left end, rollers on the long sides, so the strain is uniaxial and
# the front travels at c = sqrt((lambda + 2 mu)/rho) = 3000 m/s), written by build/fdem with
# [[probe]] points. Checks the apparent speed, the free-end reflection, the probe variables
# in the history file and the error messages. About 10 s on 2 cores with PoCL.
# Usage: tests/test_wave_tool.sh PATH_TO_FDEM
set -euo pipefail

if [ $# -ne 1 ] || [ ! -x "$1" ]; then
  echo "usage: $0 PATH_TO_FDEM" >&2
  exit 2
fi
fdem=$(realpath "$1")
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
wave="$repo/tools/fdem-wave"
case_file="$repo/tests/data/cases/wave_strip.toml"
work=$(mktemp -d /tmp/fdem_wave_test.XXXXXX)
trap 'rm -rf "$work"' EXIT

failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }

# Runs a command that must fail with exit code 2 and a message matching a pattern.
expect_error() {
  local pattern=$1; shift
  local rc=0
  "$@" >"$work/out.txt" 2>&1 || rc=$?
  [ "$rc" -eq 2 ] || fail "exit code $rc (want 2): $*"
  grep -q -- "$pattern" "$work/out.txt" || fail "no '$pattern' in the message of: $* ($(cat "$work/out.txt"))"
}

# The speed printed by `fdem-wave arrival`.
speed_of() { sed -n 's/^apparent P-wave speed V = \([0-9.eE+-]*\) m\/s.*/\1/p' "$1"; }

# |V/c - 1| < tol, printing the figure.
check_speed() {
  local label=$1 v=$2 tol=$3
  [ -n "$v" ] || { fail "$label: no speed printed"; return; }
  /usr/bin/python3 -c "
import sys
v, tol = float('$v'), float('$tol')
err = v / 3000.0 - 1.0
print(f'$label: V = {v:.1f} m/s, {100 * err:+.2f}% from c = 3000 m/s (tolerance {100 * tol:g}%)')
sys.exit(0 if abs(err) < tol else 1)" || fail "$label: V = $v m/s is not within $tol of 3000 m/s"
}

run_case() {  # run_case DIR [--set ...]
  local dir=$1; shift
  "$fdem" run "$case_file" --quiet --set "output.dir=$dir" "$@" >"$dir.log" 2>&1 ||
    { cat "$dir.log" >&2; echo "FAIL: fdem run $*" >&2; exit 1; }
}

# --- the run (h = 20 mm) and its probes ---------------------------------------------------
"$fdem" check "$case_file" --set "output.dir=$work/h20" >"$work/check.txt" 2>&1 ||
  fail "fdem check: $(cat "$work/check.txt")"
grep -q "^probe     x02 at (0.2, 0.05): node [0-9]* at" "$work/check.txt" ||
  fail "fdem check does not list probe x02: $(cat "$work/check.txt")"
[ "$(grep -c '^probe ' "$work/check.txt")" -eq 6 ] || fail "fdem check lists $(grep -c '^probe ' "$work/check.txt") probes, not 6"
run_case "$work/h20"
hist="$work/h20/wave_strip_history.nc"
exo="$work/h20/wave_strip.exo"

PYTHONPATH="$repo/tools" /usr/bin/python3 - "$hist" <<'PY' || fail "probe variables in the history file"
import sys
import netCDF4
import numpy as np
from fdem_load import load_history
hist = load_history(sys.argv[1])
for name, x in [("x02", 0.2), ("x05", 0.5), ("x08", 0.8), ("x11", 1.1), ("x14", 1.4), ("x17", 1.7)]:
    for q, unit in [("vx", "m/s"), ("vy", "m/s"), ("sxx", "Pa"), ("syy", "Pa"), ("sxy", "Pa"), ("ps1", "Pa")]:
        assert hist.units.get(f"{name}_{q}") == unit, (name, q, hist.units.get(f"{name}_{q}"))
    with netCDF4.Dataset(sys.argv[1]) as ds:
        assert np.allclose(ds[f"{name}_ps1"].probe_point, [x, 0.05]), name
    v = hist.values
    # A row every history step (2 us), not every frame; PS1 from the three components;
    # uniaxial strain behind the front: sigma_yy = sigma_xx / 3 (lambda = mu), sigma_xy ~ 0.
    assert len(hist.times) > 400, len(hist.times)
    sxx, syy, sxy = v[f"{name}_sxx"], v[f"{name}_syy"], v[f"{name}_sxy"]
    ps1 = 0.5 * (sxx + syy) + np.hypot(0.5 * (sxx - syy), sxy)
    assert np.allclose(v[f"{name}_ps1"], ps1, rtol=1e-12, atol=1e-9 * np.max(np.abs(sxx))), name
    plateau = slice(int(np.argmin(sxx)), None)
    assert np.allclose(syy[plateau].mean(), sxx[plateau].mean() / 3, rtol=0.05), name
    # velocity behind the front approaches the pushed end's 2 m/s
    assert 1.6 < np.max(v[f"{name}_vx"]) < 6.0, (name, np.max(v[f"{name}_vx"]))
PY

# --- apparent speed -----------------------------------------------------------------------
# Tolerance 2%: on this 20 mm mesh the step front spreads as it travels (lumped-mass TRI3
# dispersion: width ~ h (c t / h)^(1/3)), so its half-peak crossing lags more and more and
# the fitted speed comes out about 1% low; the error falls with h (about 3% at 40 mm,
# 0.6% at 10 mm), which the refinement check below asserts.
"$wave" arrival "$hist" --centre 0 0.05 --csv "$work/arrival.csv" --png "$work/arrival.png" \
  >"$work/arrival.txt" || fail "arrival on the history file"
cat "$work/arrival.txt"
v_history=$(speed_of "$work/arrival.txt")
check_speed "history probes, h = 20 mm" "$v_history" 0.02
[ "$(wc -l <"$work/arrival.csv")" -eq 7 ] || fail "arrival.csv has $(wc -l <"$work/arrival.csv") lines, not 7"
[ -s "$work/arrival.png" ] && file "$work/arrival.png" | grep -q "PNG image data" || fail "arrival.png"

# The same from the Exodus frames (every 20 us), at the same points on the line y = 0.05.
"$wave" arrival "$exo" --centre 0 0.05 --radii 0.2 0.5 0.8 1.1 1.4 1.7 --angles 0 \
  >"$work/arrival_exo.txt" || fail "arrival on the Exodus file"
cat "$work/arrival_exo.txt"
check_speed "Exodus frames, h = 20 mm" "$(speed_of "$work/arrival_exo.txt")" 0.02
# Arrival times of points x = 0.2 ... 1.7: about x / c (within a tenth of the span).
/usr/bin/python3 - "$work/arrival.csv" <<'PY' || fail "arrival times"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert [r["point"] for r in rows] == ["x02", "x05", "x08", "x11", "x14", "x17"], rows
for r in rows:
    assert abs(float(r["arrival_s"]) - float(r["radius_m"]) / 3000.0) < 0.05 * 1.5 / 3000.0, r
    # PS1 = sigma_yy = -6 MPa behind the front, with the front's overshoot
    assert -8e6 < float(r["peak_compression_Pa"]) < -5e6, r
PY

# Refinement: on a 10 mm mesh the speed is closer to c. Double builds only: in a float
# build the round-off of positions (7 digits) is a strain error that grows as the
# elements shrink, and at 10 mm it is as large as the dispersion (V 2968 m/s both).
if "$fdem" --version | grep -q "double precision"; then
  run_case "$work/h10" --set mesh.size=0.01
  "$wave" arrival "$work/h10/wave_strip_history.nc" --centre 0 0.05 >"$work/arrival10.txt" ||
    fail "arrival, h = 10 mm"
  v_fine=$(speed_of "$work/arrival10.txt")
  check_speed "history probes, h = 10 mm" "$v_fine" 0.01
  /usr/bin/python3 -c "import sys; sys.exit(0 if abs($v_fine - 3000) < abs($v_history - 3000) else 1)" ||
    fail "refining the mesh did not bring the speed closer to c ($v_history -> $v_fine m/s)"
fi

# --- reflection at the free right end ----------------------------------------------------
# x17 is 0.3 m from the free end: sigma_xx comes back as tension that cancels the step,
# reflected/incident = -1. Tolerance 10%: both fronts ring (overshoot about 25% of the
# step on this mesh) and the extremes catch the ringing at different phases; splits at
# D = 0.2 ... 0.35 m gave -0.93 ... -1.03. A fixed end would give +1, an absorbing one 0.
"$wave" reflection "$hist" --probe x17 --var sxx --boundary-distance 0.3 --speed 3000 \
  --csv "$work/reflection.csv" --png "$work/reflection.png" >"$work/reflection.txt" ||
  fail "reflection"
cat "$work/reflection.txt"
ratio=$(sed -n 's/^  reflected \/ incident *//p' "$work/reflection.txt")
/usr/bin/python3 -c "import sys; sys.exit(0 if abs($ratio + 1) < 0.1 else 1)" ||
  fail "free-end reflection ratio $ratio, not -1 within 10%"
file "$work/reflection.png" | grep -q "PNG image data" || fail "reflection.png"
"$wave" reflection "$exo" --point 1.7 0.05 --var SXX --split 7.0e-4 >"$work/reflection_exo.txt" ||
  fail "reflection on the Exodus file"
# Frames every 20 us (6 cm of travel) undersample the front's overshoot: 20% there.
ratio_exo=$(sed -n 's/^  reflected \/ incident *//p' "$work/reflection_exo.txt")
/usr/bin/python3 -c "import sys; sys.exit(0 if abs($ratio_exo + 1) < 0.2 else 1)" ||
  fail "free-end reflection ratio from frames $ratio_exo, not -1 within 20%"

# --- errors -------------------------------------------------------------------------------
expect_error "no such file" "$wave" arrival "$work/missing.exo" --centre 0 0 --radii 1
expect_error "available: SXX, SYY, SXY, PS1, PS2" "$wave" arrival "$exo" --centre 0 0.05 --radii 0.5 --var NOPE
expect_error "probes there: x02, x05" "$wave" arrival "$hist" --centre 0 0.05 --var nope
expect_error "no probe 'x99'" "$wave" arrival "$hist" --centre 0 0.05 --probes x02 x99
expect_error "none of the points lies in the mesh" "$wave" arrival "$exo" --centre 0 0.05 --radii 5 6 --angles 0
expect_error "needs --centre" "$wave" arrival "$hist"
# Before 50 us the front (at 3000 m/s) has not reached x = 0.2 m: no front to time at
# the farther probes, and x02 sees only the front's dispersive precursor (about 19 kPa
# against the 7 MPa it sees later): "no front found" (issue 28 row 15: such precursors
# gave arrivals and a speed of 17,147 m/s).
expect_error "no front found: none of the 6 points" "$wave" arrival "$hist" --centre 0 0.05 --until 5e-5
expect_error "x02 (element [0-9]*): peak compressive change .* is below a tenth of the point's own peak" \
  "$wave" arrival "$hist" --centre 0 0.05 --until 5e-5
expect_error "(element [0-9]*): no compressive change after the first sample" "$wave" arrival "$hist" --centre 0 0.05 --until 5e-5
expect_error "select them with --probes" "$wave" arrival "$hist" --centre 0 0 --radii 1
expect_error "needs --split T, or --boundary-distance" "$wave" reflection "$hist" --probe x17
# A run without [[probe]] entries: its history file has no probe variables.
mkdir -p "$work/noprobe"
sed '/^\[\[probe\]\]/,$d' "$case_file" >"$work/noprobe/case.toml"
cp "$repo/tests/data/cases/wave_strip.geo" "$work/noprobe/"
"$fdem" run "$work/noprobe/case.toml" --quiet --set "output.dir=$work/noprobe/out" --set time.end=1e-5 \
  >"$work/noprobe.log" 2>&1 || fail "run without probes: $(cat "$work/noprobe.log")"
expect_error "the case has no \[\[probe\]\] entries" "$wave" arrival "$work/noprobe/out/case_history.nc" --centre 0 0

# The engine refuses a probe outside the mesh and a repeated name, naming the probe.
expect_error "probe\[0\] ('x02'): point = \[5, 0.05\] is outside the mesh" \
  "$fdem" check "$case_file" --set "output.dir=$work/bad" --set 'probe.0.point=[5.0, 0.05]'
expect_error "probe\[1\].name = \"x02\" is already the name of probe\[0\]" \
  "$fdem" check "$case_file" --set "output.dir=$work/bad" --set 'probe.1.name="x02"'

if [ "$failures" -ne 0 ]; then
  echo "test_wave_tool.sh: $failures failure(s)" >&2
  exit 1
fi
echo "test_wave_tool.sh: all checks passed"
