#!/bin/bash
# KGD against its vertex solutions (cases/kgd/README.md): both runs at full size, then
# cases/kgd/compare.py (exit 1 when a figure is more than 10% off its vertex once the
# crack spans 20 edges, or the volumes do not balance within 0.1%). ctest label
# "validate" (tens of minutes on PoCL). Usage: kgd_validate.sh FDEM OUT
set -euo pipefail
fdem=$1
out=$2
src=$(cd "$(dirname "$0")/.." && pwd)
status=0
for regime in toughness viscosity; do
  "$fdem" run "$src/cases/kgd/$regime.toml" --set "output.dir=\"$out/kgd_$regime\""
  /usr/bin/python3 "$src/cases/kgd/compare.py" "$regime" "$out/kgd_$regime" --png "$out/kgd_$regime.png" || status=1
done
exit $status
