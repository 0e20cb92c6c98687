#!/usr/bin/env python3
"""Test of tools/plot_report.py on a small report.json made here.

    python3 plot_report_test.py --script tools/plot_report.py --work DIR

The report has two levels, two materials, three environments and two models;
refined's MSE is near 1e-17 (one exactly 0), faithful's near 1e-5. The test
runs the script as `haarcast eval` does and checks that every PNG is written
at its documented size and is a real picture (many colours, not one flat
fill); then it imports the script to check that every MSE axis is logarithmic,
labelled, titled, with a legend, that all of them share one y range that
spans both variants, and that every figure's title names its frame size,
level and machine. Tiles of 128 px or more are laid out pixel for pixel. Exits 77 (ctest's skip code here) when no python3 with
matplotlib is found, naming the package to install.
"""

import argparse
import json
import os
import shutil
import struct
import subprocess
import sys
import zlib

SKIP = 77
MACHINE = {"cpu_model": "Test CPU 9000", "cores": 3, "load_average_at_start": "0.00 0.00 0.00"}
MACHINE_TEXT = "Test CPU 9000, 3 cores"


def python_with_matplotlib():
    """This interpreter if it has matplotlib, else the one eval would use."""
    candidates = [sys.executable]
    if os.environ.get("HAARCAST_PYTHON"):
        candidates = [os.environ["HAARCAST_PYTHON"]]
    elif os.path.exists("/usr/bin/python3"):
        candidates.append("/usr/bin/python3")
    for python in candidates:
        try:
            if subprocess.run([python, "-c", "import matplotlib"], capture_output=True).returncode == 0:
                return python
        except OSError:
            pass
    return None


def write_png(path, width, height, pixel):
    """A small RGB PNG from pixel(x, y) → (r, g, b), with the standard library only."""
    raw = b"".join(b"\0" + bytes(c for x in range(width) for c in pixel(x, y)) for y in range(height))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(raw)))
        f.write(chunk(b"IEND", b""))


def png_size(path):
    with open(path, "rb") as f:
        head = f.read(24)
    if head[:8] != b"\x89PNG\r\n\x1a\n" or head[12:16] != b"IHDR":
        raise AssertionError("%s is not a PNG" % path)
    return struct.unpack(">II", head[16:24])


def make_report(work):
    environments = ["grace", "uffizi", "ennis"]
    models = ["sphere", "bunny"]
    materials = ["alum-bronze", "blue-metallic-paint"]
    ks = [4, 16, 64, 256]
    gloss_materials = ["steel", "blue-metallic-paint", "alum-bronze"]
    report = {
        "config": {"environments": environments, "models": models, "levels": [5, 6], "quick": False,
                   "frame": 24, "rotations_per_model": 1, "machine": MACHINE},
        "mse": {},
        "tables": {},
        "figures": {"mse": {}},
        "glossiness": {
            "file": "glossiness.png",
            "model": "bunny",
            "environment": "grace",
            "level": 6,
            "method": "haar",
            "frame_size": 256,
            "light_coefficients": ks,
            "materials": gloss_materials,
            "tile_size": 24,
            "tiles": [],
        },
        "timings": {"tables_s": 1.0, "glossiness_s": 1.0, "truth_s": 1.0, "total_s": 3.0},
    }
    for level in (5, 6):
        key = "level%d" % level
        for mi, material in enumerate(materials):
            for ei, env in enumerate(environments):
                for oi, model in enumerate(models):
                    scale = 1.0 + ei + 2 * oi + 3 * mi + level
                    refined = 0.0 if (level, mi, ei, oi) == (5, 0, 0, 0) else 1e-17 * scale
                    faithful = 1e-5 * scale
                    report["mse"].setdefault(key, {}).setdefault(material, {}).setdefault(env, {})[model] = {
                        "refined": refined, "faithful": faithful}
                report["tables"].setdefault(key, {}).setdefault(material, {})[env] = {
                    "refined": 170.0 - ei, "faithful": 30.0 + ei}
            report["figures"]["mse"].setdefault(key, {})[material] = "mse_%s_%s.png" % (key, material)
    os.makedirs(os.path.join(work, "glossiness"))
    for r, k in enumerate(ks):
        row = []
        for c, material in enumerate(gloss_materials):
            name = "glossiness/k%d_%s.png" % (k, material)
            write_png(os.path.join(work, name), 24, 24,
                      lambda x, y, r=r, c=c: (10 * x, 10 * y, 50 * r + 30 * c))
            row.append(name)
        report["glossiness"]["tiles"].append(row)
    with open(os.path.join(work, "report.json"), "w") as f:
        json.dump(report, f, indent=2)
    return report


def check_picture(path, expected_size):
    import matplotlib.image as mpimg
    import numpy as np

    size = png_size(path)
    if size != expected_size:
        raise AssertionError("%s is %d×%d, expected %d×%d" % ((path,) + size + expected_size))
    pixels = mpimg.imread(path)[:, :, :3]
    colours = len(np.unique((pixels * 255).astype(np.uint8).reshape(-1, 3), axis=0))
    ink = float(np.mean(pixels < 0.5))  # dark pixels: text, axes, bars, tiles
    if colours < 50 or not 0.005 < ink < 0.9 or float(pixels.std()) < 0.05:
        raise AssertionError("%s looks blank or flat: %d colours, %.3f dark, std %.3f"
                             % (path, colours, ink, float(pixels.std())))


