#!/bin/bash
# The split run (`mpirun -np N fdem run`, ARCHITECTURE.md "Scale-out") on PoCL: a small
# blast (tests/data/cases/blast_small.msh, CE4s breaking around the hole, a blast load,
# an absorbing rim, two probes; once without its [contact] table, once with it), a small
# geostatic column (tests/data/cases/column_small.*), a coarse Brazilian disc (contact
# between platens and a disc that cracks) and a coarse disc impact (contact without CE4s)
# run as one process and over 1, 2 and 4 ranks give byte-identical .exo, history,
# fragments and events files; a failure on the ranks ends every rank with one rank's exit
# code and message; checkpoints continue at any number of ranks, with contact too; a node
# travelling beyond the contact ghosts stops every rank with exit 2; the column in its
# in-situ state with a heterogeneous E over 2 ranks; a tunnel excavated over 2 ranks and
# across a restart from 2 ranks to one; the small blast with extrinsic CE4s, with and
# without contact, over 2 and 4 ranks and across restarts.
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
# The .geo cases mesh once (every rank reads the case, and meshes it when not cached).
export FDEM_MESH_CACHE="$tmp/meshes"
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
# With contact (a fixed skin: a split run keeps its first skin, one process would adapt
# an "auto" one): every detection lists every triangle's couples, split or not.
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

# Contact across ranks. The small blast with its [contact] table (activation
# "fractured", skin rebuilds, couples across intact and broken CE4s and corner fans):
# 2 ranks with tight contact ghosts (--contact-travel 0.02 m), 4 with the default ones.
"$fdem" run contact.toml --quiet --set 'output.dir="cone"' > cone.log 2>&1
check "one process runs the small blast with contact" test $? -eq 0
csplit() {  # csplit NP OUT [ARGS...]
  local np=$1 out=$2
  shift 2
  "$mpirun" --oversubscribe -np "$np" "$fdem" run contact.toml --set "output.dir=\"$out\"" "$@" > "$out.log" 2>&1
}
csplit 2 cnp2 --partition metis --contact-travel 0.02
check "contact: mpirun -np 2 (METIS, tight ghosts) runs" test $? -eq 0
csplit 4 cnp4 --partition bisection
check "contact: mpirun -np 4 (bisection) runs" test $? -eq 0
# A chain over rank counts with contact: 2 ranks to half the time, 4 on; one process, then 2.
csplit 2 chalf --set 'time.end=1e-4'
check "contact: 2 ranks to half the time" test $? -eq 0
csplit 4 chalf --restart
check "contact: 4 ranks continue its checkpoint" test $? -eq 0
"$fdem" run contact.toml --quiet --set 'output.dir="chalf1"' --set 'time.end=1e-4' > chalf1.log 2>&1
csplit 2 chalf1 --restart
check "contact: 2 ranks continue one process's checkpoint" test $? -eq 0
for out in cnp2 cnp4 chalf chalf1; do
  for f in blast.exo blast_history.nc blast_fragments.nc blast_events.nc; do
    check "contact: $out/$f byte-identical to one process" cmp -s "cone/$f" "$out/$f"
  done
done

# A coarse Brazilian disc (5 mm, platens at 1 m/s, 0.12 ms: CE4s break under the platens)
# over 2 ranks.
cp "$src/../cases/brazilian/case.toml" brazilian.toml
cp "$src/../cases/brazilian/"*.geo .
bset=(--set 'mesh.size=5e-3' --set 'time.end=0.12e-3' --set 'output.frames=3'
      --set 'boundary.0.velocity=[0.0, -1.0]' --set 'boundary.1.velocity=[0.0, 1.0]')
"$fdem" run brazilian.toml --quiet "${bset[@]}" --set 'output.dir="bone"' > bone.log 2>&1
check "one process runs the coarse Brazilian disc" test $? -eq 0
check "... and CE4s break in it" grep -q "[1-9][0-9]* CE4s broken" bone.log
"$mpirun" --oversubscribe -np 2 "$fdem" run brazilian.toml "${bset[@]}" --set 'output.dir="bnp2"' > bnp2.log 2>&1
check "the Brazilian disc over 2 ranks runs" test $? -eq 0
for f in brazilian.exo brazilian_history.nc brazilian_fragments.nc brazilian_events.nc; do
  check "bnp2/$f byte-identical to one process" cmp -s "bone/$f" "bnp2/$f"
