#!/usr/bin/env bash
# BDPT at equal time on a sunlit box (benches/scenes/sun-box.ron), two
# builds interleaved: each round renders OLD then NEW for SECONDS with the
# round's seed; then each image's relMSE against a long reference, the
# share of it in the worst 1% of pixels, and what is left without them; the
# same for path tracing (NEW) for comparison (relMSE here: per pixel, the
# mean over channels of (image − reference)² / (reference² + 0.01)).
# Heavy-tailed errors (rare bright connections) make single runs erratic:
# quote means and medians.
# Usage: benches/sun_bdpt.sh OLD_BINARY NEW_BINARY [ROUNDS] [SECONDS]
# Needs python3 with numpy and OpenEXR (e.g. a venv: pip install numpy OpenEXR).
set -euo pipefail
cd "$(dirname "$0")/.."
old="$(realpath "$1")" new="$(realpath "$2")" rounds="${3:-8}" seconds="${4:-20}"
python="${PYTHON:-python3}"
scene=benches/scenes/sun-box.ron
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
echo "reference: BDPT for $((seconds * 12)) s…"
"$new" render "$scene" --algo bdpt --time $((seconds * 12)) --seed 77 -o "$work/reference.exr" > /dev/null
for round in $(seq 1 "$rounds"); do
    for build in old new; do
        bin=$old; [ "$build" = new ] && bin=$new
        "$bin" render "$scene" --algo bdpt --time "$seconds" --seed $((200 + round)) -o "$work/bdpt-$build-$round.exr" > /dev/null
    done
    "$new" render "$scene" --algo path --time "$seconds" --seed $((200 + round)) -o "$work/path-$round.exr" > /dev/null
    echo "round $round of $rounds"
done
"$python" - "$work" "$rounds" <<'PY'
import sys, numpy as np, OpenEXR
work, rounds = sys.argv[1], int(sys.argv[2])
def load(name):
    with OpenEXR.File(f"{work}/{name}.exr") as f:
        ch = f.channels()
        rgb = ch["RGB"].pixels if "RGB" in ch else np.stack([ch[k].pixels for k in "RGB"], -1)
        return rgb.astype(np.float64)
ref = load("reference")
for kind in ["bdpt-old", "bdpt-new", "path"]:
    rows = []
    for r in range(1, rounds + 1):
        e = (((load(f"{kind}-{r}") - ref) ** 2) / (ref ** 2 + 1e-2)).mean(-1).ravel()
        worst = np.sort(e)[::-1][: max(1, e.size // 100)]
        rows.append((e.mean(), worst.sum() / e.sum(), (e.sum() - worst.sum()) / (e.size - worst.size)))
    rel, share, rest = map(np.array, zip(*rows))
    print(f"{kind:9s} relMSE mean {rel.mean():.3e} median {np.median(rel):.3e}  "
          f"worst-1% share median {np.median(share):.2f}  without it {np.median(rest):.3e}")
PY
