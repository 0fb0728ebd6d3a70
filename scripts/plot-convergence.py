#!/usr/bin/python3
"""Plots relMSE versus render time (log-log) for one `penumbra converge` study folder: one line per
configuration (mean over runs) with its min-max band and a slope -1 guide. Writes convergence.png and
convergence.svg into the folder. Usage: scripts/plot-convergence.py STUDY_DIR [TITLE]"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    folder = sys.argv[1]
    title = sys.argv[2] if len(sys.argv) > 2 else folder
    with open(f"{folder}/summary.json") as f:
        summary = json.load(f)
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    t_all = []
    for name, data in summary["configs"].items():
        pts = data["points"]
        t = [p["seconds"] for p in pts]
        rel = [p["relmse"] for p in pts]
        # The band is the interquartile range over runs (the range in studies made before quartiles).
        lo = [max(p.get("relmse_q25", p["relmse_min"]), 1e-12) for p in pts]
        hi = [p.get("relmse_q75", p["relmse_max"]) for p in pts]
        line, = ax.loglog(t, rel, marker="o", markersize=3, label=name)
        ax.fill_between(t, lo, hi, color=line.get_color(), alpha=0.15)
        t_all += t
        if name == next(iter(summary["configs"])):
            # Slope -1 guide through this configuration's first point.
            ax.loglog([t[0], t[-1]], [rel[0], rel[0] * t[0] / t[-1]], "k:", linewidth=1, label="slope -1")
    ax.set_xlabel("render time [s]")
    ax.set_ylabel("median relMSE over runs, IQR band (eps = %g)" % summary["relmse_epsilon"])
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(f"{folder}/convergence.png", dpi=110)
    fig.savefig(f"{folder}/convergence.svg")


if __name__ == "__main__":
    main()
