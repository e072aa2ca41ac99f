#!/usr/bin/env bash
# A shot on a one-node Slurm cluster that this test starts and stops itself (munged, slurmctld,
# slurmd, configured in a temporary folder): scripts/slurm-simulate.sh submits a 4-task array over a
# 24-frame sequence of a moving light with a cold shared cache; every frame must be byte-identical
# to a single process's. Then two frames are lost and the same submission renders only those.
#   tests/farm/test_slurm.sh FOURIERFLARE_BINARY
# Exit 77 (skipped) with the reason where Slurm, munge or root are missing.
set -euo pipefail
ff="$(readlink -f "$1")"
source_dir="$(cd "$(dirname "$0")/../.." && pwd)"
skip() { echo "test_slurm: SKIPPED: $*"; exit 77; }
fail() { echo "test_slurm: FAIL: $*" >&2; exit 1; }
for tool in munged munge slurmctld slurmd sbatch sinfo scontrol oiiotool; do
  command -v "$tool" > /dev/null || skip "$tool is not installed (Debian: slurmctld slurmd slurm-client munge openimageio-tools)"
done
[ "$(id -u)" -eq 0 ] || skip "slurmd runs its jobs as root here; run as root"

tmp="$(mktemp -d /tmp/ff-slurm.XXXXXX)"
chmod 755 "$tmp" # munged requires its socket's folders to be reachable by all
cleanup() {
  SLURM_CONF="$tmp/slurm.conf" scontrol shutdown > /dev/null 2>&1 || true
  for p in slurmctld slurmd munged; do
    [ -f "$tmp/$p.pid" ] && kill "$(cat "$tmp/$p.pid")" 2> /dev/null || true
  done
  sleep 1
  for p in slurmctld slurmd munged; do
    [ -f "$tmp/$p.pid" ] && kill -9 "$(cat "$tmp/$p.pid")" 2> /dev/null || true
  done
  rm -rf "$tmp"
}
trap cleanup EXIT

# munge: a fresh key and a private socket.
head -c 1024 /dev/urandom > "$tmp/munge.key"
chmod 600 "$tmp/munge.key"
munged --socket="$tmp/munge.socket" --key-file="$tmp/munge.key" --pid-file="$tmp/munged.pid" \
  --log-file="$tmp/munged.log" --seed-file="$tmp/munge.seed" || fail "munged did not start: $(cat "$tmp/munged.log" 2> /dev/null)"

