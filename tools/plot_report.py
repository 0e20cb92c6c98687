#!/usr/bin/env python3
"""Draws the figures of `haarcast eval` and `haarcast loadtest` from their
report.json, with matplotlib.

    python3 tools/plot_report.py eval/report.json [--out DIR]
    python3 tools/plot_report.py build/loadtest/report.json [--out DIR]

`haarcast eval` runs this itself when python3 has matplotlib (Debian:
`apt-get install python3-matplotlib`). It writes, beside report.json or into
DIR, the files that report.json names:

  figures.mse.levelL.MATERIAL  (e.g. mse_level6_alum-bronze.png)
      The MSE of `haar` against `spatial` over the object's pixels, one panel
      per variant (refined, faithful), bars per model (groups) and environment
      (colours). Every MSE figure of a report shares one logarithmic y axis,
      so that bar heights compare across variants, materials and levels.
  glossiness.file  (glossiness.png)
      The glossiness tiles (glossiness.tiles, one PNG per material and light
      coefficient count, written by eval) laid out in a labelled grid, one
      screen pixel per tile pixel when the tiles are 128 px or more.

Every figure's title names its frame size, map level and machine (the CPU
model and core count of report.json's machine, config.machine for eval).

A loadtest report ("kind": "loadtest") gets the three files it lists under
"figures": loadtest_bandwidth.png (Mbit/s per client against clients, a line
per method), loadtest_fps.png (fps per client against clients: the median,
bars from the slowest to the fastest client) and loadtest_storage.png (stored
bytes per method on a logarithmic axis, at the runs' level and at the
storage level, with the PRT downloads).

Headless: matplotlib's Agg backend, no display needed. Exit status 0 when
drawn, 2 for a bad report (the message names what is wrong), 3 when
matplotlib is missing.
"""

import argparse
import json
import math
import os
import sys

DPI = 100
MSE_SIZE_IN = (12.0, 5.0)      # one (level, material) figure: 1200×500 px
LOADTEST_SIZE_IN = (8.0, 5.0)  # each loadtest figure: 800×500 px
TILE_IN = 2.0                  # a glossiness tile under 128 px is drawn 200 px wide …
TILE_GAP_IN = 0.1              # … 10 px apart
NATIVE_TILE_PX = 128           # … one from 128 px up at its own size, pixel for pixel
SHEET_MARGINS_IN = {"left": 0.9, "right": 0.15, "top": 0.95, "bottom": 0.15}

# Okabe–Ito: distinguishable with colour-vision deficiencies.
COLOURS = ["#E69F00", "#56B4E9", "#009E73", "#F0E442", "#0072B2", "#D55E00", "#CC79A7", "#999999"]

VARIANTS = [
    ("refined", "refined (haar's default)"),
    ("faithful", "faithful (the seed as written)"),
]


class ReportError(Exception):
    """report.json lacks something a figure needs."""


def load_matplotlib():
    try:
        import matplotlib
    except ImportError:
        print(
            "plot_report.py: matplotlib is missing for %s; install it with "
            "`apt-get install python3-matplotlib`" % sys.executable,
            file=sys.stderr,
        )
        sys.exit(3)
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def need(node, *path):
    """node[path[0]][path[1]]…, or a ReportError naming the missing key."""
    for i, key in enumerate(path):
        try:
            node = node[key]
        except (KeyError, IndexError, TypeError):
            raise ReportError("report.json lacks " + ".".join(str(k) for k in path[: i + 1]))
    return node


def machine_text(report):
    """"AMD EPYC, 2 cores": the machine a report ran on, for figure titles."""
    m = report.get("machine") or report.get("config", {}).get("machine") or {}
    cpu = m.get("cpu_model") or "unknown CPU"
    cores = m.get("cores")
    return "%s, %d core%s" % (cpu, cores, "" if cores == 1 else "s") if cores else cpu


def level_number(level_key):
    return int(level_key[len("level"):])


def mse_range(report):
    """The shared y range: whole decades around every positive MSE in the report."""
    values = []
    for materials in report.get("mse", {}).values():
        for environments in materials.values():
            for models in environments.values():
                for variants in models.values():
                    values += [v for v in variants.values() if isinstance(v, (int, float)) and v > 0]
    if not values:
        return 1e-20, 1.0
    # A decade below the smallest value, so that its bar is seen.
    lo = 10.0 ** (math.floor(math.log10(min(values))) - 1)
    hi = 10.0 ** math.ceil(math.log10(max(values)) + 1e-9)
    return lo, max(hi, lo * 10.0)


