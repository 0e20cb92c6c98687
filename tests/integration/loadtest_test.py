#!/usr/bin/env python3
"""`haarcast loadtest --quick` end to end.

    python3 loadtest_test.py --haarcast build/bin/haarcast --script tools/plot_report.py --work DIR

Runs the quick load test against its own loopback server and checks
report.json: a run per (method, client count) for at least fused, haar and
table, every key of docs/loadtest.md with sane values (fps > 0, latency
p50 ≤ p99, bits/s > 0, …), the PRT baseline's arithmetic, table's stored
bytes at least 100× haar's at level 6, report.md's table, and that the
server child is gone afterwards. Then the plot script draws the three
figures from it, each an 800×500 PNG with labelled axes, a title that
names the frame size, level and machine (CPU model and cores), and a
legend; without matplotlib that part is skipped with a message naming the
package (the rest still runs).
"""

import argparse
import json
import os
import shutil
import subprocess
import sys

RUN_KEYS = ["method", "clients", "width", "height", "encoding", "fps_per_client", "latency_ms",
            "bits_per_second_per_client", "stored_bytes", "coefficient_bytes_per_frame",
            "server_cpu_seconds", "server_rss_bytes"]
QUICK_METHODS = {"fused", "haar", "table"}
FIGURE_SIZE = (800, 500)


def fail(message):
    print("FAIL: " + message, file=sys.stderr)
    sys.exit(1)


def check(condition, message):
    if not condition:
        fail(message)


def python_with_matplotlib():
    candidates = [os.environ["HAARCAST_PYTHON"]] if os.environ.get("HAARCAST_PYTHON") else [sys.executable, "/usr/bin/python3"]
    for python in candidates:
        try:
            if subprocess.run([python, "-c", "import matplotlib"], capture_output=True).returncode == 0:
                return python
        except OSError:
            pass
    return None


def servers_left(marker):
    """Processes whose command line names this test's own cache folder: the loadtest's server children."""
    left = []
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            with open("/proc/%s/cmdline" % pid, "rb") as f:
                args = f.read().split(b"\0")
        except OSError:
            continue
        if b"serve" in args and marker.encode() in args:
            left.append(int(pid))
    return left


def check_runs(report):
    runs = report.get("runs")
    check(isinstance(runs, list) and runs, "report.json has no runs")
    methods = {r.get("method") for r in runs}
    check(QUICK_METHODS <= methods, "runs cover %s, not all of %s" % (sorted(methods), sorted(QUICK_METHODS)))
    for r in runs:
        where = "run %s/%s clients" % (r.get("method"), r.get("clients"))
        for key in RUN_KEYS:
            check(key in r, "%s lacks %s" % (where, key))
        check(r["failures"] == [], "%s failed: %s" % (where, r["failures"]))
        fps = r["fps_per_client"]
        check(0 < fps["min"] <= fps["median"] <= fps["max"], "%s: fps per client %s is not 0 < min ≤ median ≤ max" % (where, fps))
        lat = r["latency_ms"]
        check(0 < lat["p50"] <= lat["p99"], "%s: latency %s is not 0 < p50 ≤ p99" % (where, lat))
        check(r["bits_per_second_per_client"] > 0, "%s: bits per second %s" % (where, r["bits_per_second_per_client"]))
        # A 32² JPEG is ~1 KB: bits/s per client ≈ 8 × bytes per frame × fps.
        expected = 8 * r["bytes_per_frame"] * fps["median"]
        check(0.5 * expected < r["bits_per_second_per_client"] < 2.0 * expected,
              "%s: %.0f bit/s per client, but 8 × %.0f bytes/frame × %.2f fps = %.0f"
              % (where, r["bits_per_second_per_client"], r["bytes_per_frame"], fps["median"], expected))
        check(r["encoding"] == "jpeg" and r["width"] == 32 and r["height"] == 32, "%s: not 32×32 jpeg" % where)
        check(r["stored_bytes"] == report["storage_at_run_level"]["stored_bytes"][r["method"]],
              "%s: stored_bytes differs from storage_at_run_level" % where)
        check(r["coefficient_bytes_per_frame"] > 0, "%s: no coefficient bytes per frame" % where)
        check(isinstance(r["server_cpu_seconds"], (int, float)) and r["server_cpu_seconds"] >= 0,
              "%s: server CPU seconds %s (the local server's /proc should give a number)" % (where, r["server_cpu_seconds"]))
        check(isinstance(r["server_rss_bytes"], int) and r["server_rss_bytes"] > 1 << 20,
              "%s: server RSS %s" % (where, r["server_rss_bytes"]))
    clients = {r["clients"] for r in runs}
    check(len(clients) >= 2, "the quick run should try more than one client count, got %s" % sorted(clients))


