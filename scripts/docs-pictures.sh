#!/usr/bin/env bash
# Redraws the pictures README.md and docs/ show, each from a named world and script, with
# today's rover, and says what it wrote. Run it when what rover draws changes (a body, a
# mesh, the HUD, the Rerun layout, a sensor's drawing): see docs/TESTING.md.
#
#   scripts/docs-pictures.sh            every picture below
#   scripts/docs-pictures.sh NAME...    only these (e.g. camera-playground window)
#   scripts/docs-pictures.sh --long     every picture, the 70 minutes of soak plots too
#
# Deterministic (the same bytes on every run, on any machine with the same renderer):
#   camera-playground   worlds/playground.toml, examples/scripts/follow.toml: the car's camera
#                       at 4 s, following MakeHuman's walker, YOLO's boxes drawn (rover detect)
#   person-sweep        rover bench people (worlds/people.toml): MakeHuman's body standing at
#                       3, 5 and 8 m, facing the camera, YOLO's boxes drawn, side by side
#   robots              turtlebot3-burger.png and tiago.png: each robot at rest from 1.2 m
#                       (tests/tests/robots.rs with ROVER_SAVE_VIEWS; needs ../shared's corpus
#                       and example-robot-data from set-up)
#   playground-world    the tutorial car's first camera image in turtlebot_gazebo's
#                       playground.world (../shared/corpus; skipped without it)
#   arm-car-reach       worlds/arm_car_reach.toml's workspace camera 5 s into
#                       examples/scripts/reach.toml: the hand 10 cm short of the ball
#   people-dataset      rover dataset on the playground (seed 11), the first 16 people seen
#                       whole (scripts/people_grid.py)
#   street              street-textured.png (tests/worlds/street.world from a 1 m mast, as
#                       tests/tests/ground_truth.rs renders it) and dataset-street.png (a rover
#                       dataset of it, scripts/dataset_preview.py); needs ../shared's models
# Live (a window or a browser on wall time, so their bytes differ between runs):
#   window              the driver's station under Xvfb in worlds/playground.toml, `f` pressed:
#                       the follower at work, boxes and HUD (the detector on its own thread)
#   arm-car-window      the arm car's window (worlds/arm_car.toml) after driving and jogging
#                       its shoulder lift and elbow with the keys, as tests/window.rs does
#   rerun-web           a headless follow run in worlds/playground.toml served to Rerun's web
#                       viewer, shot in headless Chromium: 3D scene, camera, plots
#   rerun-ground-truth  worlds/playground.toml followed at once with --ground-truth: the truth
#                       boxes beside YOLO's
#   fetch-rerun         worlds/arm_car_fetch.toml's fetch (pick toggled at 1 s) at its end, 38 s
#   rerun-vlp16         the VLP-16 car in worlds/people.toml in Rerun's web viewer: its cloud
# Long (measurement runs, only when named or with --long):
#   soak-window         scripts/soak.sh window: the window's RSS over a 10-minute soak
#   soak-headless       scripts/soak.sh headless: RSS over a 60-minute headless recording
#
# Needs what ./run and ./test set up (scripts/setup.sh: the detector model, MakeHuman's body,
# xvfb, xdotool, chromium and the node packages, the Python venv with Pillow).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$HOME/.cache/rover/target}"
cache="${ROVER_CACHE_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/rover}"
python="$cache/venv/bin/python3"
all=(camera-playground person-sweep robots playground-world arm-car-reach people-dataset street
  window arm-car-window rerun-web rerun-ground-truth fetch-rerun rerun-vlp16)
long=(soak-window soak-headless)
wanted=("$@")
if [ ${#wanted[@]} -eq 0 ]; then
  wanted=("${all[@]}")
elif [ "${wanted[*]}" = "--long" ]; then
  wanted=("${all[@]}" "${long[@]}")
fi
for name in "${wanted[@]}"; do
  case " ${all[*]} ${long[*]} " in
    *" $name "*) ;;
    *) echo "unknown picture '$name'; one of: ${all[*]} ${long[*]} (or --long)" >&2; exit 2 ;;
  esac
done

cargo build --release --quiet
rover="$CARGO_TARGET_DIR/release/rover"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
wrote() { echo "docs-pictures: wrote $1 ($2)"; }

camera_playground() {
  "$rover" --headless --world worlds/playground.toml --script examples/scripts/follow.toml \
    --duration 4 --save-frames "$work/frames" --frame-every 10 > "$work/run.log" 2>&1
  local frame
  frame="$(ls "$work/frames"/*.png | tail -n 1)"
  "$rover" detect "$frame" --out docs/camera-playground.png > /dev/null
  wrote docs/camera-playground.png "worlds/playground.toml at 4 s of examples/scripts/follow.toml, YOLO's boxes"
}