def mean_psnr(report, level_key, material, variant):
    table = report.get("tables", {}).get(level_key, {}).get(material, {})
    values = [env[variant] for env in table.values() if variant in env]
    return sum(values) / len(values) if values else None


def mse_figure(plt, report, level_key, material, ylim):
    """One figure: a panel per variant, models on x, environments as coloured bars."""
    import matplotlib.ticker as ticker

    environments = need(report, "config", "environments")
    models = need(report, "config", "models")
    data = need(report, "mse", level_key, material)
    level = level_number(level_key)

    fig, axes = plt.subplots(1, len(VARIANTS), figsize=MSE_SIZE_IN, dpi=DPI, sharey=True)
    width = 0.8 / max(len(environments), 1)
    for ax, (variant, title) in zip(axes, VARIANTS):
        for e, env in enumerate(environments):
            xs, heights, zeros = [], [], []
            for m, model in enumerate(models):
                value = need(data, env, model, variant)
                x = m - 0.4 + (e + 0.5) * width
                if value > 0:
                    xs.append(x)
                    heights.append(value)
                else:
                    zeros.append(x)  # exact: no bar on a log axis, say so
            ax.bar(xs, heights, width=width * 0.92, color=COLOURS[e % len(COLOURS)], label=env,
                   edgecolor="black", linewidth=0.3)
            for x in zeros:
                ax.text(x, ylim[0], "exact", ha="center", va="bottom", fontsize=8)
        ax.set_yscale("log")
        ax.set_ylim(*ylim)
        ax.yaxis.set_major_locator(ticker.LogLocator(base=10.0, numticks=30))
        ax.yaxis.set_minor_locator(ticker.NullLocator())
        ax.grid(axis="y", which="major", color="#dddddd", linewidth=0.6)
        ax.set_axisbelow(True)
        ax.set_xticks(range(len(models)))
        ax.set_xticklabels(models)
        ax.set_xlim(-0.5, len(models) - 0.5)
        ax.set_xlabel("model")
        psnr = mean_psnr(report, level_key, material, variant)
        ax.set_title(title + ("\nmean seed PSNR %.1f dB" % psnr if psnr is not None else ""), fontsize=11)
    axes[0].set_ylabel("MSE over the object's pixels (linear RGB)")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, title="environment", loc="center right", frameon=False)
    config = report.get("config", {})
    fig.suptitle("haar against spatial: %s, level %d (%d×%d maps)\n%s² frames, %d model(s) × %s rotation(s); %s"
                 % (material, level, 2 ** level, 2 ** level, config.get("frame", "?"), len(models),
                    config.get("rotations_per_model", "?"), machine_text(report)), fontsize=12)
    fig.subplots_adjust(left=0.08, right=0.87, top=0.78, bottom=0.11, wspace=0.06)
    return fig


def mse_figures(plt, report):
    """(file name, figure) for every level and table material, on one y range."""
    ylim = mse_range(report)
    names = report.get("figures", {}).get("mse", {})
    for level_key in sorted(report.get("mse", {}), key=level_number):
        for material in report["mse"][level_key]:
            name = names.get(level_key, {}).get(material, "mse_%s_%s.png" % (level_key, material))
            yield name, mse_figure(plt, report, level_key, material, ylim)


