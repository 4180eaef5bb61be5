#!/usr/bin/env bash
# The error the studio shows on an edited scene, measured in the real
# window: four panes (Whitted, path tracing, photon mapping, SPPM) on a
# preset whose camera was edited (so no built-in or cached reference fits),
# under Xvfb, for SECONDS; each pane's label as the studio printed it
# (measured "relMSE x" or "relMSE ≈x (own noise)"), then each pane's image
# against a 4096-spp reference of the same scene with that reference's own
# noise taken off (`gi-studio compare`), and the ratio of the two.
# Usage: benches/studio_error.sh [PRESET] [SECONDS]   (release build first)
set -euo pipefail
cd "$(dirname "$0")/.."
preset="${1:-cornell}"
seconds="${2:-30}"
bin="$(realpath target/release/gi-studio)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
export XDG_DATA_HOME="$work/data" XDG_CACHE_HOME="$work/cache" XDG_RUNTIME_DIR="$work/run"
mkdir -p "$XDG_RUNTIME_DIR" "$work/panes" && chmod 700 "$XDG_RUNTIME_DIR"

# The edit: one degree more field of view
python3 - "assets/scenes/$preset.ron" "$work/edited.ron" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
text = re.sub(r"fov_y_degrees: ([0-9.]+)", lambda m: f"fov_y_degrees: {float(m.group(1)) + 1.0}", text, count=1)
open(sys.argv[2], "w").write(text)
PY
size=$(python3 -c "import re; t=open('$work/edited.ron').read(); print(*re.search(r'width: (\d+), height: (\d+)', t).groups())")
read -r width height <<< "$size"

echo "truth: 4096 spp at $((width / 2))×$((height / 2))…"
"$bin" reference "$work/edited.ron" --spp 4096 --width $((width / 2)) --height $((height / 2)) \
    -o "$work/truth.exr" > /dev/null
run() {
    "$bin" --scene "$work/edited.ron" --panes 4 --screenshot "$work/shot.png" \
        --quit-after-seconds "$seconds" --save-panes "$work/panes"
}
if [ -n "${DISPLAY:-}" ]; then run > "$work/studio.log"; else
    xvfb-run -a -s "-screen 0 1600x1000x24" bash -c "$(declare -f run); work=$work seconds=$seconds bin=$bin run" \
        > "$work/studio.log"
fi
grep -E "^(pane|reference|Reference)" "$work/studio.log" || true
for i in 1 2 3 4; do
    shown=$(grep "^pane $i:" "$work/studio.log" | sed -E 's/.*relMSE [≈<]?([0-9.e+-]+).*/\1/')
    truth=$("$bin" compare "$work/panes/pane-$i.exr" "$work/truth.exr" | sed -nE 's/^relMSE ([0-9.e+-]+),.*/\1/p')
    kind=$(grep "^pane $i:" "$work/studio.log" | grep -oE "relMSE [≈<]" | sed 's/relMSE ≈/own noise/; s/relMSE </a bound/' || true)
    kind=${kind:-measured}
    python3 -c "print(f'pane $i: shown {float(\"$shown\"):.3e} ($kind), against the 4096-spp reference {float(\"$truth\"):.3e}: {float(\"$shown\") / float(\"$truth\"):.2f}')"
done
