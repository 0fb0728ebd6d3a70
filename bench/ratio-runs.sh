#!/usr/bin/env bash
# Repeated runs of penumbra-bench-render (the path tracer's ray rate against raw Embree's, issue 13's
# yardstick): one run's ratio is the median of its alternated rounds, but on this project's shared
# 2-core machine whole runs land 5-10 points apart from minute to minute (docs/benchmarks.md,
# "Renderer versus raw Embree"). This runs the default program --runs times, one after the other,
# keeps every run's JSON lines, and prints per thread count the median of the runs' ratios with a
# distribution-free interval of at least 95 % for it (bench/pair_stats.py; 6 runs or more), their
# range, and how many runs were below --target; then the rounds split by the program's probe of core
# contention (quiet or contended), and the runs' medians over their quiet rounds.
#   bench/ratio-runs.sh [--build DIR] [--scene FILE] [--runs N] [--target PERCENT] [--keep FILE]
#                       [--from FILE] [-- OPTIONS FOR penumbra-bench-render]
#   --build   default: build/ of this checkout
#   --scene   default: the program's own (the bundled Cornell box)
#   --runs    default 12
#   --target  default 60 (the box's target; cornell-water's is 85)
#   --keep    write every run's JSON lines to FILE (each with "run", its number, and "utc", its start)
#   --from    run nothing: summarise the JSON lines an earlier run kept in FILE
# Example: bench/ratio-runs.sh --runs 24 --keep /tmp/box.jsonl
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
source "$root/bench/common.sh"

build="$root/build"
scene=""
runs=12
target=60
keep=""
from=""
extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build="$2"; shift 2 ;;
    --scene) scene="$2"; shift 2 ;;
    --runs) runs="$2"; shift 2 ;;
    --target) target="$2"; shift 2 ;;
    --keep) keep="$2"; shift 2 ;;
    --from) from="$2"; shift 2 ;;
    --) shift; extra=("$@"); break ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "ratio-runs.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
[[ "$runs" =~ ^[1-9][0-9]*$ ]] || { echo "ratio-runs.sh: --runs must be a positive whole number, not '$runs'" >&2; exit 2; }
[[ "$target" =~ ^[0-9]+([.][0-9]+)?$ ]] || { echo "ratio-runs.sh: --target must be a percentage, not '$target'" >&2; exit 2; }
lines=$(mktemp)
trap 'rm -f "$lines"' EXIT
if [ -n "$from" ]; then
  [ -f "$from" ] || { echo "ratio-runs.sh: --from: no file '$from'" >&2; exit 2; }
  cp "$from" "$lines"
else
  bench_find_build "$build"
  args=(--json)
  [ -n "$scene" ] && args+=(--scene "$scene")
  args+=("${extra[@]}")
  echo "commit $(bench_commit "$root"), $(bench_cpu_model), load $(bench_loadavg); $runs runs of penumbra-bench-render ${args[*]}" >&2
  for ((i = 1; i <= runs; ++i)); do
    "$build/bin/penumbra-bench-render" "${args[@]}" | sed "s/^{/{\"run\":$i,\"utc\":\"$(date -u +%H:%M:%S)\",/" >>"$lines"
    echo "run $i/$runs done ($(date -u +%H:%M:%S) UTC)" >&2
  done
  [ -n "$keep" ] && cp "$lines" "$keep"
fi

"$(bench_python)" - "$lines" "$target" "$root/bench" <<'EOF'
import json, statistics, sys
sys.path.insert(0, sys.argv[3])
from pair_stats import describe_ratios
target = float(sys.argv[2])
rows = [json.loads(l) for l in open(sys.argv[1]) if l.strip()]
if not rows or "ratio" not in rows[0]:
    sys.exit("ratio-runs.sh: the program printed no ratios")
print(f"scene {rows[0]['scene']}: {rows[0]['triangles']} triangles; each run's ratio is the median of its "
      f"{rows[0]['rounds']} rounds; over runs: median [95 % interval] (min-max)")
print(f"{'threads':>7}  {'runs':>4}  {'ratio, % of raw Embree':<36}  {'below ' + format(target, 'g') + ' %':>9}  "
      f"{'path Mrays/s':<24}  raw mixed Mrays/s")
runs_of = {}
for r in rows:
    runs_of.setdefault(r["threads"], []).append(r)
for threads, rs in sorted(runs_of.items()):
    ratios = [100 * r["ratio"] for r in rs]
    below = sum(q < target for q in ratios)
    print(f"{threads:>7}  {len(rs):>4}  {describe_ratios(ratios, 1):<36}  {below:>9}  "
          f"{describe_ratios([r['path_mrays_per_second'] for r in rs], 2):<24}  "
          f"{describe_ratios([r['raw_mixed_mrays_per_second'] for r in rs], 2)}")
both = {}
for r in rows:
    both.setdefault(r["run"], []).append(100 * r["ratio"] >= target)
print(f"runs with every thread count at or above {target:g} %: {sum(all(v) for v in both.values())} of {len(both)}")
# Rounds split by the core-contention probes (bench/core_contention.h): quiet when every probe of the
# round was within 10 % of the idle value. That is a low tenth of the runs' own smallest indices at
# the thread count: a run inside a contended phase finds no idle probe of its own, and a stray probe
# can read far below idle (0.84 once, against 0.95-0.96 in 22 other runs of the same batch).
print("rounds by core contention (quiet: every probe within 10 % of the idle value, the tenth percentile of "
      "the runs' smallest): ratio, median [95 % interval] (min-max)")
for threads, rs in sorted(runs_of.items()):
    idle = sorted(r["idle_core_contention"] for r in rs)[len(rs) // 10]
    quiet, contended, quiet_runs = [], [], []
    for r in rs:
        mine = []
        for ratio, c in zip(r["round_ratios"], r["round_core_contention"]):
            (mine if c <= 1.1 * idle else contended).append(100 * ratio)
        quiet += mine
        if mine:
            quiet_runs.append(statistics.median(mine))
    for label, v in (("quiet", quiet), ("contended", contended)):
        print(f"{threads:>7}  {label:<9}  {len(v):>3} rounds  {describe_ratios(v, 1)}  "
              f"below {target:g} %: {sum(q < target for q in v)}")
    print(f"{threads:>7}  idle value {idle:.2f}; runs' medians over their quiet rounds ({len(quiet_runs)} of {len(rs)} "
          f"runs have one): {describe_ratios(quiet_runs, 1)}  below {target:g} %: {sum(q < target for q in quiet_runs)}")
EOF
