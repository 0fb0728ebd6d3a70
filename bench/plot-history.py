#!/usr/bin/python3
"""Plots bench/results/history.csv (written by bench/integrators.sh): passes per second of each
(scene, integrator) against the run index, one panel per scene, one line per integrator, so that a
throughput regression shows as a step. Runs are the distinct dates of the CSV in file order; the x
axis is labelled with their commits. Only runs with the most common time budget, thread count,
machine and build architecture (x86-64 or native) are plotted unless --time/--threads/--all say
otherwise, since passes/s is only comparable between like runs.

With --csv bench/results/instructions.csv (written by bench/instructions.sh) it plots instructions
per ray (or --metric instructions_per_sample) instead, keeping the runs with the most common image
size, pass count, machine, build architecture and valgrind version (--time and --threads do not
apply there).

Usage: bench/plot-history.py [--csv bench/results/history.csv] [-o FILE.png (default: the CSV's name)]
                             [--metric passes_per_s|mrays_per_s|relmse|ratio_to_embree|
                                       instructions_per_ray|instructions_per_sample]
                             [--time S] [--threads N] [--all]
Needs matplotlib (python3-matplotlib, installed by scripts/install-deps.sh)."""
import argparse
import collections
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

LABELS = {
    "passes_per_s": "passes/s (spp or iterations)",
    "mrays_per_s": "Mrays/s",
    "relmse": "relMSE at equal time",
    "ratio_to_embree": "path tracer Mrays/s / raw Embree",
    "instructions_per_ray": "instructions per ray (callgrind)",
    "instructions_per_sample": "instructions per pixel sample (callgrind)",
}


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--csv", default=os.path.join(here, "results", "history.csv"))
    ap.add_argument("-o", "--output", help="default: the CSV's path with .png")
    ap.add_argument("--metric", choices=sorted(LABELS), help="default: passes_per_s, or instructions_per_ray "
                    "for bench/instructions.sh's CSV")
    ap.add_argument("--time", type=float, help="only runs with this time budget (default: the most common)")
    ap.add_argument("--threads", type=int, help="only runs with this thread count (default: the most common)")
    ap.add_argument("--all", action="store_true", help="plot every run whatever its budget, threads and machine")
    a = ap.parse_args()

    with open(a.csv, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{a.csv}: no rows")
    counts = "instructions_per_ray" in rows[0]  # bench/instructions.sh's CSV
    metric = a.metric or ("instructions_per_ray" if counts else "passes_per_s")
    if metric not in rows[0]:
        sys.exit(f"{a.csv}: no column {metric}")
    output = a.output or os.path.splitext(a.csv)[0] + ".png"
    tool = "bench/instructions.sh" if counts else "bench/integrators.sh"

    def machine(r):  # rows from before the arch column were all portable (x86-64) builds
        if counts:
            return f"{r['cpu']}, {r['arch']} build, {r['valgrind']}"
        return f"{r['nproc']} x {r['cpu']}, {r.get('arch') or 'x86-64'} build"

    def most_common(key):
        return collections.Counter(key(r) for r in rows).most_common(1)[0][0]

    if counts and not a.all:
        size = most_common(lambda r: (r["res"], r["passes"]))
        m = most_common(machine)
        rows = [r for r in rows if (r["res"], r["passes"]) == size and machine(r) == m]
        subtitle = f"{size[0]}x{size[0]}, {size[1]} passes, one thread, {m}"
    elif not a.all:
        t = a.time if a.time is not None else float(most_common(lambda r: float(r["time"])))
        th = a.threads if a.threads is not None else int(most_common(lambda r: int(r["threads"])))
        m = most_common(machine)
        rows = [r for r in rows if float(r["time"]) == t and int(r["threads"]) == th and machine(r) == m]
        subtitle = f"{t:g} s per render, {th} threads, {m}"
    else:
        subtitle = "all runs"
    if not rows:
        sys.exit("no runs match the filter")

    runs = []  # distinct dates in file order
    for r in rows:
        if r["date"] not in runs:
            runs.append(r["date"])
    index = {d: i for i, d in enumerate(runs)}
    commit_of = {r["date"]: r["commit"] for r in rows}

    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    cols = min(3, len(scenes))
    nrows = (len(scenes) + cols - 1) // cols
    fig, axes = plt.subplots(nrows, cols, figsize=(5.2 * cols, 3.6 * nrows), squeeze=False)
    for ax, scene in zip(axes.flat, scenes):
        series = collections.defaultdict(list)
        for r in rows:
            if r["scene"] == scene and r[metric] not in ("", None):
                series[r["integrator"]].append((index[r["date"]], float(r[metric])))
        for integ, pts in series.items():
            pts.sort()
            ax.plot([p[0] for p in pts], [p[1] for p in pts], marker="o", label=integ)
        ax.set_title(scene)
        ax.set_yscale("log")
        ax.set_xticks(range(len(runs)))
        ax.set_xticklabels([commit_of[d] for d in runs], rotation=60, ha="right", fontsize=7)
        ax.set_xlabel("run (commit)")
        ax.set_ylabel(LABELS[metric])
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    for ax in list(axes.flat)[len(scenes):]:
        ax.axis("off")
    fig.suptitle(f"{tool} history: {subtitle}", fontsize=10)
    fig.tight_layout()
    fig.savefig(output, dpi=110)
    print(f"wrote {output} ({len(runs)} runs, {len(scenes)} scenes)", file=sys.stderr)


if __name__ == "__main__":
    main()
