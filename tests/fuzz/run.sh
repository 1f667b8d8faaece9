#!/usr/bin/env bash
# One fuzz target's CI run (ctest label "fuzz", docs/fuzzing.md):
#   run.sh FUZZER CORPUS_ROOT REGRESSIONS_ROOT
# 1. replays every recorded input of REGRESSIONS_ROOT/<target>/ (each must now be a clean
#    refusal), except those named in REGRESSIONS_ROOT/PENDING (inputs whose fix is not
#    merged yet; each line says where the fix belongs);
# 2. fuzzes for FDEM_FUZZ_SECONDS (default 20) from a copy of CORPUS_ROOT/<target>/ on
#    one core. Any crash, sanitizer report, leak, timeout (10 s an input) or use of more
#    than 2 GB fails the test; the input is kept in fuzz/artifacts/<target>/ of the
#    build directory.
set -euo pipefail
fuzzer=$1 corpus_root=$2 regressions=$3
name=$(basename "$fuzzer"); name=${name#fuzz_}
seconds=${FDEM_FUZZ_SECONDS:-20}
build_dir=$(dirname "$corpus_root")
artifacts=$build_dir/artifacts/$name
scratch_root=/tmp
[ -d /dev/shm ] && [ -w /dev/shm ] && scratch_root=/dev/shm
work=$(mktemp -d "$scratch_root/fdem-fuzz-$name.XXXXXX")
trap 'rm -rf "$work"' EXIT
export FDEM_FUZZ_SCRATCH=$work  # the targets' scratch directories (tests/fuzz/fuzz_common.hpp)
mkdir -p "$artifacts"
dict=$(dirname "$0")/$name.dict
opts=(-timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=2048 -print_final_stats=1 "-artifact_prefix=$artifacts/")
[ -f "$dict" ] && opts+=("-dict=$dict")
# Extra libFuzzer flags of one target, one a line, each with its reason (# comments).
extra=$(dirname "$0")/$name.options
[ -f "$extra" ] && while read -r flag; do opts+=("$flag"); done < <(grep -v '^[[:space:]]*\(#\|$\)' "$extra")
# allocator_may_return_null: a C library's malloc (libnetcdf's) of an impossible size
# returns NULL, as it would without ASan, and the library reports it; C++ new still
# reports it (an allocation from a size our code read without a bound is a finding).
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}

if [ -d "$regressions/$name" ]; then
  inputs=()
  for f in "$regressions/$name"/*; do
    [ -f "$f" ] || continue
    if [ -f "$regressions/PENDING" ] && grep -qxF "$name/$(basename "$f")" "$regressions/PENDING"; then
      echo "skipped (listed in PENDING: its fix is not merged yet): $name/$(basename "$f")"
      continue
    fi
    inputs+=("$f")
  done
  if [ ${#inputs[@]} -gt 0 ]; then
    echo "replaying ${#inputs[@]} recorded inputs of $regressions/$name"
    # Raw: fuzz_checkpoint's netCDF header check must not turn a recorded input away
    # before the reader sees it.
    FDEM_FUZZ_RAW_NETCDF=1 "$fuzzer" "${opts[@]}" "${inputs[@]}"
  fi
fi

[ -d "$corpus_root/$name" ] || { echo "no seed corpus $corpus_root/$name: build the fuzz_corpus target" >&2; exit 1; }
cp -r "$corpus_root/$name" "$work/corpus"
echo "fuzzing $name for $seconds s from $(ls "$work/corpus" | wc -l) seeds"
"$fuzzer" "${opts[@]}" -max_total_time="$seconds" "$work/corpus"
