#!/usr/bin/python3
"""Reads the renders of one bench/integrators.sh run (stats JSON, error JSON, raw Embree JSON), prints
the table (Markdown) and appends one line per (scene, integrator) to the history CSV. Standard library
only. Called by bench/integrators.sh; not meant to be run by hand."""
import argparse
import csv
import json
import math
import os
import statistics
import sys

HISTORY_FIELDS = [
    "date", "commit", "nproc", "cpu", "loadavg", "threads", "scene", "integrator", "time", "runs",
    "seconds", "passes", "passes_per_s", "mrays_per_s", "relmse", "relmse_min", "relmse_max",
    "embree_mrays_per_s", "ratio_to_embree", "nonfinite", "arch",
]


def load(path):
    try:
        with open(path) as f:
            return json.load(f)
    except FileNotFoundError:
        return None


def fmt(x, spec):
    return "n/a" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, spec)


def upgrade_history(path):
    """Rewrites a history file written before a column was added: the new columns are empty."""
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        if reader.fieldnames == HISTORY_FIELDS:
            return
        old = list(reader)
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=HISTORY_FIELDS)
        w.writeheader()
        for r in old:
            w.writerow({k: r.get(k, "") or "" for k in HISTORY_FIELDS})


def main():
    ap = argparse.ArgumentParser()
    for name in ["work", "scenes", "integrators", "date", "commit", "cpu", "load", "references", "arch"]:
        ap.add_argument("--" + name, required=True)
    ap.add_argument("--runs", type=int, required=True)
    ap.add_argument("--time", type=float, required=True)
    ap.add_argument("--threads", type=int, required=True)
    ap.add_argument("--nproc", type=int, required=True)
    ap.add_argument("--history")
    a = ap.parse_args()

    rows, notes = [], []
    for scene in a.scenes.split():
        # Raw Embree just before and just after the path tracer's runs: their mean, so that a drift of
        # the machine during the renders moves both sides of the ratio alike (one of them if only one).
        raw = [r for r in (load(os.path.join(a.work, scene, f)) for f in ("embree.json", "embree-after.json")) if r]
        embree_mix = statistics.mean(r["raw_mixed_mrays_per_second"] for r in raw) if raw else None
        ref_meta = load(os.path.join(a.references, scene + ".json"))
        if ref_meta is None and not os.path.exists(os.path.join(a.references, scene + ".exr")):
            notes.append(f"{scene}: no reference (bench/make-references.sh --scenes {scene}); relMSE n/a")
        elif ref_meta is not None:
            notes.append(f"{scene}: reference {ref_meta['integrator']}, {ref_meta['spp']} spp in "
                         f"{ref_meta['render_seconds']:.0f} s ({ref_meta['date'][:10]}, {ref_meta['commit']}); "
                         f"its own noise floor relMSE ~ {fmt(ref_meta.get('relmse_floor'), '.2g')}"
                         + (f", its own error ~ {fmt(ref_meta['relmse_own_error'], '.2g')}"
                            if "relmse_own_error" in ref_meta else ""))
        for integ in a.integrators.split(","):
            stats, errs = [], []
            for k in range(1, a.runs + 1):
                s = load(os.path.join(a.work, scene, f"{integ}-{k}.json"))
                if s is None:
                    continue
                stats.append(s)
                e = load(os.path.join(a.work, scene, f"{integ}-{k}.errors.json"))
                errs.append(e)
            if not stats:
                continue
            seconds = statistics.median(s["seconds"] for s in stats)
            # What the image holds: a pass cut by the time budget counts with the samples it took
            # (samples_per_pixel; older stats files have only the whole passes, spp).
            taken = [s.get("samples_per_pixel", s["spp"]) for s in stats]
            passes = round(statistics.median(taken), 1)
            pps = statistics.median(n / s["seconds"] for n, s in zip(taken, stats) if s["seconds"] > 0)
            mrays = statistics.median(s["mrays_per_second"] for s in stats)
            nonfinite = sum(s["nonfinite_samples"] for s in stats) + sum(e.get("nonfinite", 0) for e in errs if e)
            rel = [e["relmse"] for e in errs if e and e.get("relmse") is not None]
            rel_med = statistics.median(rel) if rel else None
            ratio = mrays / embree_mix if (integ == "path" and embree_mix) else None
            rows.append(dict(
                date=a.date, commit=a.commit, nproc=a.nproc, cpu=a.cpu, loadavg=a.load, threads=a.threads,
                scene=scene, integrator=integ, time=a.time, runs=len(stats), seconds=round(seconds, 3),
                passes=passes, passes_per_s=round(pps, 4), mrays_per_s=round(mrays, 4),
                relmse=None if rel_med is None else float(f"{rel_med:.5g}"),
                relmse_min=float(f"{min(rel):.5g}") if rel else None,
                relmse_max=float(f"{max(rel):.5g}") if rel else None,
                embree_mrays_per_s=None if embree_mix is None else round(embree_mix, 3),
                ratio_to_embree=None if ratio is None else round(ratio, 4), nonfinite=nonfinite, arch=a.arch))

    out = sys.stdout
    out.write(f"\n{a.date}, commit {a.commit} ({a.arch} build), {a.nproc} x {a.cpu}, load average {a.load} at start; "
              f"{a.time:g} s per render, {a.threads} threads, {a.runs} run(s)\n\n")
    out.write("| scene | integrator | passes | passes/s | Mrays/s | relMSE (median [min, max]) | vs Embree | non-finite |\n")
    out.write("|---|---|---|---|---|---|---|---|\n")
    for r in rows:
        rel = fmt(r["relmse"], ".4g")
        if a.runs > 1 and r["relmse"] is not None:
            rel += f" [{r['relmse_min']:.4g}, {r['relmse_max']:.4g}]"
        ratio = "" if r["ratio_to_embree"] is None else f"{100 * r['ratio_to_embree']:.0f} % of {r['embree_mrays_per_s']:.1f}"
        passes = f"{r['passes']:g}"
        out.write(f"| {r['scene']} | {r['integrator']} | {passes} | {r['passes_per_s']:.3g} | {r['mrays_per_s']:.2f} "
                  f"| {rel} | {ratio} | {r['nonfinite']} |\n")
    if notes:
        out.write("\n" + "\n".join("- " + n for n in notes) + "\n")
    bad = [r for r in rows if r["nonfinite"]]
    if bad:
        out.write("\nWARNING: non-finite samples or pixels in " +
                  ", ".join(f"{r['scene']}/{r['integrator']}" for r in bad) + "\n")

    if a.history:
        os.makedirs(os.path.dirname(a.history), exist_ok=True)
        new = not os.path.exists(a.history) or os.path.getsize(a.history) == 0
        if not new:
            upgrade_history(a.history)
        with open(a.history, "a", newline="") as f:
            w = csv.DictWriter(f, fieldnames=HISTORY_FIELDS)
            if new:
                w.writeheader()
            for r in rows:
                w.writerow({k: ("" if r[k] is None else r[k]) for k in HISTORY_FIELDS})
        print(f"\nappended {len(rows)} lines to {a.history}", file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