person_sweep() {
  "$rover" bench people --bodies makehuman --postures standing --save "$work/sweep" \
    > "$work/sweep.log" 2>&1
  local parts=()
  for d in 3 5 8; do
    local image="$work/sweep/makehuman/standing_000deg_${d}.0m.png"
    [ -f "$image" ] || { echo "no $image (rover bench people --save changed its names?)" >&2; exit 1; }
    "$rover" detect "$image" --out "$work/sweep_$d.png" > /dev/null
    parts+=("$work/sweep_$d.png")
  done
  "$python" - docs/person-sweep.png "${parts[@]}" <<'EOF'
import sys
from PIL import Image
out, paths = sys.argv[1], sys.argv[2:]
images = [Image.open(p).convert("RGB") for p in paths]
w, h = images[0].size
row = Image.new("RGB", (w * len(images) + 8 * (len(images) - 1), h), (24, 26, 30))
for i, im in enumerate(images):
    row.paste(im, (i * (w + 8), 0))
row.save(out, optimize=False)
EOF
  wrote docs/person-sweep.png "rover bench people, MakeHuman's body standing at 3, 5 and 8 m with YOLO's boxes"
}

robots() {
  ROVER_SAVE_VIEWS="$PWD/docs" cargo test --quiet --workspace --test robots \
    turtlebot3_and_tiago_render_with_their_meshes > "$work/robots.log" 2>&1 \
    || { cat "$work/robots.log" >&2; exit 1; }
  wrote docs/turtlebot3-burger.png "the TurtleBot3 burger from ../shared's xacro, at rest from 1.2 m"
  wrote docs/tiago.png "TIAGo from example-robot-data, at rest from 1.2 m"
}

arm_car_reach() {
  "$rover" --headless --world worlds/arm_car_reach.toml --script examples/scripts/reach.toml \
    --duration 5.5 --save-frames "$work/reach" --frame-every 5 > "$work/reach.log" 2>&1
  cp "$(ls "$work/reach"/*.png | tail -n 1)" docs/arm-car-reach.png
  wrote docs/arm-car-reach.png "worlds/arm_car_reach.toml's workspace camera 5 s after reach (examples/scripts/reach.toml)"
}

street() {
  local models=../shared/corpus/gazebo_models
  if [ ! -d "$models" ]; then
    echo "docs-pictures: skipped street: no $models (../shared beside the repository)" >&2
    return
  fi
  ROVER_TEST_OUT="$work" cargo test --quiet --workspace --test ground_truth \
    yolo_finds_the_textured_street_models > "$work/street.log" 2>&1 \
    || { cat "$work/street.log" >&2; exit 1; }
  cp "$work/street.png" docs/street-textured.png
  wrote docs/street-textured.png "tests/worlds/street.world from the tutorial car's camera on a 1 m mast"
  "$rover" dataset --world tests/worlds/street.world --model-path "$models" --out "$work/ds" \
    --images 80 --seed 3 --distance 3,9 > "$work/ds.log" 2>&1
  "$python" scripts/dataset_preview.py "$work/ds" docs/dataset-street.png 0 24 44 56 > /dev/null
  wrote docs/dataset-street.png "rover dataset of tests/worlds/street.world (seed 3), images 0 24 44 56 with their labels"
}

people_dataset() {
  "$rover" dataset --out "$work/people" --images 40 --seed 11 --distance 2.5,4 --background 0 \
    > "$work/people.log" 2>&1
  "$python" scripts/people_grid.py "$work/people" docs/people-dataset.png > /dev/null
  wrote docs/people-dataset.png "rover dataset on the playground (seed 11), the first 16 people seen whole"
}

playground_world() {
  local shared=../shared/corpus
  if [ ! -d "$shared/turtlebot_gazebo" ]; then
    echo "docs-pictures: skipped playground-world: no $shared (../shared beside the repository)" >&2
    return
  fi
  "$rover" --headless --world "$shared/turtlebot_gazebo/worlds/playground.world" \
    --model-path "$shared/gazebo_models" --no-detector --duration 0.1 \
    --save-frames "$work/world" > "$work/world.log" 2>&1
  cp "$(ls "$work/world"/*.png | head -n 1)" docs/playground-world.png
  wrote docs/playground-world.png "the tutorial car's first camera image in turtlebot_gazebo's playground.world"
}

