#!/usr/bin/env bash
# Render pbrt-v4 scenes with Penumbra and with pbrt-v4 itself at the same low resolution and sample
# count, and print the per-channel image-mean ratios Penumbra / pbrt-v4.
#
#   PBRT=/path/to/pbrt scripts/compare-with-pbrt-v4.sh [options] [SCENE[:SPP] ...]
#   scripts/compare-with-pbrt-v4.sh /path/to/pbrt [options] [SCENE[:SPP] ...]
#
# SCENE is a folder name under scenes/pbrt-v4/ (coffee, cornell-box, ...) or a path to a .pbrt file;
# the default is the eight scenes in scenes/pbrt-v4/. ":SPP" overrides --spp for that scene.
#
# Options:
#   --width N       image width in pixels; the height keeps the scene's aspect (default 160)
#   --spp N         samples per pixel, the same for both renderers (default 64)
#   --threads N     threads for each render (default 2); renders run one at a time
#   --seed N        seed for both renderers (default 1)
#   --noise         also render each Penumbra run with seed+1 and print the seed-to-seed change of the means
#   --pbrt-path     also render pbrt-v4 with "path" when the scene's integrator is another one
#   --no-native     do not render Penumbra with the scene's own integrator (only with path)
#   --out DIR       where the temporary scene copies and images go (default /tmp/penumbra-vs-pbrt-v4)
#   --penumbra BIN  Penumbra binary (default: build/bin/penumbra of this checkout)
#   --rgb           render Penumbra with RGB transport (its default) instead of spectral transport, which
#                   this script uses by default because pbrt-v4 always renders spectrally
#   --crop-top F    also compare the means of the images without their top fraction F (0 < F < 1): for
#                   scenes whose mean is dominated by a tiny light seen directly (water-caustic: a few
#                   camera samples per render hit it, so the full mean cannot agree at any practical spp)
#
# Each scene is rendered from a copy in DIR/<scene>/ (symlinks to the scene's folder contents plus a
# rewritten scene file): the Film's resolution is replaced, nothing else. When the scene lights with a
# 2:1 lat-long `infinite` image (pbrt-v4 refuses those: it reads only square equal-area maps), the image
# is converted with `penumbra envmap IN OUT.exr --to equalarea` and the copy points both renderers at
# the converted map; the output says so. Files under scenes/ are never modified.
#
# pbrt-v4 renders with the scene's own integrator; Penumbra with "path" (maxdepth taken from the scene)
# and, when the scene asks for bdpt/sppm/volpath, also with that integrator.
# Output: one block per scene and a summary table; the images stay in DIR for inspection.
set -u -o pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
pbrt="${PBRT:-}"
if [[ $# -gt 0 && "$1" != -* && -x "$1" && ! -d "$1" && "$1" != *.pbrt ]]; then pbrt="$1"; shift; fi
width=160 spp=64 threads=2 seed=1 noise=0 pbrtpath=0 native=1 croptop="" transport=(--spectral)
out=/tmp/penumbra-vs-pbrt-v4
penumbra="$here/build/bin/penumbra"
scenes=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --width) width="$2"; shift 2 ;;
    --spp) spp="$2"; shift 2 ;;
    --threads|--nthreads) threads="$2"; shift 2 ;;
    --seed) seed="$2"; shift 2 ;;
    --noise) noise=1; shift ;;
    --pbrt-path) pbrtpath=1; shift ;;
    --no-native) native=0; shift ;;
    --out) out="$2"; shift 2 ;;
    --penumbra) penumbra="$2"; shift 2 ;;
    --crop-top) croptop="$2"; shift 2 ;;
    --rgb) transport=(); shift ;;
    -h|--help) sed -n '2,30p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "unknown option $1" >&2; exit 2 ;;
    *) scenes+=("$1"); shift ;;
  esac
done
if [[ -z "$pbrt" || ! -x "$pbrt" ]]; then
  echo "error: give the pbrt-v4 binary as the first argument or in \$PBRT" >&2; exit 2
