#!/usr/bin/env bash
# The real window keeps what a user makes: the studio started under Xvfb,
# an edit made with the mouse (three wheel notches over the pane dolly the
# camera), a wait past the autosave interval, `kill -9`, and a second start:
# it must offer the edit back, naming the camera. Then the same window
# destroyed by the X server (`xdotool windowclose`): the studio must exit
# cleanly (winit panics there; the studio catches it).
# Usage: .ci/studio-crash.sh path/to/gi-studio
set -euo pipefail
bin="$(realpath "$1")"
root="$(mktemp -d)"
trap 'kill -9 "${studio:-0}" 2>/dev/null || true; [ -n "${KEEP:-}" ] || rm -rf "$root"' EXIT
export XDG_DATA_HOME="$root/data" XDG_CACHE_HOME="$root/cache" XDG_RUNTIME_DIR="$root/run"
mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"
fail() { echo "studio crash test: $*" >&2; exit 1; }

if [ -z "${DISPLAY:-}" ]; then
    exec xvfb-run -a -s "-screen 0 1600x1000x24" "$0" "$@"
fi

window() { xdotool search --sync --onlyvisible --name "GI Studio" | head -n 1; }

# 1. Start, edit, wait past the interval (10 s), crash
"$bin" > "$root/first.log" 2>&1 &
studio=$!
id=$(timeout 60 bash -c "$(declare -f window); window") || fail "no window"
sleep 3
eval "$(xdotool getwindowgeometry --shell "$id")"
# The pane's image: right of the inspector, in the upper part
xdotool mousemove --window "$id" $((WIDTH * 3 / 5)) $((HEIGHT * 2 / 5))
for _ in 1 2 3; do xdotool click 4; sleep 0.2; done
sleep 14
kill -9 "$studio"
wait "$studio" 2>/dev/null || true
state="$XDG_DATA_HOME/gistudio/app.ron"
[ -s "$state" ] || fail "the studio wrote no state in 14 s"
grep -q '"autosave_scene": "(' "$state" || { cat "$state" >&2; fail "no autosaved scene in $state"; }

# 2. Start again: the edit is offered back (a screenshot run shows the
# offer as any start does, and answers nothing)
"$bin" --screenshot "$root/offer.png" --quit-after-passes 1 > "$root/second.log" 2>&1 || { cat "$root/second.log" >&2; fail "the second start failed"; }
grep -q "offered back: the last session's unsaved scene (the camera)" "$root/second.log" ||
    { cat "$root/second.log" >&2; fail "the edit was not offered back"; }
test -s "$root/offer.png"

# 3. The window destroyed under the studio: a clean exit
"$bin" > "$root/third.log" 2>&1 &
studio=$!
id=$(timeout 60 bash -c "$(declare -f window); window") || fail "no window the third time"
sleep 3
xdotool windowclose "$id"
code=0
wait "$studio" || code=$?
[ "$code" = 0 ] || { cat "$root/third.log" >&2; fail "exit $code when the window was destroyed"; }
grep -q "The window system destroyed the window" "$root/third.log" || { cat "$root/third.log" >&2; fail "no word of the window"; }
echo "studio crash test: the edit was autosaved, offered back, and a destroyed window closed the studio cleanly"