# Runs the window under Xvfb in WORLD for SECONDS, runs KEYS (xdotool lines, in $KEYS) once it
# shows, and writes its last image to FILE.
window_shot() {
  local world="$1" seconds="$2" keys="$3" file="$4"
  cat > "$work/window.sh" <<'SCRIPT'
set -eu
"$ROVER" --world "$WORLD" --duration "$SECONDS_SIM" --screenshot "$SHOT" --viewer none \
  2> "$WORK/window.log" &
pid=$!
wid=$(timeout 120 xdotool search --sync --onlyvisible --name "driver's station" | head -n 1)
sleep 2
xdotool windowfocus --sync "$wid"
eval "$KEYS"
wait "$pid"
SCRIPT
  ROVER="$rover" WORLD="$world" SECONDS_SIM="$seconds" KEYS="$keys" SHOT="$PWD/$file" \
    WORK="$work" xvfb-run -a -s "-screen 0 1280x800x24" bash "$work/window.sh"
}

window() {
  window_shot worlds/playground.toml 5 "xdotool key f" docs/window.png
  wrote docs/window.png "the driver's station under Xvfb, worlds/playground.toml, follow mode at 5 s"
}

arm_car_window() {
  window_shot worlds/arm_car.toml 16 "xdotool keydown i; sleep 2; xdotool keyup i; sleep 1
xdotool key 2; for n in 1 2 3 4 5; do xdotool key bracketright; sleep 0.3; done
sleep 4; xdotool key 3; xdotool key bracketright; sleep 2" docs/arm-car-window.png
  wrote docs/arm-car-window.png "the arm car's window after driving and jogging its arm (worlds/arm_car.toml)"
}

# Serves `rover ARGS...` headless to the web viewer and shoots it into FILE.
web_shot() {
  local file="$1"
  shift
  local web_port=$((20000 + RANDOM % 10000))
  local grpc_port=$((web_port + 1))
  "$rover" --headless --viewer web --web-port "$web_port" --grpc-port "$grpc_port" "$@" \
    > "$work/web.out" 2> "$work/web.log" &
  local pid=$!
  local url=""
  for _ in $(seq 300); do
    url="$(grep -o 'still serving the web viewer at [^ ]*' "$work/web.out" | awk '{print $NF}' || true)"
    [ -n "$url" ] && break
    sleep 1
  done
  [ -n "$url" ] || { kill "$pid"; cat "$work/web.log" >&2; echo "rover never served the viewer" >&2; exit 1; }
  node scripts/webview/screenshot.mjs "$url" "$file" --wait-s 150 > "$work/shot.json" 2> /dev/null \
    || { kill "$pid"; cat "$work/shot.json" >&2; exit 1; }
  kill "$pid" 2> /dev/null || true
  wait "$pid" 2> /dev/null || true
}

rerun_web() {
  web_shot docs/rerun-web.png --world worlds/playground.toml --script examples/scripts/follow.toml \
    --duration 8
  wrote docs/rerun-web.png "Rerun's web viewer in headless Chromium: worlds/playground.toml, follow mode"
}

rerun_ground_truth() {
  echo 'steps = [ { at = 0.0, toggle = "follow" } ]' > "$work/follow.toml"
  web_shot docs/rerun-ground-truth.png --script "$work/follow.toml" --ground-truth --duration 6
  wrote docs/rerun-ground-truth.png "Rerun's web viewer: worlds/playground.toml followed at once, --ground-truth"
}

fetch_rerun() {
  echo 'steps = [ { at = 1.0, toggle = "pick" } ]' > "$work/pick.toml"
  web_shot docs/fetch-rerun.png --world worlds/arm_car_fetch.toml --script "$work/pick.toml" \
    --duration 38
  wrote docs/fetch-rerun.png "Rerun's web viewer at the end of worlds/arm_car_fetch.toml's fetch"
}

rerun_vlp16() {
  web_shot docs/rerun-vlp16.png --world worlds/people.toml \
    --robot assets/robots/my_robot_vlp16.urdf.xacro --no-detector --duration 3
  wrote docs/rerun-vlp16.png "Rerun's web viewer: the VLP-16 car's cloud in worlds/people.toml"
}

soak_window() {
  SOAK_OUT="$work/soak-window" scripts/soak.sh window
  cp "$work/soak-window/rss.png" docs/soak-window-rss.png
  wrote docs/soak-window-rss.png "scripts/soak.sh window: RSS over a 10-minute soak"
}

soak_headless() {
  SOAK_OUT="$work/soak-headless" scripts/soak.sh headless
  cp "$work/soak-headless/rss.png" docs/soak-headless-rss.png
  wrote docs/soak-headless-rss.png "scripts/soak.sh headless: RSS over a 60-minute recording"
}

for name in "${wanted[@]}"; do
  "${name//-/_}"
done