def glossiness_figure(plt, report, base_dir):
    """The tiles in a grid: rows = light coefficients, columns = materials."""
    import matplotlib.image as mpimg

    g = need(report, "glossiness")
    tiles = need(g, "tiles")
    ks = need(g, "light_coefficients")
    materials = need(g, "materials")
    if len(tiles) != len(ks) or any(len(row) != len(materials) for row in tiles):
        raise ReportError("report.json: glossiness.tiles is not %d rows of %d" % (len(ks), len(materials)))
    rows, cols = len(ks), len(materials)
    m = SHEET_MARGINS_IN
    tile_px = g.get("tile_size", 0)
    native = tile_px >= NATIVE_TILE_PX
    tile_in = tile_px / DPI if native else TILE_IN
    step = tile_in + TILE_GAP_IN
    width = m["left"] + cols * step - TILE_GAP_IN + m["right"]
    height = m["top"] + rows * step - TILE_GAP_IN + m["bottom"]
    fig = plt.figure(figsize=(width, height), dpi=DPI)
    for r in range(rows):
        for c in range(cols):
            path = os.path.join(base_dir, tiles[r][c])
            if not os.path.isfile(path):
                raise ReportError("glossiness tile %s is missing (report.json names it)" % path)
            ax = fig.add_axes([
                (m["left"] + c * step) / width,
                1.0 - (m["top"] + r * step + tile_in) / height,
                tile_in / width,
                tile_in / height,
            ])
            ax.imshow(mpimg.imread(path), interpolation="nearest")  # native: pixel for pixel
            ax.set_xticks([])
            ax.set_yticks([])
            for side in ax.spines.values():
                side.set_visible(False)
            if r == 0:
                ax.set_title(materials[c], fontsize=11, pad=4)
            if c == 0:
                ax.set_ylabel("k = %d" % ks[r], fontsize=11, rotation=0, ha="right", va="center", labelpad=6)
    level = g.get("level", 0)
    fig.suptitle("Glossiness: %s in %s, %s at level %d (%d×%d maps)\nrows: k light coefficients kept\n"
                 "%s² frames, %d px tiles; %s"
                 % (g.get("model", "?"), g.get("environment", "?"), g.get("method", "haar"), level, 2 ** level,
                    2 ** level, g.get("frame_size", "?"), tile_px, machine_text(report)),
                 fontsize=10, y=1.0 - 0.06 / height, va="top")
    return fig


def loadtest_series(report):
    """{label: [(clients, run), …] sorted by clients}: a line per method, size and encoding."""
    runs = need(report, "runs")
    if not runs:
        raise ReportError("report.json: runs is empty")
    keys = {(r["width"], r["height"], r["encoding"]) for r in runs}
    series = {}
    for r in runs:
        label = need(r, "method")
        if len(keys) > 1:  # name the size and encoding only when they vary
            label += " %d×%d %s" % (r["width"], r["height"], r["encoding"])
        series.setdefault(label, []).append((need(r, "clients"), r))
    return {label: sorted(points, key=lambda p: p[0]) for label, points in series.items()}


def clients_axis(ax, report):
    counts = sorted({r["clients"] for r in report["runs"]})
    ax.set_xscale("log", base=2)
    ax.set_xticks(counts)
    ax.set_xticklabels([str(c) for c in counts])
    ax.minorticks_off()
    ax.set_xlabel("clients at once")
    ax.grid(color="#dddddd", linewidth=0.6)
    ax.set_axisbelow(True)


def frame_sizes(report):
    """"32×32" or "32×32, 64×64": the runs' frame sizes."""
    sizes = sorted({(r["width"], r["height"]) for r in report.get("runs", []) if "width" in r})
    return ", ".join("%d×%d" % s for s in sizes) or "?"


def loadtest_subtitle(report):
    return "runs at level %s, frames %s, %s s each\n%s, load average %s at the start" % (
        report.get("level", "?"), frame_sizes(report), report.get("seconds_per_run", "?"), machine_text(report),
        report.get("machine", {}).get("load_average_at_start", "?"))


def bandwidth_figure(plt, report):
    fig, ax = plt.subplots(figsize=LOADTEST_SIZE_IN, dpi=DPI)
    for i, (label, points) in enumerate(sorted(loadtest_series(report).items())):
        xs = [c for c, _ in points]
        ys = [need(r, "bits_per_second_per_client") / 1e6 for _, r in points]
        ax.plot(xs, ys, marker="o", color=COLOURS[i % len(COLOURS)], label=label)
    clients_axis(ax, report)
    ax.set_ylim(bottom=0)
    ax.set_ylabel("Mbit/s per client (Frame messages)")
    ax.set_title("Bandwidth per client against clients\n" + loadtest_subtitle(report), fontsize=11)
    ax.legend(title="method", frameon=False)
    fig.tight_layout()
    return fig


def fps_figure(plt, report):
    fig, ax = plt.subplots(figsize=LOADTEST_SIZE_IN, dpi=DPI)
    top = 0.0
    for i, (label, points) in enumerate(sorted(loadtest_series(report).items())):
        xs = [c for c, _ in points]
        fps = [need(r, "fps_per_client") for _, r in points]
        top = max([top] + [need(f, "max") for f in fps])
        median = [need(f, "median") for f in fps]
        below = [m - need(f, "min") for m, f in zip(median, fps)]
        above = [need(f, "max") - m for m, f in zip(median, fps)]
        ax.errorbar(xs, median, yerr=[below, above], marker="o", capsize=3, color=COLOURS[i % len(COLOURS)],
                    label=label)
    clients_axis(ax, report)
    ax.set_ylim(0, top * 1.15 if top > 0 else 1.0)  # room above the fastest client's bar
    ax.set_ylabel("frames per second per client\n(median; bars: slowest to fastest client)")
    ax.set_title("Frame rate per client against clients\n" + loadtest_subtitle(report), fontsize=11)
    ax.legend(title="method", frameon=False)
    fig.tight_layout()
    return fig


