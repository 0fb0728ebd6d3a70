#!/usr/bin/env bash
# Where the time of the path integrator and of the minimal path tracer's layers goes, split into
# Embree and everything else. `penumbra-bench-render --minimal` says how many nanoseconds each layer
# adds per pixel sample; this says whether those nanoseconds are spent inside Embree (the same rays
# traced differently) or in the code around it, and in which functions.
#
# It samples one round of `penumbra-bench-render --minimal` (one thread) with perf and DWARF call
# graphs (Embree is built without frame pointers, so only DWARF unwinding finds who called it), then
# gives each sample to the renderer whose frame is nearest the sampled instruction on its stack: the
# path integrator (its `Li` and the render loop around it, reported apart), one of the minimal
# tracer's four layers or its variant with robust ray origins (bench/minimal_path_tracer.cpp), or
# raw Embree's measurement. Every layer renders the same pixel samples, so the counts compare
# directly. perf here samples the cpu-clock (this project's virtual machine has no hardware
# counters), about once per millisecond.
#
# With --instructions it counts instead of sampling: valgrind's callgrind runs the same round and
# dumps its counts after each renderer's render, so each renderer's instructions per pixel sample,
# inside Embree (rtcIntersect1, rtcOccluded1, rtcIntersect8 and what they call) and elsewhere, come
# out exactly and the same in every run: what a change to one layer does shows without the machine's
# noise (but not its cache misses or stalls, which only the times above see).
#
# Usage: bench/layer-profile.sh [--scene FILE] [--spp N] [--res N] [--top N] [--instructions]
#                               [--keep DIR] [--build DIR]
#   --scene   default: the bundled Cornell box (bench/scenes/cornell-water-diffuse.pbrt also works;
#             the minimal tracer takes only Lambertian triangles under area lights)
#   --spp     samples per pixel of each render (default 16, or 8 with --instructions); --res film
#             size (default 256, or 128 with --instructions). Much smaller renders trip the bench
#             program's check that the two tracers' image means agree within 1 % (cornell-water
#             needs --spp 16 with --instructions).
#   --top     functions listed per renderer outside Embree (default 10; not with --instructions)
#   --instructions  count instructions with callgrind instead of sampling with perf
#   --keep    keep perf.data and the decoded stacks (or the callgrind parts) in DIR (default: a
#             temporary folder)
# Needs linux-perf (Debian: apt-get install linux-perf) and permission to profile
# (kernel.perf_event_paranoid <= 2); under a minute, a recording of about 90 MB. --instructions needs
# valgrind instead (apt-get install valgrind) and takes about a minute at its defaults.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
source "$root/bench/common.sh"

scene=""
spp=""
res=""
top=10
instructions=0
keep=""
build="$root/build"
while [ $# -gt 0 ]; do
  case "$1" in
    --scene) scene="$2"; shift 2 ;;
    --spp) spp="$2"; shift 2 ;;
    --res) res="$2"; shift 2 ;;
    --top) top="$2"; shift 2 ;;
    --instructions) instructions=1; shift ;;
    --keep) keep="$2"; shift 2 ;;
    --build) build="$2"; shift 2 ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "layer-profile.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
[ -n "$spp" ] || spp=$([ "$instructions" = 1 ] && echo 8 || echo 16)
[ -n "$res" ] || res=$([ "$instructions" = 1 ] && echo 128 || echo 256)
for n in spp res top; do
  [[ "${!n}" =~ ^[1-9][0-9]*$ ]] || { echo "layer-profile.sh: --$n must be a positive whole number, not '${!n}'" >&2; exit 2; }
done
[ -z "$scene" ] || [ -f "$scene" ] || { echo "layer-profile.sh: --scene: no file '$scene'" >&2; exit 2; }
if [ "$instructions" = 1 ]; then
  command -v valgrind > /dev/null || { echo "layer-profile.sh: needs valgrind (apt-get install valgrind)" >&2; exit 1; }
else
  command -v perf > /dev/null || { echo "layer-profile.sh: needs perf (Debian: apt-get install linux-perf)" >&2; exit 1; }
fi
bench_find_build "$build"
py=$(bench_python)
bench_work_dir "$keep" penumbra-layers

args=(--threads 1 --rounds 1 --minimal --spp "$spp" --res "$res")
[ -z "$scene" ] || args+=(--scene "$scene")

if [ "$instructions" = 1 ]; then
  # Dumps around the path integrator's render and after each layer's: each layer's part holds what
  # ran since the dump before, its render and little else (the previous image's mean: 8 instructions
  # per sample at the defaults).
  echo "layer-profile.sh: callgrind of penumbra-bench-render ${args[*]} (commit $(bench_commit "$root"))" >&2
  valgrind --tool=callgrind --callgrind-out-file="$work/parts.out" \
    --dump-before='penumbra::SampleIntegrator::render(penumbra::RenderContext&)' \
    --dump-after='penumbra::SampleIntegrator::render(penumbra::RenderContext&)' \
    --dump-after='penumbra::MinimalRenderResult penumbra::MinimalPathTracer::render_with<*' \
    "$build/bin/penumbra-bench-render" "${args[@]}" --rays 1000 > "$work/bench.txt" 2> "$work/valgrind.log" ||
    { tail -20 "$work/valgrind.log" >&2; echo "layer-profile.sh: the counted run failed" >&2; exit 1; }
  for part in "$work"/parts.out.*[0-9]; do  # function totals only (--auto=no: no source listings)
    callgrind_annotate --inclusive=yes --auto=no "$part" > "$part.txt" 2> /dev/null
  done
  "$py" - "$work" "$((res * res * spp))" <<'EOF'