def check_storage(report):
    s = report["storage"]
    check(s["level"] == 6, "the storage figure is at level %s, not 6" % s["level"])
    haar, table = s["stored_bytes"]["haar"], s["stored_bytes"]["table"]
    check(haar > 0 and table >= 100 * haar, "table stores %d bytes at level 6, not ≥ 100 × haar's %d" % (table, haar))
    for name in ("table", "matrix"):
        b = report["prt_baseline"].get(name)
        check(b is not None, "prt_baseline lacks %s" % name)
        shared = report["shared_bytes"]
        parts = report["storage_at_run_level"]["stored_bytes"][name] + shared["visibility"] + shared["light"] + shared["meshes"]
        check(b["bytes"] == parts, "prt_baseline.%s.bytes %d ≠ its data + visibility + light + meshes %d" % (name, b["bytes"], parts))
        fastest = max(r["bits_per_second_per_client"] for r in report["runs"])
        check(abs(b["break_even_seconds"] - b["bytes"] * 8 / fastest) <= 1e-6 * b["break_even_seconds"],
              "prt_baseline.%s.break_even_seconds %s ≠ bytes · 8 / the fastest per-client rate" % (name, b["break_even_seconds"]))


def check_figures(haarcast_out, report, script):
    python = python_with_matplotlib()
    if python is None:
        print("SKIP figures: no python3 with matplotlib (apt-get install python3-matplotlib)")
        return
    figures_dir = os.path.join(haarcast_out, "replot")
    rc = subprocess.run([python, script, os.path.join(haarcast_out, "report.json"), "--out", figures_dir]).returncode
    check(rc == 0, "plot_report.py exited %d on the loadtest report" % rc)
    for name in report["figures"]:
        for folder in (haarcast_out, figures_dir):  # drawn by loadtest itself, and again here
            path = os.path.join(folder, name)
            check(os.path.isfile(path), "%s was not drawn" % path)
            with open(path, "rb") as f:
                head = f.read(24)
            size = (int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big"))
            check(size == FIGURE_SIZE, "%s is %s, expected %s" % (path, size, FIGURE_SIZE))
    # The axes themselves, in the interpreter that has matplotlib.
    rc = subprocess.run([python, os.path.abspath(__file__), "--check-axes", os.path.join(haarcast_out, "report.json"),
                         "--script", script]).returncode
    check(rc == 0, "the figures' axes are not as documented (above)")
    with open(os.path.join(haarcast_out, "report.md"), encoding="utf-8") as f:
        md = f.read()
    for name in report["figures"]:
        check("](%s)" % name in md, "report.md does not show %s" % name)


def check_axes(report_path, script):
    sys.path.insert(0, os.path.dirname(os.path.abspath(script)))
    import plot_report

    with open(report_path, encoding="utf-8") as f:
        report = json.load(f)
    plt = plot_report.load_matplotlib()
    machine = report.get("machine", {})
    check(machine.get("cpu_model") and machine.get("cores", 0) >= 1, "report.json's machine is %s" % machine)
    says = ["frames 32×32", "level %d" % report["level"], machine.get("cpu_model", "?"), "%d core" % machine.get("cores", 0)]
    for name, fig in plot_report.loadtest_figures(plt, report):
        ax = fig.axes[0]
        check(ax.get_xlabel() and ax.get_ylabel() and ax.get_title(), "%s lacks an axis label or title" % name)
        for part in says:
            check(part in ax.get_title(), "%s's title does not say %r: %r" % (name, part, ax.get_title()))
        check(ax.get_legend() is not None, "%s has no legend" % name)
        if name == "loadtest_storage.png":
            check(ax.get_yscale() == "log", "the storage figure's y axis is %s, not log" % ax.get_yscale())
        plt.close(fig)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--haarcast")
    parser.add_argument("--script", required=True)
    parser.add_argument("--work")
    parser.add_argument("--check-axes", metavar="REPORT", help="only check the figures' axes (run by the test itself)")
    args = parser.parse_args()
    if args.check_axes:
        return check_axes(args.check_axes, args.script)
    if not args.haarcast or not args.work:
        parser.error("--haarcast and --work are required")
    out = os.path.join(args.work, "out")
    cache = os.path.join(args.work, "cache")  # kept between runs; also marks our server children
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(cache, exist_ok=True)
    proc = subprocess.run([args.haarcast, "loadtest", "--quick", "--out", out, "--cache-dir", cache],
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=300)
    sys.stderr.write(proc.stderr[-4000:])
    check(proc.returncode == 0, "haarcast loadtest --quick exited %d" % proc.returncode)
    check(not servers_left(cache), "server children still running: %s" % servers_left(cache))
    with open(os.path.join(out, "report.json"), encoding="utf-8") as f:
        report = json.load(f)
    check(report.get("kind") == "loadtest", "report.json's kind is %r" % report.get("kind"))
    check_runs(report)
    check_storage(report)
    with open(os.path.join(out, "report.md"), encoding="utf-8") as f:
        md = f.read()
    check("| method | clients | size | encoding |" in md, "report.md has no run table")
    check("\n| table | 1 | 32×32 | jpeg |" in md, "report.md's table lacks the run of table with 1 client")
    check_figures(out, report, args.script)
    print("ok: %d runs, table/haar storage at level 6 = %.0f×" % (
        len(report["runs"]), report["storage"]["stored_bytes"]["table"] / report["storage"]["stored_bytes"]["haar"]))


if __name__ == "__main__":
    main()
