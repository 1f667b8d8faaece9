#!/bin/bash
# The split run (`mpirun -np N fdem run`, ARCHITECTURE.md "Scale-out") on PoCL: a small
# blast (tests/data/cases/blast_small.msh, CE4s breaking around the hole, a blast load,
# an absorbing rim, two probes; [contact] left out, which a split run refuses) and a small
# geostatic column (tests/data/cases/column_small.*) run as one process and
# over 1, 2 and 4 ranks gives byte-identical .exo, history, fragments and events files;
# a failure on the ranks ends every rank with one rank's exit code and message;
# checkpoints continue at any number of ranks; what a split run does not do is refused
# with exit 2.
# Usage: test_mpi.sh FDEM [MPIRUN]
set -u
fdem=$(readlink -f "$1")
mpirun=${2:-mpirun}
if ! command -v "$mpirun" >/dev/null 2>&1; then
  echo "skipped: no mpirun ($mpirun), so no split run to test"
  exit 0
fi
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export FDEM_DEVICE=${FDEM_DEVICE:-cpu}
src=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fails=0
check() {  # check WHAT COMMAND...: counts a failure when the command fails
  local what=$1
  shift
  if "$@"; then echo "ok: $what"; else echo "FAILED: $what"; fails=$((fails + 1)); fi
}

cp "$src/data/cases/blast_small.msh" "$tmp/"
# The small blast without its [contact] table (from [contact] to the first [[boundary]]).
awk '/^\[contact\]/{skip=1} /^\[\[boundary\]\]/{skip=0} !skip' "$src/data/cases/blast_small.toml" > "$tmp/blast.toml"
# Two history probes: one the wave reaches, one it does not.
printf '[[probe]]\nname = "near"\npoint = [0.5, 0.2]\n[[probe]]\nname = "far"\npoint = [-3.0, -1.0]\n' >> "$tmp/blast.toml"
cp "$src/data/cases/blast_small.toml" "$tmp/contact.toml"
cd "$tmp" || exit 1

split() {  # split NP OUT [ARGS...]
  local np=$1 out=$2
  shift 2
  "$mpirun" --oversubscribe -np "$np" "$fdem" run blast.toml --set "output.dir=\"$out\"" "$@" > "$out.log" 2>&1
}

"$fdem" run blast.toml --quiet --set 'output.dir="one"' > one.log 2>&1
check "one process runs the small blast" test $? -eq 0
check "CE4s break in it" grep -q "CE4s broken" one.log
split 1 np1
check "mpirun -np 1 runs" test $? -eq 0
split 2 np2 --partition metis
check "mpirun -np 2 (METIS) runs" test $? -eq 0
split 4 np4 --partition bisection
check "mpirun -np 4 (bisection) runs" test $? -eq 0
check "4 ranks said so" grep -q "over 4 ranks" np4.log
for out in np1 np2 np4; do
  for f in blast.exo blast_history.nc blast_fragments.nc blast_events.nc; do
    check "$out/$f byte-identical to one process" cmp -s "one/$f" "$out/$f"
  done
done

# A small geostatic column (gravity, local damping with mass scaling, viscosity, rollers:
# the other terms of the energy account and the reaction columns) over 2 and 4 ranks.
cp "$src/data/cases/column_small.msh" "$src/data/cases/column_small.toml" .
"$fdem" run column_small.toml --quiet --set 'output.dir="col1"' > col1.log 2>&1
check "one process runs the column" test $? -eq 0
for np in 2 4; do
  "$mpirun" --oversubscribe -np "$np" "$fdem" run column_small.toml --set "output.dir=\"col$np\"" > "col$np.log" 2>&1
  check "the column over $np ranks runs" test $? -eq 0
  for f in column.exo column_history.nc; do
    check "col$np/$f byte-identical to one process" cmp -s "col1/$f" "col$np/$f"
  done
done

# A failure found on the ranks (a triangle inverts under a blast of 1e13 Pa): every rank
# ends with exit 3 and one rank's message, and rank 0 writes the last good frame.
"$fdem" run blast.toml --quiet --set 'output.dir="fail1"' --set 'boundary.0.blast.peak=1e13' > fail1.log 2>&1
check "one process: exit 3 on the inverted triangle" test $? -eq 3
split 2 fail2 --set 'boundary.0.blast.peak=1e13'
check "2 ranks: exit 3 too" test $? -eq 3
message=$(grep "^numerical failure" fail1.log | sed 's/fail1/OUT/g')
check "one process: a message naming the triangle" grep -q "inverted" fail1.log
check "2 ranks: the same message, once" test "$(grep "^numerical failure" fail2.log | sed 's/fail2/OUT/g')" = "$message"
check "2 ranks: the same last frame" cmp -s fail1/blast.exo fail2/blast.exo

# Rank 0 alone cannot write its file (the .exo path is a directory): every rank ends
# with the output error's exit code 5, none waits.
mkdir -p out5/blast.exo
timeout 120 "$mpirun" --oversubscribe -np 2 "$fdem" run blast.toml --set 'output.dir="out5"' > out5.log 2>&1
check "rank 0's output error ends both ranks with exit 5" test $? -eq 5
check "... naming the file" grep -q "output error: .*blast.exo" out5.log

# Checkpoints hold the whole model and continue at any number of ranks: 2 ranks to half
# the time, 4 ranks on to the end give one process's files; so do one process then 2 ranks.
split 2 half --set 'time.end=1e-4'
check "2 ranks to half the time" test $? -eq 0
split 4 half --restart
check "4 ranks continue its checkpoint" test $? -eq 0
check "... resumed" grep -q "resumed from" half.log
"$fdem" run blast.toml --quiet --set 'output.dir="half1"' --set 'time.end=1e-4' > half1.log 2>&1
split 2 half1 --restart
check "2 ranks continue one process's checkpoint" test $? -eq 0
# --max-wall over 2 ranks: every rank stops at the same step (exit 75) with a
# checkpoint; 4 ranks continue it.
split 2 wall --max-wall 0.01
check "--max-wall stops 2 ranks with exit 75" test $? -eq 75
check "... printing how to resume" grep -q "resume with: mpirun" wall.log
split 4 wall --restart
check "4 ranks continue the stopped run" test $? -eq 0
for out in half half1 wall; do
  for f in blast.exo blast_history.nc blast_fragments.nc blast_events.nc; do
    check "$out/$f (a chain over rank counts) byte-identical to one process" cmp -s "one/$f" "$out/$f"
  done
done

# Refused under N > 1 with one message and exit 2: contact.
"$mpirun" --oversubscribe -np 2 "$fdem" run contact.toml --set 'output.dir="c"' > c.log 2>&1
check "contact over 2 ranks: exit 2" test $? -eq 2
check "... saying what is missing" grep -q "\[contact\] cannot run over several ranks yet" c.log
check "... once" test "$(grep -c '^error:' c.log)" -eq 1

if [ "$fails" -ne 0 ]; then
  echo "$fails check(s) failed"
  exit 1
fi
echo "all checks passed"
