#!/usr/bin/env python3
"""Checks deploy/run.sh's package roles against the built binaries and the
Dockerfile, standing in for a container build where no Docker engine runs:

- every shared library the binaries name as NEEDED (readelf -d) comes from a
  package in the runtime list, or from one every Debian image has (Essential
  packages and what they depend on, recursively);
- the Vulkan loader and Mesa's Vulkan drivers (dlopen'd, so never NEEDED)
  are in the runtime list;
- the runtime list carries no headers, compilers or test tools: no -dev
  package, nothing from the build or test lists;
- the Dockerfile installs packages only through `run.sh install ROLE` (one
  list per role, nowhere else), the build stage's roles and the runtime
  stage's runtime role alone.

Exit 77 (skip) without dpkg-query or readelf (not a Debian system).
"""
import argparse
import os
import re
import shutil
import subprocess
import sys

SKIP = 77
DLOPENED = ("libvulkan1", "mesa-vulkan-drivers")  # the loader, lavapipe's ICD


def run(*cmd):
    return subprocess.run(cmd, capture_output=True, text=True, check=True).stdout


def role(run_sh, name):
    return run("bash", run_sh, "packages", name).split()


def needed(binary):
    """NEEDED sonames of an ELF file."""
    return re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]", run("readelf", "-d", binary))


def resolved(binary):
    """soname → path, as the dynamic loader finds it (ldd)."""
    paths = {}
    for line in run("ldd", binary).splitlines():
        m = re.match(r"\s*(\S+) => (/\S+)", line)
        if m:
            paths[m.group(1)] = m.group(2)
    return paths


def owner(path):
    """The package that ships path, trying the merged-/usr twin (/lib ↔ /usr/lib)."""
    real = os.path.realpath(path)
    candidates = {path, real}
    for p in list(candidates):
        candidates.add(p[4:] if p.startswith("/usr/") else "/usr" + p)
    for p in candidates:
        r = subprocess.run(["dpkg-query", "-S", p], capture_output=True, text=True)
        if r.returncode == 0:
            return r.stdout.split(":")[0].strip()
    return None


def base_image_packages():
    """Essential packages and their Depends/Pre-Depends, recursively, among
    the installed ones: what every Debian image (debian:bookworm-slim) has."""
    fmt = "${Package}\t${Essential}\t${Pre-Depends}, ${Depends}\n"
    deps, essential = {}, []
    for line in run("dpkg-query", "-W", "-f", fmt).splitlines():
        pkg, ess, rest = line.split("\t")
        names = [re.split(r"[\s(:]", alt.strip())[0] for alt in re.split(r"[,|]", rest) if alt.strip()]
        deps[pkg] = names
        if ess == "yes":
            essential.append(pkg)
    seen, todo = set(), list(essential)
    while todo:
        pkg = todo.pop()
        if pkg in seen or pkg not in deps:
            continue
        seen.add(pkg)
        todo.extend(deps[pkg])
    return seen


def dockerfile_stages(path):
    """{stage name: its instructions as one string}, continuation lines joined."""
    with open(path, encoding="utf-8") as f:
        text = re.sub(r"\\\n", " ", f.read())
    stages, name = {}, None
    for line in text.splitlines():
        if line.lstrip().startswith("#"):
            continue
        m = re.match(r"FROM\s+\S+\s+AS\s+(\S+)", line, re.I)
        if m:
            name = m.group(1)
            stages[name] = ""
        elif name:
            stages[name] += line + "\n"
    return stages


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--run-sh", required=True, help="deploy/run.sh")
    parser.add_argument("--dockerfile", required=True, help="deploy/Dockerfile")
    parser.add_argument("binaries", nargs="+", help="the binaries the image ships")
    opts = parser.parse_args()
    for tool in ("dpkg-query", "readelf", "ldd"):
        if not shutil.which(tool):
            print(f"SKIP: no {tool} (a Debian system with binutils is needed)")
            return SKIP

    build, runtime, test = (role(opts.run_sh, r) for r in ("build", "runtime", "test"))
    failures = []
    base = base_image_packages()

    for binary in opts.binaries:
        paths = resolved(binary)
        for soname in needed(binary):
            if soname not in paths:
                failures.append(f"{binary}: NEEDED {soname} is not found by the loader here")
                continue
            pkg = owner(paths[soname])
            if pkg is None:
                failures.append(f"{binary}: {soname} ({paths[soname]}) belongs to no package")
            elif pkg not in runtime and pkg not in base:
                failures.append(f"{binary}: {soname} comes from {pkg}, which is neither in run.sh's runtime list "
                                f"nor in every Debian image")
            else:
                print(f"{os.path.basename(binary)}: {soname} <- {pkg}{' (base image)' if pkg not in runtime else ''}")

    for pkg in DLOPENED:
        if pkg not in runtime:
            failures.append(f"{pkg} (loaded with dlopen) is not in the runtime list")
    for pkg in runtime:
        if pkg.endswith("-dev") or pkg in build or pkg in test:
            failures.append(f"runtime package {pkg} is a -dev package or also in the build or test list")

    stages = dockerfile_stages(opts.dockerfile)
    if "apt-get install" in "".join(stages.values()) or "apt install" in "".join(stages.values()):
        failures.append("the Dockerfile installs packages itself: use deploy/run.sh install ROLE")
    installs = {name: re.findall(r"run\.sh install ([a-z ]+?)\s*(?:&&|\n|$)", body) for name, body in stages.items()}
    expected = {"build": ["build runtime"], "runtime": ["runtime"]}
    if installs != expected:
        failures.append(f"the Dockerfile's stages install {installs}, expected {expected}")

    for f in failures:
        print(f"FAIL: {f}")
    if failures:
        return 1
    print(f"PASS: {len(runtime)} runtime packages cover the NEEDED libraries of {len(opts.binaries)} binaries")
    return 0


if __name__ == "__main__":
    sys.exit(main())