def storage_figure(plt, report):
    """Bars per method at the runs' level and at the storage level; the PRT downloads as lines."""
    storage = need(report, "storage")
    at_run = need(report, "storage_at_run_level")
    methods = sorted(set(need(storage, "stored_bytes")) | set(need(at_run, "stored_bytes")))
    fig, ax = plt.subplots(figsize=LOADTEST_SIZE_IN, dpi=DPI)
    width = 0.38
    for k, (s, offset) in enumerate([(at_run, -width / 2), (storage, width / 2)]):
        xs = [m + offset for m, name in enumerate(methods) if name in s["stored_bytes"]]
        ys = [s["stored_bytes"][name] for name in methods if name in s["stored_bytes"]]
        ax.bar(xs, ys, width=width * 0.92, color=COLOURS[k], edgecolor="black", linewidth=0.3,
               label="stored bytes, level %d" % need(s, "level"))
    for k, (name, b) in enumerate(sorted(report.get("prt_baseline", {}).items())):
        ax.axhline(need(b, "bytes"), color=COLOURS[4 + k], linestyle="--", linewidth=1.2,
                   label="PRT download with %s, level %d (%.0f s of the fastest stream)"
                   % (name, b.get("level", 0), b.get("break_even_seconds", 0)))
    ax.set_yscale("log")
    ax.set_xticks(range(len(methods)))
    ax.set_xticklabels(methods)
    ax.set_xlabel("method")
    ax.set_ylabel("bytes (log scale)")
    ax.grid(axis="y", color="#dddddd", linewidth=0.6)
    ax.set_axisbelow(True)
    ax.set_title("BRDF coefficient data each method holds, and the PRT downloads\n" + loadtest_subtitle(report),
                 fontsize=10)
    ax.legend(frameon=False, fontsize=8, loc="upper left")
    fig.tight_layout()
    return fig


def loadtest_figures(plt, report):
    """(file name, figure) for each figure a loadtest report lists."""
    drawers = {"loadtest_bandwidth.png": bandwidth_figure, "loadtest_fps.png": fps_figure,
               "loadtest_storage.png": storage_figure}
    for name in need(report, "figures"):
        if name not in drawers:
            raise ReportError("report.json names the figure %s, which this script does not draw (it draws %s)"
                              % (name, ", ".join(sorted(drawers))))
        yield name, drawers[name](plt, report)


def main(argv):
    parser = argparse.ArgumentParser(
        description="Draw the figures of haarcast eval's or loadtest's report.json (matplotlib).")
    parser.add_argument("report", help="report.json written by `haarcast eval` or `haarcast loadtest`")
    parser.add_argument("--out", help="folder for the PNGs (default: report.json's)")
    args = parser.parse_args(argv)

    plt = load_matplotlib()
    base_dir = os.path.dirname(os.path.abspath(args.report))
    out_dir = args.out or base_dir
    try:
        with open(args.report, encoding="utf-8") as f:
            report = json.load(f)
    except (OSError, ValueError) as e:
        print("plot_report.py: cannot read %s: %s" % (args.report, e), file=sys.stderr)
        return 2
    os.makedirs(out_dir, exist_ok=True)

    written = []
    try:
        figures = loadtest_figures(plt, report) if report.get("kind") == "loadtest" else mse_figures(plt, report)
        for name, fig in figures:
            fig.savefig(os.path.join(out_dir, name), dpi=DPI)
            plt.close(fig)
            written.append(name)
        if "glossiness" in report:
            fig = glossiness_figure(plt, report, base_dir)
            name = report["glossiness"].get("file", "glossiness.png")
            fig.savefig(os.path.join(out_dir, name), dpi=DPI)
            plt.close(fig)
            written.append(name)
    except ReportError as e:
        print("plot_report.py: %s" % e, file=sys.stderr)
        return 2
    for name in written:
        print("wrote %s" % os.path.join(out_dir, name))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