fi
if [[ ! -x "$penumbra" ]]; then echo "error: no Penumbra binary at $penumbra" >&2; exit 2; fi
command -v oiiotool >/dev/null || { echo "error: oiiotool is needed for the image means" >&2; exit 2; }
if [[ ${#scenes[@]} -eq 0 ]]; then
  for d in "$here"/scenes/pbrt-v4/*/; do [[ -f "$d/scene-v4.pbrt" ]] && scenes+=("$(basename "$d")"); done
fi
mkdir -p "$out"

# Run Penumbra (log file, then its arguments). A crash or a missing binary is retried twice after
# 30 s: the build directory may be being rebuilt while the comparison runs.
runpen() { local log="$1" rc try; shift
  for try in 1 2 3; do
    if [[ -x "$penumbra" ]]; then "$penumbra" "$@" >"$log" 2>&1; rc=$?; else rc=127; fi
    [[ $rc -lt 126 ]] && return $rc
    echo "   (penumbra exit status $rc, attempt $try: retrying in 30 s)" >&2; sleep 30
  done
  return $rc; }

# Image mean per channel: "r g b".
means() { oiiotool -v --stats "$1" 2>/dev/null | awk '/Stats Avg/ { print $3, $4, $5; exit }'; }
# Mean per channel over the image without its top fraction $croptop.
cropmeans() { local w h y0
  read -r w h < <(oiiotool --info "$1" | sed -E 's/.*: *([0-9]+) x +([0-9]+),.*/\1 \2/')
  y0=$(awk -v h="$h" -v f="$croptop" 'BEGIN { printf "%d", h * f + 0.5 }')
  oiiotool "$1" --crop "${w}x$((h - y0))+0+$y0" -o "${1%.exr}-cropped.exr" && means "${1%.exr}-cropped.exr"; }
# Ratio a/b per channel: "1.0123 0.9987 1.0034".
ratios() { awk -v a="$1" -v b="$2" 'BEGIN { n = split(a, x, " "); split(b, y, " ");
  for (i = 1; i <= n; i++) printf "%s%.4f", (i > 1 ? " " : ""), (y[i] != 0 ? x[i] / y[i] : 0); }'; }
# Largest |ratio - 1| in percent.
worst() { awk -v r="$1" 'BEGIN { n = split(r, x, " "); m = 0;
  for (i = 1; i <= n; i++) { d = x[i] - 1; if (d < 0) d = -d; if (d > m) m = d; } printf "%.1f", 100 * m; }'; }

# Write the copy of a scene: prints "integrator maxdepth width height note" on stdout.
prepare() { # src dst width
  python3 - "$1" "$2" "$3" "$penumbra" <<'PY'
import os, re, subprocess, sys
src, dst, width, penumbra = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
text = open(src).read()
# Comment-free view (same length) so matches ignore commented-out values.
def strip(t):
    return re.sub(r'#[^\n]*', lambda m: ' ' * len(m.group(0)), re.sub(r'"[^"\n]*"', lambda m: m.group(0).replace('#', '\0'), t)).replace('\0', '#')
clean = strip(text)
directive = re.compile(r'^\s*([A-Z][A-Za-z]+)\b', re.M)
def statements(name):
    """(start, end) of each statement with this directive, up to the next directive."""
    starts = [(m.start(1), m.group(1)) for m in directive.finditer(clean)]
    for i, (s, n) in enumerate(starts):
        if n == name:
            yield s, (starts[i + 1][0] if i + 1 < len(starts) else len(clean))
def param(s, e, ty, name):
    m = re.search(r'"\s*%s\s+%s\s*"\s*(\[?)\s*([^\]"\s]+|"[^"]*")' % (ty, re.escape(name)), clean[s:e])
    return (m, s) if m else (None, s)
integ, maxdepth = 'path', 5
for s, e in statements('Integrator'):
    integ = re.match(r'Integrator\s+"([^"]+)"', clean[s:e]).group(1)
    m, _ = param(s, e, 'integer', 'maxdepth')
    if m: maxdepth = int(m.group(2))
edits = []  # (start, end, replacement)
xres, yres = 1280, 720  # pbrt-v4's defaults
film = list(statements('Film'))
if not film:
    sys.exit('no Film statement in ' + src)
fs, fe = film[0]
for ty, nm in (('integer', 'xresolution'), ('integer', 'yresolution')):
    m, off = param(fs, fe, ty, nm)
    if m:
        v = int(m.group(2))
        if nm == 'xresolution': xres = v
        else: yres = v
height = max(1, round(width * yres / xres))
# Drop both resolution parameters and put ours after the Film's type.
for nm in ('xresolution', 'yresolution'):
    for m in re.finditer(r'"\s*integer\s+%s\s*"\s*(\[\s*[^\]]*\]|\S+)' % nm, clean[fs:fe]):
        edits.append((fs + m.start(), fs + m.end(), ''))
m = re.match(r'Film\s+"[^"]+"', clean[fs:fe])
edits.append((fs + m.end(), fs + m.end(), '\n    "integer xresolution" [ %d ] "integer yresolution" [ %d ]' % (width, height)))
# Environment images that are not square: convert to pbrt-v4's equal-area map.
notes = []
for s, e in statements('LightSource'):
    if not re.match(r'LightSource\s+"infinite"', clean[s:e]): continue
    m = re.search(r'"\s*string\s+filename\s*"\s*\[?\s*"([^"]*)"', clean[s:e])
    if not m: continue
    fn = m.group(1)
    path = fn if os.path.isabs(fn) else os.path.join(os.path.dirname(src), fn)
    info = subprocess.run(['oiiotool', '--info', path], capture_output=True, text=True).stdout
    size = re.search(r'(\d+)\s*x\s*(\d+)', info)
    if not size or size.group(1) == size.group(2): continue
    conv = os.path.join(os.path.dirname(dst), 'equalarea-' + re.sub(r'[^A-Za-z0-9._-]', '_', os.path.basename(fn)) + '.exr')
    r = subprocess.run([penumbra, 'envmap', path, conv, '--to', 'equalarea'], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit('envmap conversion of %s failed: %s' % (path, r.stderr.strip()))
    edits.append((s + m.start(1), s + m.end(1), conv))
    notes.append('%s is %sx%s lat-long: pbrt-v4 refuses it, both renderers read %s (penumbra envmap --to equalarea)'
                 % (fn, size.group(1), size.group(2), os.path.basename(conv)))
for a, b, r in sorted(edits, reverse=True):
    text = text[:a] + r + text[b:]
open(dst, 'w').write(text)
print(integ, maxdepth, width, height, ' | '.join(notes) if notes else '-')
PY
}

summary=()
for entry in "${scenes[@]}"; do
  name="${entry%%:*}"; sspp="$spp"
  [[ "$entry" == *:* ]] && sspp="${entry##*:}"
  if [[ -f "$name" ]]; then src="$(cd "$(dirname "$name")" && pwd)/$(basename "$name")"; tag="$(basename "$(dirname "$src")")-$(basename "$src" .pbrt)"
  else src="$here/scenes/pbrt-v4/$name/scene-v4.pbrt"; tag="$name"; fi
  [[ -f "$src" ]] || { echo "== $name: no scene file $src"; continue; }
  work="$out/$tag"; rm -rf "$work"; mkdir -p "$work"
  for f in "$(dirname "$src")"/*; do ln -s "$f" "$work/$(basename "$f")"; done
  copy="$work/compare-$(basename "$src")"
  read -r integ maxdepth w h note < <(prepare "$src" "$copy" "$width" || echo FAIL)
  if [[ "$integ" == FAIL || -z "$integ" ]]; then echo "== $tag: could not prepare the scene copy"; continue; fi
  echo "== $tag: ${w}x${h}, $sspp spp, seed $seed, scene integrator $integ (maxdepth $maxdepth)"
  [[ "$note" != "-" ]] && echo "   note: $note"

  t0=$SECONDS
  if "$pbrt" --nthreads "$threads" --spp "$sspp" --seed "$seed" --quiet --outfile "$work/pbrt-$integ.exr" "$copy" \
       >"$work/pbrt-$integ.log" 2>&1 && [[ -f "$work/pbrt-$integ.exr" ]]; then
    pm="$(means "$work/pbrt-$integ.exr")"
    echo "   pbrt-v4 $integ: mean $pm ($((SECONDS - t0)) s)"
  else
    pm=""
    echo "   pbrt-v4 refused or failed ($((SECONDS - t0)) s): $(grep -m1 -iE 'error|fatal' "$work/pbrt-$integ.log" || tail -n1 "$work/pbrt-$integ.log")"
  fi

  runs=(path)
  # Penumbra's volpath is an alias of its path integrator: the same render.
  [[ $native -eq 1 && "$integ" != path && "$integ" != volpath ]] && runs+=("$integ")
  [[ "$integ" == volpath ]] && echo "   (Penumbra's volpath is its path integrator: rendered once)"
  pathratio="-" nativeratio="-" noisepath="-" noisenative="-"
  for run in "${runs[@]}"; do
    img="$work/penumbra-$run.exr"; t0=$SECONDS
    args=(render "$copy" -o "$img" --spp "$sspp" --res "${w}x${h}" --nthreads "$threads" --seed "$seed" -q
          ${transport[@]+"${transport[@]}"})
    [[ "$run" == path ]] && args+=(--integrator path --param "maxdepth=$maxdepth")
    runpen "$work/penumbra-$run.log" "${args[@]}"; rc=$?
    if [[ $rc -eq 0 ]]; then
      m="$(means "$img")"; msg="   penumbra $run: mean $m ($((SECONDS - t0)) s)"
      if [[ -n "$pm" ]]; then
        r="$(ratios "$m" "$pm")"; msg+="  ratio to pbrt-v4: $r (worst $(worst "$r") %)"
        [[ "$run" == path ]] && pathratio="$r" || nativeratio="$r"
      fi
      echo "$msg"
      if [[ $noise -eq 1 ]]; then
        img2="$work/penumbra-$run-seed$((seed + 1)).exr"; args2=("${args[@]}")
        for i in "${!args2[@]}"; do
          [[ "${args2[$i]}" == "$img" ]] && args2[$i]="$img2"
          [[ $i -gt 0 && "${args2[$((i - 1))]}" == --seed ]] && args2[$i]="$((seed + 1))"
        done
        if runpen "$work/penumbra-$run-seed$((seed + 1)).log" "${args2[@]}"; then
          r="$(ratios "$(means "$img2")" "$m")"
          n="$(awk -v r="$r" 'BEGIN { n = split(r, x, " ");
            for (i = 1; i <= n; i++) printf "%s%+.2f", (i > 1 ? " " : ""), 100 * (x[i] - 1); }')"
          echo "   noise: penumbra $run seed $((seed + 1)) / seed $seed - 1 = $n % (per channel)"
          [[ "$run" == path ]] && noisepath="$n" || noisenative="$n"
        fi
      fi
    else
      echo "   penumbra $run failed: $(grep -m1 -i error "$work/penumbra-$run.log" || echo "exit status $rc (see $work/penumbra-$run.log)")"
    fi
  done

  cropcol=""
  if [[ -n "$croptop" && -n "$pm" ]]; then
    cpm="$(cropmeans "$work/pbrt-$integ.exr")"
    for run in "${runs[@]}"; do
      [[ -f "$work/penumbra-$run.exr" ]] || continue
      r="$(ratios "$(cropmeans "$work/penumbra-$run.exr")" "$cpm")"
      echo "   without the top $croptop of the image: penumbra $run / pbrt-v4 = $r"
      cropcol+=" $run $r;"
      for f in "$work/penumbra-$run-seed"[0-9].exr "$work/penumbra-$run-seed"[0-9][0-9].exr; do
        [[ -f "$f" ]] && echo "     seed $((seed + 1)): penumbra $run / pbrt-v4 = $(ratios "$(cropmeans "$f")" "$cpm")"
      done
    done
  fi

  if [[ -n "$pm" && $pbrtpath -eq 1 && "$integ" != path ]]; then
    sed -E 's/^(\s*)Integrator\s+"[a-z]+"/\1Integrator "path"/' "$copy" | \
      grep -vE '"(float radius|integer photonsperiteration|integer seed|bool visualizestrategies|bool visualizeweights|string lightsampler|bool regularize)"' \
      >"$work/compare-path-$(basename "$src")"
    t0=$SECONDS
    if "$pbrt" --nthreads "$threads" --spp "$sspp" --seed "$seed" --quiet --outfile "$work/pbrt-path.exr" \
         "$work/compare-path-$(basename "$src")" >"$work/pbrt-path.log" 2>&1; then
      ppm="$(means "$work/pbrt-path.exr")"
      echo "   pbrt-v4 path: mean $ppm ($((SECONDS - t0)) s); penumbra path / pbrt-v4 path: $(ratios "$(means "$work/penumbra-path.exr")" "$ppm")"
    else
      echo "   pbrt-v4 path failed: $(grep -m1 -iE 'error|fatal' "$work/pbrt-path.log")"
    fi
  fi
  summary+=("$(printf '%-18s %-8s %-11s %-22s %-22s %-20s %s' "$tag" "$integ" "${w}x${h}/$sspp" "$pathratio" "$nativeratio" "$noisepath" "$noisenative")")
  [[ "$note" != "-" ]] && summary[-1]+="  (equal-area copy of the environment)"
  [[ -n "$cropcol" ]] && summary+=("$(printf '%-18s without the top %s:%s' "" "$croptop" "$cropcol")")
done

echo
echo "Penumbra / pbrt-v4, image mean per channel (R G B); pbrt-v4 with the scene's integrator"
printf '%-18s %-8s %-11s %-22s %-22s %-20s %s\n' scene pbrt-v4 res/spp "penumbra path" "penumbra same integ." "path seed2/seed1-1 %" "same integ. %"
for l in "${summary[@]}"; do echo "$l"; done
