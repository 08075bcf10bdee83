#!/usr/bin/env bash
# Makes envelope goldens on a real distributed engine and checks them against the in-process run (issue 17, item 7):
# starts a single-node Slurm cluster on this machine (Debian's slurm-wlm and munge; proctrack/linuxproc, no cgroups),
# submits the lines of 'refray golden update --emit-jobs' as one 'sbatch --array' job, collects the goldens and
# requires them to equal those of 'refray golden update' in one process: every pixel of every envelope channel and
# every attribute but the render times.
#
#   bash tools/slurm_goldens_check.sh REFRAY [SIZE]     (SIZE: 64x36 by default)
#
# Exit status: 0 equal, 1 different or a job failed, 77 skipped: slurmctld or slurmd cannot start here (the message
# says why; ctest reports the test as skipped). Everything lives in a temporary directory and is stopped on exit.
set -uo pipefail

refray=$(readlink -f "${1:?usage: slurm_goldens_check.sh REFRAY [SIZE]}")
size=${2:-64x36}
root=$(cd "$(dirname "$0")/.." && pwd)
skip() { echo "SKIPPED: $*" >&2; exit 77; }
fail() { echo "FAILED: $*" >&2; exit 1; }

for tool in munged slurmctld slurmd sbatch sinfo scontrol; do
  command -v "$tool" > /dev/null || PATH=$PATH:/usr/sbin:/sbin
  command -v "$tool" > /dev/null || skip "$tool is not installed (bash tools/setup.sh installs slurm-wlm and munge)"
done

work=$(mktemp -d /tmp/refray-slurm.XXXXXX)
chmod 700 "$work"
pids=()
cleanup() {
  scontrol shutdown > /dev/null 2>&1 || true
  for f in "$work"/slurmctld.pid "$work"/slurmd.pid "$work"/munged.pid; do
    [ -f "$f" ] && kill "$(cat "$f")" 2> /dev/null
  done
  sleep 1
  for f in "$work"/slurmctld.pid "$work"/slurmd.pid "$work"/munged.pid; do
    [ -f "$f" ] && kill -9 "$(cat "$f")" 2> /dev/null
  done
  if [ "${keep:-0}" = 1 ]; then echo "logs kept in $work" >&2; else rm -rf "$work"; fi
}
trap cleanup EXIT
show_logs() {
  for log in "$work"/munged.log "$work"/slurmctld.log "$work"/slurmd.log; do
    [ -f "$log" ] && { echo "--- $log (last lines)"; tail -n 15 "$log"; }
  done >&2
}

# munge: its own key, socket and files in the work directory.
user=$(id -un)
dd if=/dev/urandom of="$work/munge.key" bs=1024 count=1 status=none
chmod 400 "$work/munge.key"
munged --force --key-file="$work/munge.key" --socket="$work/munge.sock" --pid-file="$work/munged.pid" \
  --log-file="$work/munged.log" --seed-file="$work/munged.seed" > "$work/munged.out" 2>&1 ||
  { cat "$work/munged.out" >&2; skip "munged cannot start: $(tail -n 1 "$work/munged.out")"; }

# TCP ports for the controller and the node daemon: free ones where the kernel lists what is bound, random ones in
# 20000..59999 otherwise (a clash makes the daemon fail to start, and the start below is tried again with others).
port_in_use() { grep -qi ":$(printf '%04X' "$1") " /proc/net/tcp /proc/net/tcp6 2> /dev/null; }
pick_port() {
  local p
  while :; do p=$((20000 + (RANDOM * 32768 + RANDOM) % 40000)); port_in_use "$p" || { echo "$p"; return; }; done
}

