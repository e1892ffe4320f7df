#!/usr/bin/env bash
# Soak runs: rover's memory, pace and detector rate over a long run, sampled every 10 s, with
# an RSS plot drawn at the end (scripts/soak_plot.py).
#
#   scripts/soak.sh window [MINUTES]    the window under Xvfb (release build), follow mode in
#                                       worlds/walking.toml (a person walking a square), the
#                                       web viewer served and kept open in headless Chromium
#                                       for the whole run; default 10 minutes
#   scripts/soak.sh headless [MINUTES]  headless follow run in worlds/walking.toml with
#                                       --record (images at 1/4 size, 5 per sim second,
#                                       --record-no-footer: see docs/RELIABILITY.md) and
#                                       --trace, unpaced; default 60 sim minutes;
#                                       SOAK_FOOTER=1 keeps the footer
#
# Output in $SOAK_OUT (default target/soak/MODE/): rss.csv (wall_s, rss_mib), rover.log (the
# window's status lines / headless progress), rss.png, summary.txt. Needs what ./test installs
# (scripts/setup.sh: xvfb, chromium, node packages, the Python venv with Pillow).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
mode="${1:-}"
case "$mode" in
  window) minutes="${2:-10}" ;;
  headless) minutes="${2:-60}" ;;
  *) sed -n '2,19p' "$0"; exit 2 ;;
esac
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$HOME/.cache/rover/target}"
venv="$HOME/.cache/rover/venv"
[ -x "$venv/bin/python3" ] && export PATH="$venv/bin:$PATH"
out="${SOAK_OUT:-target/soak/$mode}"
mkdir -p "$out"
out="$(cd "$out" && pwd)"
cargo build --release --quiet
rover="$CARGO_TARGET_DIR/release/rover"
seconds=$((minutes * 60))
script="$out/follow.toml"
echo 'steps = [ { at = 0.0, toggle = "follow" } ]' > "$script"

echo "wall_s,rss_mib" > "$out/rss.csv"
sample() { # PID: RSS every 10 s until the process ends
  local pid="$1" t0
  t0=$(date +%s.%N)
  while kill -0 "$pid" 2>/dev/null; do
    local kb
    kb=$(ps -o rss= -p "$pid" 2>/dev/null | tr -d ' ') || true
    [ -n "$kb" ] && printf '%.1f,%.1f\n' "$(echo "$(date +%s.%N) - $t0" | bc)" "$(echo "$kb / 1024" | bc -l)" >> "$out/rss.csv"
    sleep 10
  done
}

if [ "$mode" = window ]; then
  web_port=$((20000 + RANDOM % 10000))
  grpc_port=$((web_port + 1))
  xvfb-run -a -s "-screen 0 1280x800x24" \
    "$rover" --world worlds/walking.toml --script "$script" --duration "$seconds" \
      --viewer web --web-port "$web_port" --grpc-port "$grpc_port" \
      > "$out/rover.out" 2> "$out/rover.log" &
  wrapper=$!
  pid=""
  for _ in $(seq 300); do
    pid=$(pgrep -f -n "release/rover --world worlds/walking.toml" || true)
    url=$(grep -o 'http://[^ ]*' "$out/rover.out" 2>/dev/null | head -n 1 || true)
    [ -n "$pid" ] && [ -n "$url" ] && break
    sleep 0.5
  done
  [ -n "$pid" ] && [ -n "$url" ] || { echo "soak: rover did not start; see $out/rover.log" >&2; exit 1; }
  echo "soak: window pid $pid, web viewer $url, $minutes min"
  # The web viewer stays open (connected and drawing) for the whole run.
  (cd scripts/webview && node screenshot.mjs "$url" "$out/web.png" --wait-s 600 \
      --hold-s $((seconds - 20)) > "$out/web.json" 2> "$out/web.log") &
  browser=$!
  sample "$pid"
  wait "$wrapper" || true
  wait "$browser" || true
  grep -o 'status: .*' "$out/rover.log" > "$out/status.txt" || true
  {
    echo "window soak, $minutes min, worlds/walking.toml, follow mode, web viewer in headless Chromium"
    python3 scripts/soak_plot.py "$out/rss.csv" "$out/rss.png" "rover window soak: RSS, $minutes min"
    echo "status lines: $(wc -l < "$out/status.txt") (every 10 s); after the first minute:"
    tail -n +7 "$out/status.txt" | awk -F'[ ,]+' '
      BEGIN { n = 0 }
      { for (i = 1; i <= NF; i++) { if ($(i+1) == "real") rtf[n] = $i; if ($i == "detector") hz[n] = $(i+1) } n++ }
      END { if (n == 0) exit; minr = maxr = rtf[0]; minh = maxh = hz[0]
            for (i = 0; i < n; i++) { sr += rtf[i]; sh += hz[i]
              if (rtf[i] < minr) minr = rtf[i]; if (rtf[i] > maxr) maxr = rtf[i]
              if (hz[i] < minh) minh = hz[i]; if (hz[i] > maxh) maxh = hz[i] }
            printf "  sim pace %.3f x real time (min %.2f, max %.2f); detector %.2f Hz (min %.1f, max %.1f)\n", sr / n, minr, maxr, sh / n, minh, maxh }'
    echo "web viewer: $(cat "$out/web.json")"
  } | tee "$out/summary.txt"
else
  "$rover" --headless --world worlds/walking.toml --script "$script" --duration "$seconds" \
    --record "$out/soak.rrd" $([ -n "${SOAK_FOOTER:-}" ] || echo --record-no-footer) --image-downscale 4 --image-hz 5 --trace "$out/trace.csv" \
    > "$out/rover.out" 2> "$out/rover.log" &
  pid=$!
  echo "soak: headless pid $pid, $minutes sim minutes"
  sample "$pid"
  wait "$pid"
  {
    echo "headless soak, $minutes sim min, worlds/walking.toml, follow mode, --record (1/4 size, 5 Hz images${SOAK_FOOTER:+, with footer}${SOAK_FOOTER:-, --record-no-footer}) + --trace"
    python3 scripts/soak_plot.py "$out/rss.csv" "$out/rss.png" "rover headless soak: RSS, $minutes sim min with --record"
    grep -E '^rover:|^recording:|^trace:' "$out/rover.out"
  } | tee "$out/summary.txt"
fi
echo "soak: figures in $out/summary.txt, plot $out/rss.png"