done

# A coarse disc impact (no CE4s, activation "all"): skin rebuilds over 2 and 4 ranks,
# rebuilds every step over 2.
cp "$src/../cases/impact/case.toml" impact.toml
cp "$src/../cases/impact/"*.geo .
# A fixed skin: a split run keeps its first one, one process would adapt an "auto" skin
# (the same physics, other contact_candidates and contact_rebuilds).
iset=(--set 'mesh.size=0.02' --set 'time.end=0.004' --set 'contact.skin=0.004')
"$fdem" run impact.toml --quiet "${iset[@]}" --set 'output.dir="ione"' > ione.log 2>&1
check "one process runs the coarse impact" test $? -eq 0
"$fdem" run impact.toml --quiet "${iset[@]}" --set 'contact.rebuild="step"' --set 'output.dir="istep1"' > istep1.log 2>&1
check "... and with rebuild = step" test $? -eq 0
for np in 2 4; do
  "$mpirun" --oversubscribe -np "$np" "$fdem" run impact.toml "${iset[@]}" --set "output.dir=\"inp$np\"" > "inp$np.log" 2>&1
  check "the impact over $np ranks runs" test $? -eq 0
done
"$mpirun" --oversubscribe -np 2 "$fdem" run impact.toml "${iset[@]}" --set 'contact.rebuild="step"' \
  --set 'output.dir="istep2"' > istep2.log 2>&1
check "the impact with rebuild = step over 2 ranks runs" test $? -eq 0
for f in impact.exo impact_history.nc; do
  check "inp2/$f byte-identical to one process" cmp -s "ione/$f" "inp2/$f"
  check "inp4/$f byte-identical to one process" cmp -s "ione/$f" "inp4/$f"
  check "istep2/$f (rebuild = step) byte-identical to one process" cmp -s "istep1/$f" "istep2/$f"
done

# A node that travels beyond the contact ghosts (--contact-travel 1 mm; the disc falls
# further) stops every rank at a detection with exit 2 and one message.
"$mpirun" --oversubscribe -np 2 "$fdem" run impact.toml "${iset[@]}" --contact-travel 0.001 \
  --set 'output.dir="itravel"' > itravel.log 2>&1
check "travel beyond the contact ghosts: exit 2" test $? -eq 2
check "... saying so" grep -q "more than 0.001 m from its start" itravel.log
check "... once" test "$(grep -c '^error:' itravel.log)" -eq 1

# The column started in its in-situ state ([in_situ] growing with depth below its top) with
# a heterogeneous E ([material.heterogeneity]): each rank computes its elements' initial
# stress and draws from its local model, so 2 ranks give one process's bytes.
hset=(--set 'in_situ.datum=100.0' --set 'in_situ.k_H=0.5'
      --set 'material.0.heterogeneity={homogeneity=3.0, seed=7, properties=["young"]}')
"$fdem" run column_small.toml "${hset[@]}" --quiet --set 'output.dir="hs1"' > hs1.log 2>&1
check "one process runs the column in situ, heterogeneous" test $? -eq 0
"$mpirun" --oversubscribe -np 2 "$fdem" run column_small.toml "${hset[@]}" --set 'output.dir="hs2"' > hs2.log 2>&1
check "... and over 2 ranks" test $? -eq 0
for f in column.exo column_history.nc; do
  check "hs2/$f byte-identical to one process" cmp -s "hs1/$f" "hs2/$f"
done

