#!/bin/bash
# The blast's gas against Eq. 21 (cases/blasting/README.md, "Gas in the hole and the
# cracks"): both loads on the case's own mesh (0.012) to 400 µs, then cases/blasting/compare_gas.py,
# which prints the README's tables, draws its two figures (into OUT, not over the
# committed ones) and exits 1 when the gas's mass drifts by more than 0.1%, its energy
# error exceeds 1% or the hole's pressure does not fall. ctest label "validate" (about six
# minutes on PoCL, 2 cores). Usage: gas_blast_validate.sh FDEM OUT
set -euo pipefail
fdem=$1
out=$2
src=$(cd "$(dirname "$0")/.." && pwd)
common=(--set time.end=400e-6)
"$fdem" run "$src/cases/blasting/case.toml" "${common[@]}" --set "output.dir=\"$out/blasting-case-400\""
"$fdem" run "$src/cases/blasting/gas.toml" "${common[@]}" --set "output.dir=\"$out/blasting-gas-400\""
/usr/bin/python3 "$src/cases/blasting/compare_gas.py" "$out/blasting-case-400" "$out/blasting-gas-400" --figures "$out"
