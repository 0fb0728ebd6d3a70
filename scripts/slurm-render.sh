#!/usr/bin/env bash
# Renders one scene on a Slurm cluster as a job array: task i renders its share of one sample
# sequence (penumbra render --spp-total/--spp-offset/--spp-count), and a merge job that waits for the
# whole array combines the parts (penumbra merge). docs/farm.md explains the options.
#
#   scripts/slurm-render.sh SCENE OUTPUT.exr SPP PARTS [penumbra render options...]
#       submits the array and the merge job (sbatch options: $SBATCH_OPTIONS, e.g. "-p render -c 32")
#   scripts/slurm-render.sh --local SCENE OUTPUT.exr SPP PARTS [options...]
#       runs the same parts one after the other here, then merges: a rehearsal without Slurm
#
# Parts go to OUTPUT.parts/part-NNNN.exr (with Slurm logs). Every part renders with the same seed
# (--seed in the options, default 0): parts are ranges of one sequence, not independent renders.
# $PENUMBRA names the program (default: penumbra on the PATH); SCENE and OUTPUT must be on storage
# every node sees.
set -euo pipefail

local_run=0
if [ "${1:-}" = "--local" ]; then
  local_run=1
  shift
fi
if [ $# -lt 4 ]; then
  sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
fi
scene="$1" output="$2" spp="$3" parts="$4"
shift 4
penumbra="${PENUMBRA:-penumbra}"
case "$output" in *.exr) ;; *) echo "slurm-render: OUTPUT must end in .exr" >&2; exit 2 ;; esac
if ! [ "$spp" -ge 1 ] 2>/dev/null || ! [ "$parts" -ge 1 ] 2>/dev/null || [ "$parts" -gt "$spp" ]; then
  echo "slurm-render: need 1 <= PARTS <= SPP (got SPP=$spp, PARTS=$parts)" >&2
  exit 2
fi
parts_dir="${output%.exr}.parts"

# Part i takes samples [i*spp/parts, (i+1)*spp/parts): sizes differ by at most one. Each part keeps
# a checkpoint beside its image (every $PENUMBRA_CHECKPOINT_EVERY seconds, default 300, and when it
# is pre-empted: Slurm's SIGTERM is passed on to penumbra, which finishes its pass, writes the
# checkpoint and exits 75); a requeued part resumes from it, so pre-emption costs at most one pass.
part_file() { printf '%s/part-%04d.exr' "$parts_dir" "$1"; }
render_part() {
  local i="$1" first end out ckpt child rc
  shift
  first=$(( i * spp / parts ))
  end=$(( (i + 1) * spp / parts ))
  out=$(part_file "$i")
  ckpt="${out%.exr}.checkpoint"
  local resume=()
  if [ -f "$ckpt" ]; then
    echo "slurm-render: part $i resumes from $ckpt (restart ${SLURM_RESTART_COUNT:-0})" >&2
    resume=(--resume "$ckpt")
  fi
  "$penumbra" render "$scene" -o "$out" -q \
    --spp-total "$spp" --spp-offset "$first" --spp-count $(( end - first )) \
    --checkpoint "$ckpt" --checkpoint-every "${PENUMBRA_CHECKPOINT_EVERY:-300}" "${resume[@]}" "$@" &
  child=$!
  # Slurm signals the batch shell; the render must hear it to save its work.
  trap 'kill -TERM "$child" 2>/dev/null' TERM INT
  rc=0
  wait "$child" || rc=$?
  while kill -0 "$child" 2>/dev/null; do
    rc=0
    wait "$child" || rc=$?
  done
  trap - TERM INT
  if [ "$rc" = 0 ]; then
    rm -f "$ckpt"
  elif [ "$rc" = 75 ]; then
    echo "slurm-render: part $i was interrupted; its checkpoint $ckpt is kept for the requeued run" >&2
    # Requeued rather than failed, so the merge job's dependency still waits for this part (a failed
    # task would leave it DependencyNeverSatisfied). Slurm holds the job briefly before it runs again.
    if [ -n "${SLURM_JOB_ID:-}" ] && [ "${PENUMBRA_SLURM_REQUEUE:-1}" = 1 ]; then
      if scontrol requeue "$SLURM_JOB_ID"; then
        echo "slurm-render: part $i requeued (job $SLURM_JOB_ID)" >&2
        # Let Slurm end this run as requeued; exiting first could record it as failed.
        sleep 120
      fi
    fi
  fi
  return "$rc"
}
# Every part must be there: a missing one is named (overlapping parts are refused by penumbra merge).
merge_parts() {
  local i missing=0
  for (( i = 0; i < parts; ++i )); do
    if [ ! -f "$(part_file "$i")" ]; then
      echo "slurm-render: part $i is missing: $(part_file "$i") (samples $(( i * spp / parts ))-$(( (i + 1) * spp / parts )))" >&2
      missing=1
    fi
    if [ -f "$(part_file "$i" | sed 's/\.exr$//').checkpoint" ]; then
      echo "slurm-render: part $i is unfinished (it was interrupted and its checkpoint remains): $(part_file "$i")" >&2
      missing=1
    fi
  done
  [ "$missing" = 0 ] || exit 1
  "$penumbra" merge "$parts_dir"/part-*.exr -o "$output"
}

case "${PENUMBRA_SLURM_ROLE:-submit}" in
  part) render_part "$SLURM_ARRAY_TASK_ID" "$@" ;;
  merge) merge_parts ;;
  submit)
    mkdir -p "$parts_dir"
    if [ "$local_run" = 1 ]; then
      for (( i = 0; i < parts; ++i )); do render_part "$i" "$@"; done
      merge_parts
      exit 0
    fi
    scene="$(realpath "$scene")" output="$(realpath -m "$output")" parts_dir="$(realpath -m "$parts_dir")"
    self="$(realpath "$0")"
    # shellcheck disable=SC2086 # $SBATCH_OPTIONS holds several words on purpose
    array_job=$(sbatch --parsable --requeue ${SBATCH_OPTIONS:-} --job-name=penumbra-parts --array=0-$(( parts - 1 )) \
      --open-mode=append --output="$parts_dir/slurm-%A_%a.log" --export=ALL,PENUMBRA_SLURM_ROLE=part,PENUMBRA="$penumbra" \
      "$self" "$scene" "$output" "$spp" "$parts" "$@")
    merge_job=$(sbatch --parsable ${SBATCH_OPTIONS:-} --job-name=penumbra-merge --dependency=afterok:"${array_job%%;*}" \
      --output="$parts_dir/slurm-merge-%j.log" --export=ALL,PENUMBRA_SLURM_ROLE=merge,PENUMBRA="$penumbra" \
      "$self" "$scene" "$output" "$spp" "$parts")
    echo "submitted array job $array_job ($parts parts) and merge job $merge_job; output: $output"
    ;;
  *) echo "slurm-render: unknown PENUMBRA_SLURM_ROLE '$PENUMBRA_SLURM_ROLE'" >&2; exit 2 ;;
esac
