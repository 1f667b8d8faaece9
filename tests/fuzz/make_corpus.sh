#!/usr/bin/env bash
# Seed corpora for the fuzz targets (docs/fuzzing.md), from committed files only:
#   make_corpus.sh SOURCE_DIR OUT_DIR CHECKPOINT_SEED_WRITER
# writes OUT_DIR/{case,msh,geo,checkpoint}/. Called by the CMake target fuzz_corpus.
set -euo pipefail
src=$1 out=$2 ckpt_writer=$3
rm -rf "$out"
mkdir -p "$out"/{case,msh,geo,checkpoint}

# Cases: every committed case file, its mesh line pointed at a committed small mesh
# (fuzz_case's scratch directory holds column_small.msh and blast_small.msh), so that a
# seed gets past read_case into the mesh and the model. Cases whose regions match a small
# mesh keep their own mesh; the others get the column, which fails on their region names
# (still the whole of read_case first). Plus each case with --set lines (fuzz_case reads
# "#--set KEY=VALUE" lines as overrides).
n=0
for f in "$src"/cases/*/*.toml "$src"/tests/data/cases/*.toml; do
  n=$((n + 1))
  mesh=column_small.msh
  case $f in *blast*) mesh=blast_small.msh ;; esac
  base=$(basename "$(dirname "$f")")-$(basename "$f" .toml)
  sed -E "s/^([[:space:]]*)(geo|file)[[:space:]]*=.*/\1file = \"$mesh\"/; /^[[:space:]]*size[[:space:]]*=/d" "$f" \
    > "$out/case/$base.toml"
  { cat "$out/case/$base.toml"
    printf '#--set time.steps=3\n#--set output.frames=2\n#--set material.0.young=2e9\n#--set gravity.g=[0.0,-9.81]\n'
  } > "$out/case/$base-set.toml"
done
# The --set spellings of docs/case-format.md: tables, arrays of tables, bare words.
{ cat "$out/case/geostatic-case.toml"
  printf '#--set mesh.refine=1\n#--set time.dt="auto"\n#--set output.name=col\n#--set damping.local=0.5\n'
  printf '#--set material.0.viscosity=critical\n#--set boundary.0.fix=["x","y"]\n'
} > "$out/case/overrides.toml"
[ "$n" -gt 0 ] || { echo "make_corpus.sh: no case files under $src" >&2; exit 1; }

# Meshes: the reader's fixtures (MSH 2.2 and 4.1, ASCII and binary, both byte orders,
# and the malformed ones of tests/test_gmsh_reader.cpp) and the small case meshes.
cp "$src"/tests/data/gmsh/*.msh "$src"/tests/data/cases/*.msh "$out/msh/"

# .geo files: the cases' and the tests'. fuzz_geo takes the first byte as the size
# choice: 0 (the .geo's own default).
for f in "$src"/cases/*/*.geo "$src"/tests/data/*/*.geo; do
  { printf '\0'; cat "$f"; } > "$out/geo/$(basename "$(dirname "$f")")-$(basename "$f")"
done

# Checkpoints: written by the project's writer (tests/fuzz/checkpoint_seeds.cpp).
"$ckpt_writer" "$out/checkpoint"

for d in case msh geo checkpoint; do echo "fuzz corpus $d: $(ls "$out/$d" | wc -l) seeds"; done
