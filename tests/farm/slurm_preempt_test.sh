#!/usr/bin/env bash
# A real farm: starts a single-node Slurm cluster (munge, slurmctld, slurmd from Debian's packages,
# configured here in a temporary folder, as root), submits a split render through
# scripts/slurm-render.sh, pre-empts one task (SIGTERM to its batch script, which passes it on and
# requeues the task), and checks
#   - the pre-empted render wrote a checkpoint, the task was requeued and its rerun resumed from it;
#   - the merged image equals the single-machine render (RGB within 2e-6: parts are stored as floats);
#   - negative controls: the same comparison fails for a merge that lacks a part, and the merge step
#     names a missing part.
# Usage: slurm_preempt_test.sh PENUMBRA_BINARY
# Exit 77 (skipped) when Slurm or munge are not installed or we are not root, unless
# PENUMBRA_REQUIRE_SLURM=1 (CI), which makes that a failure.
set -euo pipefail

penumbra="$1"
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
scene="$root/scenes/cornell-box/scene.pbrt"

skip() {
  if [ "${PENUMBRA_REQUIRE_SLURM:-0}" = 1 ]; then echo "FAIL: $1 (PENUMBRA_REQUIRE_SLURM=1)" >&2; exit 1; fi
  echo "SKIP: $1" >&2
  exit 77
}
for tool in munged slurmctld slurmd sbatch squeue scancel scontrol sinfo oiiotool; do
  command -v "$tool" >/dev/null 2>&1 || skip "$tool is not installed (apt-get install slurm-wlm munge openimageio-tools)"
done
[ "$(id -u)" = 0 ] || skip "the test cluster's daemons run as root"

D=$(mktemp -d "${TMPDIR:-/tmp}/penumbra-slurm.XXXXXX")
mkdir -p "$D"/{spool,state,log,munge,work}
H=$(hostname -s)

