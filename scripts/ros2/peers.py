#!/usr/bin/env python3
"""Sets up real ROS 2 peers for rover's tests: rclpy on rmw_fastrtps_cpp, per distribution.

    python3 scripts/ros2/peers.py CACHE_DIR [DISTRO ...]      (default: jazzy kilted)

For each distribution, in CACHE_DIR/ros2/DISTRO:
  venv/        a Python virtual environment with the distribution's wheels from PyPI
               (scripts/ros2/DISTRO.txt: rclpy with Fast DDS, the message packages PyPI has, the
               rosidl generators), pinned and installed with --require-hashes --no-deps;
  interfaces/  the interface packages PyPI lacks (control_msgs, darknet_ros_msgs, tf2_msgs,
               gazebo_msgs: scripts/ros2/interfaces), generated with those wheels and Debian's C
               compiler, as colcon would build them;
  .complete    written last, holding a hash of the pins and the interface files: the tests use
               only a finished set-up, and a change to either rebuilds it.

A test runs `venv/bin/python` with PYTHONPATH=interfaces/lib/python3.11/site-packages and
LD_LIBRARY_PATH=interfaces/lib (rover_tests::rclpy). Prints one line per step with its time and
exits 1 when a distribution could not be set up, saying why. What is already complete is kept:
a second run needs no network.
"""

import hashlib
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
INTERFACES = HERE / "interfaces"
# The interface packages, dependencies first.
PACKAGES = ["control_msgs", "darknet_ros_msgs", "tf2_msgs", "gazebo_msgs"]
# pip 26.3: the venv's own pip (23.x) cannot build empy 4.2.1's sdist.
PIP = "pip==26.3 --hash=sha256:f3b60b20ffaadd4415ed7957212a38ac63fa4c5fa375bd0f4a797777940fad13\n"


def say(text):
    print(f"rover setup: ros2: {text}", file=sys.stderr, flush=True)


def fingerprint(distro):
    """What the set-up is made of: the pins, the interface files and this script."""
    h = hashlib.sha256()
    for path in [HERE / f"{distro}.txt", Path(__file__)] + sorted(INTERFACES.rglob("*")):
        if path.is_file():
            h.update(str(path.relative_to(HERE)).encode())
            h.update(path.read_bytes())
    return h.hexdigest()


def run(cmd, log, **kwargs):
    with open(log, "a") as out:
        out.write(f"$ {' '.join(str(c) for c in cmd)}\n")
        out.flush()
        done = subprocess.run(cmd, stdout=out, stderr=subprocess.STDOUT, **kwargs)
    if done.returncode != 0:
        raise RuntimeError(f"`{' '.join(str(c) for c in cmd[:4])} ...` failed: see {log}")


def install_venv(distro, venv, log):
    """The pinned wheels into a new venv."""
    if venv.exists():
        shutil.rmtree(venv)
    run([sys.executable, "-m", "venv", venv], log)
    py = venv / "bin" / "python"
    pip_pin = venv / "pip.txt"
    pip_pin.write_text(PIP)
    quiet = ["--quiet", "--disable-pip-version-check"]
    run([py, "-m", "pip", "install", *quiet, "--require-hashes", "--no-deps", "-r", pip_pin], log)
    run([py, "-m", "pip", "install", *quiet, "--require-hashes", "--no-deps",
         "-r", HERE / f"{distro}.txt"], log)
    # The wheels' exported CMake targets name the machine that built them: its Python and numpy
    # include folders. Point them at this venv's.
    info = subprocess.run(
        [py, "-c", "import sysconfig, numpy; print(sysconfig.get_paths()['include']); "
         "print(numpy.get_include())"],
        check=True, capture_output=True, text=True).stdout.split()
    py_include, numpy_include = info
    built_py = "/opt/python/cp311-cp311/include/python3.11"
    built_numpy = "/opt/python/cp311-cp311/lib/python3.11/site-packages/numpy/_core/include"
    for cmake in (venv / "share").rglob("*.cmake"):
        text = cmake.read_text(errors="surrogateescape")
        if built_py in text or built_numpy in text:
            text = text.replace(built_numpy, numpy_include).replace(built_py, py_include)
            cmake.write_text(text, errors="surrogateescape")