def load_script(script):
    import importlib.util

    spec = importlib.util.spec_from_file_location("plot_report", script)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def check_title(name, title, *parts):
    """The title names each of parts (frame size, level, machine)."""
    for part in parts:
        if part not in title:
            raise AssertionError("%s's title does not say %r: %r" % (name, part, title))


def check_axes(script, report, work):
    """Imports the script and checks the figures' axes and titles themselves (tiles in work)."""
    module = load_script(script)
    plt = module.load_matplotlib()
    ranges = set()
    for name, fig in module.mse_figures(plt, report):
        if not fig._suptitle or not fig._suptitle.get_text():
            raise AssertionError("%s has no title" % name)
        level = name.split("_")[1][len("level"):]
        check_title(name, fig._suptitle.get_text(), "level %s" % level, "24² frames", MACHINE_TEXT)
        if not fig.legends or len(fig.legends[0].get_texts()) != len(report["config"]["environments"]):
            raise AssertionError("%s has no legend with one entry per environment" % name)
        for ax in fig.axes:
            if ax.get_yscale() != "log":
                raise AssertionError("%s: the MSE axis is not logarithmic" % name)
            if not ax.get_title() or not ax.get_xlabel():
                raise AssertionError("%s: a panel lacks its title or x label" % name)
            if [t.get_text() for t in ax.get_xticklabels()] != report["config"]["models"]:
                raise AssertionError("%s: the x ticks are not the models" % name)
            ranges.add(ax.get_ylim())
        if not fig.axes[0].get_ylabel():
            raise AssertionError("%s has no y label" % name)
        plt.close(fig)
    if len(ranges) != 1:
        raise AssertionError("the MSE figures do not share one y range: %s" % sorted(ranges))
    lo, hi = ranges.pop()
    if not (lo <= 1e-17 and hi >= 1e-4):
        raise AssertionError("the shared y range %g..%g does not span both variants" % (lo, hi))
    fig = module.glossiness_figure(plt, report, work)
    check_title("glossiness.png", fig._suptitle.get_text(), "level 6", "256² frames",
                "%d px tiles" % report["glossiness"]["tile_size"], MACHINE_TEXT)
    plt.close(fig)


def native_tiles(work, report, size):
    """The tiles again at size px: 128 or more is drawn pixel for pixel."""
    for r, row in enumerate(report["glossiness"]["tiles"]):
        for c, name in enumerate(row):
            write_png(os.path.join(work, name), size, size, lambda x, y, r=r, c=c: (x % 256, y % 256, 50 * r + 30 * c))
    report["glossiness"]["tile_size"] = size
    with open(os.path.join(work, "report.json"), "w") as f:
        json.dump(report, f, indent=2)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--script", required=True)
    parser.add_argument("--work", required=True)
    args = parser.parse_args()

    python = python_with_matplotlib()
    if python is None:
        print("SKIP: no python3 with matplotlib here (apt-get install python3-matplotlib)")
        return SKIP
    if python != sys.executable:
        # Run the rest where matplotlib is.
        return subprocess.run([python, os.path.abspath(__file__)] + sys.argv[1:]).returncode

    shutil.rmtree(args.work, ignore_errors=True)
    os.makedirs(args.work)
    report = make_report(args.work)
    run = subprocess.run([python, args.script, os.path.join(args.work, "report.json")],
                         capture_output=True, text=True)
    if run.returncode != 0:
        raise AssertionError("plot_report.py failed (%d):\n%s%s" % (run.returncode, run.stdout, run.stderr))

    # 12×5 in at 100 dpi; the sheet: 0.9 + 3·2.0 + 2·0.1 + 0.15 in wide,
    # 0.95 + 4·2.0 + 3·0.1 + 0.15 in high (the script's layout constants).
    for level_key, materials in report["figures"]["mse"].items():
        for name in materials.values():
            check_picture(os.path.join(args.work, name), (1200, 500))
    check_picture(os.path.join(args.work, "glossiness.png"), (725, 940))
    check_axes(args.script, report, args.work)

    # 140 px tiles, one sheet pixel each: 0.9 + 3·1.4 + 2·0.1 + 0.15 in wide,
    # 0.95 + 4·1.4 + 3·0.1 + 0.15 in high.
    native_tiles(args.work, report, 140)
    run = subprocess.run([python, args.script, os.path.join(args.work, "report.json")],
                         capture_output=True, text=True)
    if run.returncode != 0:
        raise AssertionError("plot_report.py failed on 140 px tiles (%d):\n%s" % (run.returncode, run.stderr))
    check_picture(os.path.join(args.work, "glossiness.png"), (545, 700))

    # A tile that report.json names but that is missing: a clear error, status 2.
    os.remove(os.path.join(args.work, report["glossiness"]["tiles"][1][2]))
    run = subprocess.run([python, args.script, os.path.join(args.work, "report.json")],
                         capture_output=True, text=True)
    if run.returncode != 2 or "k16_alum-bronze.png is missing" not in run.stderr:
        raise AssertionError("a missing tile gave status %d and: %s" % (run.returncode, run.stderr))
    print("plot_report.py: %d figures checked" % (1 + sum(len(m) for m in report["figures"]["mse"].values())))
    return 0


if __name__ == "__main__":
    sys.exit(main())