# A tunnel excavated from a plate in situ ([[excavation]], tests/data/cases/tunnel_small.*):
# 2 ranks give one process's bytes, and a checkpoint written by 2 ranks inside the ramp
# continues on one process to the same bytes (the released-energy array is per triangle).
cp "$src/data/cases/tunnel_small.msh" "$src/data/cases/tunnel_small.toml" .
"$fdem" run tunnel_small.toml --quiet --set 'output.dir="tun1"' > tun1.log 2>&1
check "one process runs the tunnel excavation" test $? -eq 0
"$mpirun" --oversubscribe -np 2 "$fdem" run tunnel_small.toml --set 'output.dir="tun2"' > tun2.log 2>&1
check "... and over 2 ranks" test $? -eq 0
"$mpirun" --oversubscribe -np 2 "$fdem" run tunnel_small.toml --set 'output.dir="tunr"' --set 'time.end=4.0e-3' > tunr.log 2>&1
check "2 ranks to the middle of the ramp" test $? -eq 0
"$fdem" run tunnel_small.toml --quiet --set 'output.dir="tunr"' --restart > tunr1.log 2>&1
check "one process continues it" test $? -eq 0
for f in tunnel.exo tunnel_history.nc; do
  check "tun2/$f byte-identical to one process" cmp -s "tun1/$f" "tun2/$f"
  check "tunr/$f (2 ranks, then one) byte-identical to one process" cmp -s "tun1/$f" "tunr/$f"
done

# Extrinsic CE4s (issue 33): the small blast without and with contact, its rock's CE4s
# inserted where an edge reaches the peak. A rank ties every mesh node it owns a copy of
# and exchanges its ghosts after the integration and after the tie: 2 and 4 ranks give one
# process's bytes; a checkpoint of 2 ranks continues on 4, one process's on 2.
xset=(--set 'material.0.fracture.model="extrinsic"')
"$fdem" run blast.toml --quiet "${xset[@]}" --set 'output.dir="xone"' > xone.log 2>&1
check "extrinsic: one process runs the small blast" test $? -eq 0
check "... breaking CE4s (each inserted first)" grep -q "[1-9][0-9]* CE4s broken" xone.log
split 2 xnp2 --partition metis "${xset[@]}"
check "extrinsic: mpirun -np 2 (METIS) runs" test $? -eq 0
split 4 xnp4 --partition bisection "${xset[@]}"
check "extrinsic: mpirun -np 4 (bisection) runs" test $? -eq 0
split 2 xhalf "${xset[@]}" --set 'time.end=1e-4'
check "extrinsic: 2 ranks to half the time" test $? -eq 0
split 4 xhalf "${xset[@]}" --restart
check "extrinsic: 4 ranks continue its checkpoint" test $? -eq 0
"$fdem" run blast.toml --quiet "${xset[@]}" --set 'output.dir="xhalf1"' --set 'time.end=1e-4' > xhalf1.log 2>&1
split 2 xhalf1 "${xset[@]}" --restart
check "extrinsic: 2 ranks continue one process's checkpoint" test $? -eq 0
for out in xnp2 xnp4 xhalf xhalf1; do
  for f in blast.exo blast_history.nc blast_fragments.nc blast_events.nc; do
    check "extrinsic: $out/$f byte-identical to one process" cmp -s "xone/$f" "$out/$f"
  done
done
"$fdem" run contact.toml --quiet "${xset[@]}" --set 'output.dir="xcone"' > xcone.log 2>&1
check "extrinsic with contact: one process" test $? -eq 0
# (The default contact travel: the extrinsic rock's pieces fly further than 0.02 m.)
csplit 2 xcnp2 "${xset[@]}" --partition metis
check "extrinsic with contact: 2 ranks (METIS)" test $? -eq 0
csplit 4 xcnp4 "${xset[@]}" --partition bisection
check "extrinsic with contact: 4 ranks (bisection)" test $? -eq 0
for out in xcnp2 xcnp4; do
  for f in blast.exo blast_history.nc blast_fragments.nc blast_events.nc; do
    check "extrinsic with contact: $out/$f byte-identical to one process" cmp -s "xcone/$f" "$out/$f"
  done
done

if [ "$fails" -ne 0 ]; then
  echo "$fails check(s) failed"
  exit 1
fi
echo "all checks passed"