def build_interfaces(venv, prefix, work, log):
    """Each interface package, generated and installed into `prefix` (an ament prefix)."""
    if prefix.exists():
        shutil.rmtree(prefix)
    env = dict(os.environ)
    env["PATH"] = f"{venv / 'bin'}:{env.get('PATH', '')}"
    env["AMENT_PREFIX_PATH"] = f"{prefix}:{venv}"
    env["CMAKE_PREFIX_PATH"] = f"{prefix}:{venv}"
    env["PYTHONPATH"] = str(prefix / "lib" / "python3.11" / "site-packages")
    env["LD_LIBRARY_PATH"] = f"{prefix / 'lib'}:{venv / 'lib'}"
    jobs = str(os.cpu_count() or 2)
    for package in PACKAGES:
        build = work / package
        run([venv / "bin" / "cmake", "-S", INTERFACES / package, "-B", build,
             f"-DCMAKE_INSTALL_PREFIX={prefix}", f"-DPython3_EXECUTABLE={venv / 'bin' / 'python'}",
             "-DBUILD_TESTING=OFF", "-DCMAKE_BUILD_TYPE=Release"], log, env=env)
        run([venv / "bin" / "cmake", "--build", build, "-j", jobs], log, env=env)
        run([venv / "bin" / "cmake", "--install", build], log, env=env)


def check(venv, prefix):
    """rclpy starts a node on Fast DDS and every built package imports."""
    env = dict(os.environ)
    env["PYTHONPATH"] = str(prefix / "lib" / "python3.11" / "site-packages")
    env["LD_LIBRARY_PATH"] = str(prefix / "lib")
    script = (
        "import rclpy\n"
        "from rclpy.utilities import get_rmw_implementation_identifier as rmw\n"
        "from control_msgs.action import FollowJointTrajectory, GripperCommand\n"
        "from darknet_ros_msgs.msg import BoundingBoxes\n"
        "from tf2_msgs.msg import TFMessage\n"
        "from gazebo_msgs.msg import ModelStates\n"
        "rclpy.init(); node = rclpy.create_node('rover_setup_check'); node.destroy_node()\n"
        "print(rmw())\n"
    )
    out = subprocess.run([venv / "bin" / "python", "-c", script], env=env, capture_output=True,
                         text=True, timeout=60)
    if out.returncode != 0 or "rmw_fastrtps_cpp" not in out.stdout:
        raise RuntimeError(f"the set-up does not run: {(out.stderr or out.stdout).strip()[-400:]}")


def setup(cache, distro):
    root = cache / "ros2" / distro
    marker = root / ".complete"
    want = fingerprint(distro)
    if marker.exists() and marker.read_text().strip() == want:
        say(f"{distro}: ready in {root}")
        return
    root.mkdir(parents=True, exist_ok=True)
    log = root / "setup.log"
    log.write_text("")
    marker.unlink(missing_ok=True)
    venv, prefix, work = root / "venv", root / "interfaces", root / "build"
    started = time.monotonic()
    say(f"{distro}: installing rclpy with Fast DDS and the rosidl generators "
        f"(scripts/ros2/{distro}.txt, hash-checked) into {venv}")
    install_venv(distro, venv, log)
    installed = time.monotonic()
    say(f"{distro}: installed in {installed - started:.0f} s; building "
        f"{', '.join(PACKAGES)} from scripts/ros2/interfaces")
    build_interfaces(venv, prefix, work, log)
    built = time.monotonic()
    shutil.rmtree(work, ignore_errors=True)
    check(venv, prefix)
    marker.write_text(want + "\n")
    say(f"{distro}: interfaces built in {built - installed:.0f} s; ready in {root}")


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    cache = Path(sys.argv[1])
    distros = sys.argv[2:] or ["jazzy", "kilted"]
    failed = []
    for distro in distros:
        if not (HERE / f"{distro}.txt").exists():
            failed.append(f"{distro}: no pins (scripts/ros2/{distro}.txt)")
            continue
        try:
            setup(cache, distro)
        except (RuntimeError, OSError, subprocess.SubprocessError) as e:
            failed.append(f"{distro}: {e}")
    for line in failed:
        say(f"could not set up {line}; set-up stops here (the tests read only rover's cache)")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