host=$(hostname -s)
cpus=$(nproc)
mkdir -p "$work/state" "$work/spool" "$work/out"
export SLURM_CONF=$work/slurm.conf
start_cluster() {
  ctld_port=$(pick_port)
  slurmd_port=$(pick_port)
  cat > "$work/slurm.conf" <<EOF
ClusterName=refray-check
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=$user
SlurmdUser=$user
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$work/munge.sock
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
MaxArraySize=100000
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=check Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF

  slurmctld -c -f "$SLURM_CONF" > "$work/slurmctld.out" 2>&1 || { why="slurmctld cannot start: $(tail -n 1 "$work/slurmctld.out")"; return 1; }
  slurmd -f "$SLURM_CONF" -N "$host" > "$work/slurmd.out" 2>&1 || { why="slurmd cannot start: $(tail -n 1 "$work/slurmd.out")"; ctld_up=1; return 1; }
  for _ in $(seq 1 60); do
    state=$(sinfo -h -n "$host" -o %t 2> /dev/null || true)
    [ "$state" = idle ] && break
    sleep 1
  done
  [ "$state" = idle ] || { why="the Slurm node did not come up in 60 s (state '${state:-none}')"; ctld_up=1; return 1; }
}
up=0
for _ in 1 2 3; do
  ctld_up=0
  if start_cluster; then up=1; break; fi
  scontrol shutdown > /dev/null 2>&1 || true
  for f in "$work"/slurmctld.pid "$work"/slurmd.pid; do [ -f "$f" ] && kill "$(cat "$f")" 2> /dev/null; rm -f "$f"; done
  sleep 1
done
if [ "$up" != 1 ]; then
  show_logs
  # Only a controller that cannot start skips the test; a controller that runs without its node is a failure.
  [ "${ctld_up:-0}" = 1 ] && fail "$why (3 tries)"
  skip "$why (3 tries)"
fi
echo "slurm: controller and node up ($host, $cpus CPUs, ports $ctld_port/$slurmd_port)"

# The plan and its job lines.
cd "$root"
# The scenes: a root holding two of the repository's scene files, one that renders with DispatchRays and one with a
# compute dispatch (every kind of job an update plans), keeps the check short; REFRAY_SLURM_ALL_SCENES=1 takes them all.
if [ "${REFRAY_SLURM_ALL_SCENES:-0}" != 1 ]; then
  mkdir -p "$work/root/scenes"
  cp "$root/scenes/d3d12-procedural-geometry.json" "$root/scenes/inline-ambient-occlusion.json" "$work/root/scenes/" ||
    fail "cannot copy the scene files"
  root=$work/root
fi
"$refray" golden update --size "$size" --dir "$work/slurm-goldens" --root "$root" --emit-jobs "$work/jobs.txt" ||
  fail "refray golden update --emit-jobs"
lines=$(wc -l < "$work/jobs.txt")
start=$(date +%s)
# The README's form, word for word: each array task runs line SLURM_ARRAY_TASK_ID of jobs.txt.
(cd "$work" && sbatch --wait --array="1-$lines" --job-name=refray-goldens --output="$work/out/%a.log" \
  --wrap 'eval "$(sed -n "${SLURM_ARRAY_TASK_ID}p" jobs.txt)"') ||
  { keep=1; show_logs; fail "the sbatch array job failed (task logs in $work/out)"; }
echo "slurm: $lines array tasks done in $(( $(date +%s) - start )) s"

"$refray" golden update --collect --dir "$work/slurm-goldens" > /dev/null || fail "refray golden update --collect"
"$refray" golden update --size "$size" --dir "$work/local-goldens" --root "$root" > /dev/null ||
  fail "refray golden update (in-process)"

# Equal: the manifests (but for nothing: the commit and the settings are the same), every envelope's pixels and
# its attributes but the render times and the file's DateTime.
diff "$work/slurm-goldens/goldens.json" "$work/local-goldens/goldens.json" || fail "the manifests differ"
count=0
for local in "$work"/local-goldens/*.envelope.exr; do
  name=$(basename "$local")
  distributed=$work/slurm-goldens/$name
  [ -f "$distributed" ] || fail "the Slurm run made no $name"
  a=$(iinfo --hash "$local" | grep SHA-1) b=$(iinfo --hash "$distributed" | grep SHA-1)
  [ -n "$a" ] && [ "$a" = "$b" ] || fail "$name: the pixels differ ($a against $b)"
  attributes() { iinfo -v "$1" | tail -n +2 | grep -v -e render_seconds -e DateTime; }
  diff <(attributes "$distributed") <(attributes "$local") || fail "$name: the attributes differ"
  count=$((count + 1))
done
[ "$count" -gt 0 ] || fail "the in-process update made no envelope"
echo "slurm: $count envelope goldens from $lines Slurm array tasks equal the in-process ones"
