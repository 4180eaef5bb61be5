#!/usr/bin/env bash
# Path tracing's samples per second on metals.ron with its rough metal
# plates, against the same scene with Phong plates (ks the aluminium's
# colour at normal incidence, exponent 2/α² − 2, the lobe of like width):
# the rough lobes run in the lanes as the Phong lobe does. Interleaved
# runs; prints each run and the medians.
#   bash benches/rough_vs_phong.sh [runs] [binary]
set -euo pipefail
runs=${1:-7}
bin=${2:-target/release/gi-studio}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
cp assets/scenes/metals.ron "$dir/rough.ron"
python3 - "$dir" <<'PY'
import re, sys
d = sys.argv[1]
s = open(f"{d}/rough.ron").read()
def phong(m):
    a = float(m.group(1))
    return f"Phong(ka: (0.0, 0.0, 0.0), kd: (0.0, 0.0, 0.0), ks: (0.91, 0.92, 0.92), shininess: {2 / a**2 - 2:.1f})"
s = re.sub(r"Conductor\(metal: Aluminium, alpha_u: ([0-9.]+), alpha_v: [0-9.]+\)", phong, s)
open(f"{d}/phong.ron", "w").write(s)
PY
for i in $(seq "$runs"); do
  for kind in rough phong; do
    line=$("$bin" render "$dir/$kind.ron" --algo path --spp 128 --width 512 --height 384 -o "$dir/$kind.exr" --force 2>&1 | tail -1)
    rate=$(sed -E 's/.* ([0-9.]+) M samples\/s.*/\1/' <<<"$line")
    echo "$kind $rate"
  done
done | tee "$dir/runs.txt"
for kind in rough phong; do
  median=$(awk -v k="$kind" '$1 == k { print $2 }' "$dir/runs.txt" | sort -n | awk '{ a[NR] = $1 } END { print a[int((NR + 1) / 2)] }')
  echo "median $kind: $median M samples/s"
done