import glob, re, sys

# Each part's renderer, from the function whose end triggered its dump (in the table's order).
work, samples = sys.argv[1], int(sys.argv[2])
names = {"render_with<0u>": "minimal", "render_with<8u>": "minimal, robust origins",
         "render_with<1u>": "+ hit records", "render_with<3u>": "+ light sampling",
         "render_with<7u>": "+ BSDF objects", "SampleIntegrator::render": "path integrator"}
rows = {}
for part in glob.glob(f"{work}/parts.out.*[0-9]"):
    text = open(part).read()
    trigger = re.search(r"^desc: Trigger: (.*)$", text, re.M).group(1)
    if trigger.startswith("--dump-before"):
        continue  # what ran before the path integrator's render: parsing, loading, building
    name = next((n for key, n in names.items() if key in trigger), None)
    if name is None:
        continue
    total = int(re.search(r"^totals: (\d+)", text, re.M).group(1))
    embree = 0  # Embree's three entry points, inclusive (nothing else calls into Embree in a render)
    for line in open(part + ".txt"):
        m = re.match(r"\s*([\d,]+) .*:rtc(Intersect1|Occluded1|Intersect8) ", line)
        if m:
            embree += int(m.group(1).replace(",", ""))
    rows[name] = (total, embree)
print(f"instructions per pixel sample ({samples:,} samples per renderer)")
print(f"{'renderer':20s} {'total':>8s} {'in Embree':>10s} {'elsewhere':>10s}")
for name in names.values():
    if name in rows:
        total, embree = rows[name]
        print(f"{name:20s} {total / samples:8.0f} {embree / samples:10.0f} {(total - embree) / samples:10.0f}")
EOF
  exit 0
fi
echo "layer-profile.sh: perf record of penumbra-bench-render ${args[*]} (commit $(bench_commit "$root"))" >&2
perf record -q -F 1000 --call-graph dwarf,16384 -o "$work/perf.data" \
  "$build/bin/penumbra-bench-render" "${args[@]}" > "$work/bench.txt"
cat "$work/bench.txt"
perf script -i "$work/perf.data" -F ip,sym,dso 2> /dev/null > "$work/stacks.txt"

"$py" - "$work/stacks.txt" "$top" <<'EOF'
import collections, sys

# The renderer a sample belongs to: the first of these frames found walking up from the sampled
# instruction. The render loop's own frame comes after Li's, so Li's callees count as Li's.
owners = [("Li<0u>", "minimal"), ("render_with<0u>", "minimal"),
          ("Li<8u>", "minimal, robust origins"), ("render_with<8u>", "minimal, robust origins"),
          ("Li<1u>", "+ hit records"), ("render_with<1u>", "+ hit records"),
          ("Li<3u>", "+ light sampling"), ("render_with<3u>", "+ light sampling"),
          ("Li<7u>", "+ BSDF objects"), ("render_with<7u>", "+ BSDF objects"),
          ("PathIntegrator::Li", "path integrator: Li"),
          ("SampleIntegrator::render", "path integrator: render loop"),
          ("raw_embree", "raw Embree")]
order = list(dict.fromkeys(name for _, name in owners))  # each renderer once, in the table's order
total = collections.Counter()
embree = collections.Counter()
leaves = collections.defaultdict(collections.Counter)
for block in open(sys.argv[1]).read().split("\n\n"):
    frames = [line.strip() for line in block.strip().split("\n") if line.strip()]
    if not frames:
        continue
    owner = next((name for f in frames for key, name in owners if key in f), None)
    if owner is None:
        continue
    total[owner] += 1
    if "libembree" in frames[0]:
        embree[owner] += 1
    else:
        parts = frames[0].split(None, 1)
        symbol = parts[1] if len(parts) > 1 else parts[0]
        symbol = symbol.rsplit(" (", 1)[0]          # drop the library
        symbol = symbol.replace("(anonymous namespace)", "{anon}").split("(")[0]  # drop the arguments
        leaves[owner][symbol.replace("{anon}", "(anonymous namespace)")[:90]] += 1

print(f"\n{'renderer':32s} {'samples':>8s} {'in Embree':>10s} {'elsewhere':>10s}")
for name in order:
    if total[name]:
        print(f"{name:32s} {total[name]:8d} {embree[name]:10d} {total[name] - embree[name]:10d}")
top = int(sys.argv[2])
for name in order:
    if leaves[name]:
        print(f"\n{name}, outside Embree:")
        for symbol, n in leaves[name].most_common(top):
            print(f"  {n:6d}  {symbol}")
EOF