# Slurm: this host as the only node, on two free ports.
host="$(hostname -s)"
port() { python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'; }
ctld_port="$(port)" slurmd_port="$(port)"
[ "$ctld_port" != "$slurmd_port" ] || slurmd_port=$((ctld_port + 1))
mkdir -p "$tmp/state" "$tmp/spool"
cat > "$tmp/slurm.conf" << EOF
ClusterName=fourierflare-test
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$tmp/munge.socket
CredType=cred/munge
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmctldLogFile=$tmp/slurmctld.log
SlurmdLogFile=$tmp/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
NodeName=$host NodeAddr=127.0.0.1 CPUs=2 RealMemory=1000 State=UNKNOWN
PartitionName=test Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$tmp/slurm.conf"
slurmctld -f "$SLURM_CONF" -c || fail "slurmctld did not start: $(tail -5 "$tmp/slurmctld.log")"
slurmd -f "$SLURM_CONF" -N "$host" || fail "slurmd did not start: $(tail -5 "$tmp/slurmd.log")"
for _ in $(seq 60); do
  sinfo -h -o %t 2> /dev/null | grep -q idle && break
  sleep 0.5
done
sinfo -h -o %t | grep -q idle || fail "the node never became idle: $(sinfo 2>&1; tail -5 "$tmp/slurmd.log")"

# 24 plates of a light crossing the frame.
mkdir -p "$tmp/plates"
for f in $(seq 1 24); do
  x=$((8 + 5 * f)) y=$((20 + f))
  oiiotool --pattern constant:color=0.02,0.025,0.03 128x72 3 \
    --box:color=900,800,700:fill=1 "$x,$y,$((x + 1)),$((y + 1))" -d float \
    -o "$tmp/plates/plate.$(printf %04d "$f").exr"
done
args=(--lens "$source_dir/lenses/cooke-triplet-50mm-f5.lens" --plate "$tmp/plates/plate.%04d.exr"
      -o "$tmp/out/flare.%04d.exr" --preview "$tmp/out/flare.%04d.png" --table-grid 16 --backend cpu)

# The reference: one process, the whole range, a cache of its own.
mkdir -p "$tmp/out"
FF_CACHE_DIR="$tmp/cache-single" "$ff" -q simulate "${args[@]}" --frames 1-24
mv "$tmp/out" "$tmp/single"

# The farm: 4 tasks of 6 frames, one cold shared cache.
mkdir -p "$tmp/out"
SECONDS=0
(cd "$tmp" && FOURIERFLARE="$ff" FF_FARM_LOGS="$tmp/logs" \
  "$source_dir/scripts/slurm-simulate.sh" --frames 1-24 --per-task 6 --cache "$tmp/cache-farm" \
  --sbatch "--cpus-per-task=1" --wait -- "${args[@]}") || fail "the array failed: $(cat "$tmp"/logs/*.log)"
seconds=$SECONDS
tasks=$(ls "$tmp"/logs/*.log | wc -l)
[ "$tasks" -eq 4 ] || fail "$tasks task logs, expected 4"
grep -h "frames" "$tmp"/logs/*.log
for f in $(seq -f %04g 1 24); do
  for ext in exr png; do
    cmp -s "$tmp/single/flare.$f.$ext" "$tmp/out/flare.$f.$ext" || fail "frame $f .$ext differs from the single process's"
  done
done
[ "$(ls "$tmp/out" | wc -l)" -eq 48 ] || fail "$(ls "$tmp/out" | wc -l) files in the output, expected 48"
# One cache: the same entries as the single process's, whole, no temporaries.
(cd "$tmp/cache-single" && ls) > "$tmp/entries-single"
(cd "$tmp/cache-farm" && ls -A) > "$tmp/entries-farm"
cmp -s "$tmp/entries-single" "$tmp/entries-farm" || fail "cache entries: $(cat "$tmp/entries-farm")"
for e in $(cat "$tmp/entries-single"); do
  cmp -s "$tmp/cache-single/$e" "$tmp/cache-farm/$e" || fail "cache entry $e differs"
done

# Two frames lost: the same submission renders those two only, the same bytes again.
rm "$tmp/out/flare.0007.exr" "$tmp/out/flare.0020.png"
rm -rf "$tmp/logs"
(cd "$tmp" && FOURIERFLARE="$ff" FF_FARM_LOGS="$tmp/logs" \
  "$source_dir/scripts/slurm-simulate.sh" --frames 1-24 --per-task 6 --cache "$tmp/cache-farm" \
  --sbatch "--cpus-per-task=1" --wait -- "${args[@]}") || fail "the rerun failed: $(cat "$tmp"/logs/*.log)"
skipped=$(grep -ho "already written, skipped" "$tmp"/logs/*.log | wc -l)
grep -h "skip-existing" "$tmp"/logs/*.log
[ "$skipped" -eq 4 ] || fail "the rerun's tasks did not skip the frames that exist"
grep -q "5 of 6 frames already written" "$tmp"/logs/*_1.log || fail "task 1 should render frame 7 only"
grep -q "5 of 6 frames already written" "$tmp"/logs/*_3.log || fail "task 3 should render frame 20 only"
for f in 0007 0020; do
  for ext in exr png; do
    cmp -s "$tmp/single/flare.$f.$ext" "$tmp/out/flare.$f.$ext" || fail "rerun frame $f .$ext differs"
  done
done
echo "test_slurm: ok: 24 frames in 4 array tasks (${seconds} s), byte-identical to one process; rerun rendered the 2 lost frames"