stop_cluster() {
  for f in "$D/slurmd.pid" "$D/slurmctld.pid" "$D/munge/munged.pid"; do
    [ -f "$f" ] && kill "$(cat "$f")" 2>/dev/null || true
  done
  sleep 0.5
  for f in "$D/slurmd.pid" "$D/slurmctld.pid" "$D/munge/munged.pid"; do
    [ -f "$f" ] && kill -9 "$(cat "$f")" 2>/dev/null || true
  done
}
fail() {
  echo "FAIL: $*" >&2
  for log in "$D"/log/*.log "$D"/work/out.parts/*.log; do
    [ -f "$log" ] && { echo "--- $log" >&2; tail -n 30 "$log" >&2; }
  done
  exit 1
}
trap 'stop_cluster; rm -rf "$D"' EXIT

dd if=/dev/urandom bs=1 count=1024 of="$D/munge/munge.key" 2>/dev/null
chmod 400 "$D/munge/munge.key"
munged --key-file="$D/munge/munge.key" --socket="$D/munge/munge.sock" --pid-file="$D/munge/munged.pid" \
  --log-file="$D/munge/munged.log" --seed-file="$D/munge/seed" -f
cat >"$D/slurm.conf" <<EOF
ClusterName=penumbra-test
SlurmctldHost=$H
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$D/munge/munge.sock
CredType=cred/munge
StateSaveLocation=$D/state
SlurmdSpoolDir=$D/spool
SlurmctldPidFile=$D/slurmctld.pid
SlurmdPidFile=$D/slurmd.pid
SlurmctldLogFile=$D/log/ctld.log
SlurmdLogFile=$D/log/d.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SlurmctldPort=16817
SlurmdPort=16818
ReturnToService=2
NodeName=$H CPUs=$(nproc) State=UNKNOWN
PartitionName=debug Nodes=$H Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$D/slurm.conf"
slurmctld -f "$D/slurm.conf"
slurmd -f "$D/slurm.conf"
for _ in $(seq 300); do
  [ "$(sinfo -h -o %T 2>/dev/null | head -n1)" = idle ] && break
  sleep 0.1
done
[ "$(sinfo -h -o %T | head -n1)" = idle ] || fail "the node did not become idle"

# The farm render: 2 parts of 1600 samples per pixel at 40x40, one task per core; checkpoints every
# 0.2 s so that the pre-emption below finds one.
spp=1600
parts=2
out="$D/work/out.exr"
opts=(--res 40x40 --threads 1 --seed 3)
export PENUMBRA="$penumbra" PENUMBRA_CHECKPOINT_EVERY=0.2 SBATCH_OPTIONS="-c 1"
submitted=$(bash "$root/scripts/slurm-render.sh" "$scene" "$out" "$spp" "$parts" "${opts[@]}")
echo "$submitted"
array=$(sed -n 's/^submitted array job \([0-9]*\).*/\1/p' <<<"$submitted")
[ -n "$array" ] || fail "no array job id in: $submitted"

# Pre-empt task 0 once it has written a checkpoint.
ckpt="$D/work/out.parts/part-0000.checkpoint"
for _ in $(seq 600); do [ -f "$ckpt" ] && break; sleep 0.05; done
[ -f "$ckpt" ] || fail "task 0 wrote no checkpoint"
scancel --batch --signal=TERM "${array}_0"
# The part's script passes SIGTERM on, penumbra finishes its pass and writes the checkpoint, and the
# script requeues its task (held by Slurm with reason BeginTime); release it at once.
for _ in $(seq 600); do
  state=$(squeue -h -j "${array}_0" -o %T 2>/dev/null || true)
  [ "$state" = PENDING ] && break
  sleep 0.05
done
[ "$state" = PENDING ] || fail "task 0 was not requeued after SIGTERM (state '$state')"
log0="$D/work/out.parts/slurm-${array}_0.log"
grep -q "interrupted (SIGTERM)" "$log0" || fail "penumbra in task 0 did not get the SIGTERM"
grep -q "part 0 was interrupted" "$log0" || fail "task 0 did not report its interruption"
[ -f "$ckpt" ] || fail "task 0's checkpoint is gone after the interruption"
# Not "starttime=now": slurmd revokes the killed run's credential with a time stamp in whole seconds
# and refuses a launch whose credential is from the same second ("Job credential revoked"; the task
# then fails and the merge job waits forever on its dependency). Two seconds later is always safe.
scontrol update jobid="${array}_0" starttime=now+2

# Everything finishes: both tasks, then the merge job.
for _ in $(seq 1200); do
  [ -z "$(squeue -h -o %i 2>/dev/null)" ] && break
  sleep 0.1
done
[ -z "$(squeue -h -o %i)" ] || fail "jobs still queued: $(squeue -h -o '%i %T %r')"
[ -f "$out" ] || fail "no merged image (the merge job did not run)"
grep -q "part 0 resumes from $ckpt (restart 1)" "$log0" || fail "the requeued task 0 did not resume from its checkpoint"
[ ! -f "$ckpt" ] || fail "the finished part left its checkpoint behind"

# The single-machine render of the same samples.
"$penumbra" render "$scene" -o "$D/work/single.exr" -q --spp-total "$spp" "${opts[@]}"
same() { oiiotool "$1" --ch R,G,B "$2" --ch R,G,B --fail 2e-6 --failpercent 0 --diff >"$D/diff.txt" 2>&1; }
same "$out" "$D/work/single.exr" || { cat "$D/diff.txt" >&2; fail "the merged image differs from the single-machine render"; }

# Negative controls: half the samples do not pass the same comparison, and a missing part is named.
"$penumbra" merge "$D/work/out.parts/part-0001.exr" -o "$D/work/half.exr" 2>/dev/null
if same "$D/work/half.exr" "$D/work/single.exr"; then fail "the comparison cannot tell half the samples from all"; fi
rm "$D/work/out.parts/part-0000.exr"
if PENUMBRA_SLURM_ROLE=merge bash "$root/scripts/slurm-render.sh" "$scene" "$out" "$spp" "$parts" 2>"$D/merge.txt"; then
  fail "the merge step accepted a missing part"
fi
grep -q "part 0 is missing: $D/work/out.parts/part-0000.exr (samples 0-800)" "$D/merge.txt" || fail "missing part not named: $(cat "$D/merge.txt")"
echo "PASS: pre-empted task resumed from its checkpoint; merged image equals the single-machine render"
