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

if [ "$failures" -ne 0 ]; then
  echo "test_tools.sh: $failures failure(s)" >&2
  exit 1
fi
echo "test_tools.sh: all checks passed"
