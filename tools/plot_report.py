#!/usr/bin/env python3
"""Draws the figures of `haarcast eval` from its report.json, with matplotlib.

    python3 tools/plot_report.py eval/report.json [--out DIR]

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
      coefficient count, written by eval) laid out in a labelled grid.

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
TILE_IN = 2.0                  # a glossiness tile is drawn 200 px wide …
TILE_GAP_IN = 0.1              # … 10 px apart
SHEET_MARGINS_IN = {"left": 0.9, "right": 0.15, "top": 0.75, "bottom": 0.15}

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
    fig.suptitle("haar against spatial: %s, level %d (%d×%d maps)" % (material, level, 2 ** level, 2 ** level),
                 fontsize=13)
    fig.subplots_adjust(left=0.08, right=0.87, top=0.82, bottom=0.11, wspace=0.06)
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
    step = TILE_IN + TILE_GAP_IN
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
                1.0 - (m["top"] + r * step + TILE_IN) / height,
                TILE_IN / width,
                TILE_IN / height,
            ])
            ax.imshow(mpimg.imread(path), interpolation="nearest")
            ax.set_xticks([])
            ax.set_yticks([])
            for side in ax.spines.values():
                side.set_visible(False)
            if r == 0:
                ax.set_title(materials[c], fontsize=11, pad=4)
            if c == 0:
                ax.set_ylabel("k = %d" % ks[r], fontsize=11, rotation=0, ha="right", va="center", labelpad=6)
    fig.suptitle("Glossiness: %s in %s, level %d; rows = k light coefficients kept"
                 % (g.get("model", "?"), g.get("environment", "?"), g.get("level", 0)),
                 fontsize=12, y=1.0 - 0.12 / height, va="top")
    return fig


def main(argv):
    parser = argparse.ArgumentParser(description="Draw the figures of haarcast eval's report.json (matplotlib).")
    parser.add_argument("report", help="report.json written by `haarcast eval`")
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
        for name, fig in mse_figures(plt, report):
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
