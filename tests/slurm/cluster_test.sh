#!/usr/bin/env bash
# tools/slurm-evaluate on a real one-node Slurm cluster started on this machine (docs/cluster.md):
# munge, slurmctld and slurmd configured in a temporary directory on ports of their own, stopped
# and removed at the end. Needs root and Debian's slurm-wlm and munge (tools/setup --slurm);
# without them it says why and exits 77 (skipped). Run from the repository after tools/setup:
#   tests/slurm/cluster_test.sh
# It checks that
#   1. 16 plans (tools/make-plan-set) in 4 shards with --monte-carlo 2, merged on the cluster, give
#      the very report of one unsharded run on this machine;
#   2. a shard that fails (a damaged plan file) fails its task and Slurm cancels the merge: no
#      report is written;
#   3. with the file mended, `--only` that shard runs it again and the merge gives the report of 1.
set -uo pipefail
top=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cd "$top"
started=$SECONDS

skip() {
  echo "slurm cluster test: skipped: $1"
  exit 77
}
[ "$(id -u)" -eq 0 ] || skip "slurmd and slurmctld need root here (run tools/test as root)"
for program in munged slurmctld slurmd sbatch squeue scontrol sinfo; do
  command -v "$program" > /dev/null ||
    skip "$program is not installed (tools/setup --slurm installs Debian's slurm-wlm and munge)"
done
[ -x build/tubeplan ] || skip "build/tubeplan is not built (tools/setup)"

failures=0
fail() {
  echo "slurm cluster test: FAILED: $1"
  failures=$((failures + 1))
}

dir=$(mktemp -d /tmp/tubeplan-slurm.XXXXXX)
export SLURM_CONF=$dir/slurm.conf
cleanup() {
  scancel --quiet --user=root 2> /dev/null
  for pid_file in "$dir/slurmd.pid" "$dir/slurmctld.pid" "$dir/munge/munged.pid"; do
    [ -f "$pid_file" ] && kill "$(cat "$pid_file")" 2> /dev/null
  done
  sleep 1
  rm -rf "$dir"
}
trap cleanup EXIT

# A port nothing listens on (a connection to it is refused).
free_port() {
  local port
  for _ in $(seq 1 50); do
    port=$((20000 + RANDOM % 20000))
    if ! (exec 3<> "/dev/tcp/127.0.0.1/$port") 2> /dev/null; then
      echo "$port"
      return
    fi
  done
  echo 0
}

# The cluster: munge with a key of its own, then the controller and one node with every core.
mkdir -p "$dir/munge" "$dir/state" "$dir/spool"
chmod 700 "$dir/munge"
head -c 1024 /dev/urandom > "$dir/munge/munge.key"
chmod 400 "$dir/munge/munge.key"
munged --socket="$dir/munge/munge.sock" --key-file="$dir/munge/munge.key" \
  --pid-file="$dir/munge/munged.pid" --log-file="$dir/munge/munged.log" \
  --seed-file="$dir/munge/munge.seed" --force || skip "munged did not start"
host=$(hostname -s)
cat > "$SLURM_CONF" << EOF
ClusterName=tubeplantest
SlurmctldHost=$host
AuthType=auth/munge
AuthInfo=socket=$dir/munge/munge.sock
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
SlurmctldPort=$(free_port)
SlurmdPort=$(free_port)
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
NodeName=$host CPUs=$(nproc) State=UNKNOWN
PartitionName=test Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
slurmctld -f "$SLURM_CONF" && slurmd -f "$SLURM_CONF" ||
  skip "slurmctld or slurmd did not start (see their logs: $(tail -n 3 "$dir"/*.log))"
for _ in $(seq 1 60); do
  [ "$(sinfo -h -o %T 2> /dev/null)" = idle ] && break
  sleep 0.5
done
[ "$(sinfo -h -o %T 2> /dev/null)" = idle ] || skip "the node did not come up: $(sinfo 2>&1)"
echo "slurm cluster test: one node ($host, $(nproc) cores) up after $((SECONDS - started)) s"

# The final state of job ID (each array task's, one a line) once none of it is queued or running;
# gives up after 120 s.
wait_job() {
  local until=$((SECONDS + 120))
  while [ -n "$(squeue -h -j "$1" -t PD,R,CG 2> /dev/null)" ] && ((SECONDS < until)); do
    sleep 0.5
  done
  scontrol -o show job "$1" | grep -o 'JobState=[A-Z_]*' | cut -d= -f2
}
# The job ids of the last submission into OUT_DIR (tools/slurm-evaluate writes them).
last_job() { grep "^$2 " "$1/jobs.txt" | tail -n 1 | cut -d' ' -f2; }

plans=$dir/plans
tools/make-plan-set 16 "$plans" > /dev/null || fail "tools/make-plan-set 16 did not make its plans"
build/tubeplan evaluate "$plans" --monte-carlo 2 --report "$dir/one.json" > /dev/null
[ $? -le 1 ] && [ -s "$dir/one.json" ] || fail "the unsharded evaluate did not write its report"

# 1. Four shards and the merge on the cluster.
tools/slurm-evaluate "$plans" 4 "$dir/out" -- --monte-carlo 2 ||
  fail "tools/slurm-evaluate did not submit"
state=$(wait_job "$(last_job "$dir/out" merge)")
[ "$state" = COMPLETED ] || fail "the merge job ended $state, expected COMPLETED"
cmp -s "$dir/one.json" "$dir/out/report.json" ||
  fail "the merged report differs from the unsharded one: $(diff "$dir/one.json" "$dir/out/report.json" | head -n 5)"

# 2. Shard 3 (plan-00003, 7, 11 and 15 in path order) fails: the merge must not run.
cp "$plans/plan-00003.yaml" "$dir/plan-00003.yaml.good"
echo "states: [not a list" >> "$plans/plan-00003.yaml"
tools/slurm-evaluate "$plans" 4 "$dir/out2" -- --monte-carlo 2 || fail "the second submission"
tasks=$(wait_job "$(last_job "$dir/out2" array)" | sort | uniq -c | tr -s ' ' | tr '\n' ',')
state=$(wait_job "$(last_job "$dir/out2" merge)")
[ "$tasks" = " 3 COMPLETED, 1 FAILED," ] || fail "the shards ended$tasks expected 3 COMPLETED and 1 FAILED"
[ "$state" = CANCELLED ] || fail "the merge after a failed shard ended $state, expected CANCELLED"
[ ! -e "$dir/out2/report.json" ] || fail "a report was written although shard 3 failed"
[ ! -e "$dir/out2/shard-3.json" ] && [ -s "$dir/out2/shard-4.json" ] ||
  fail "after the failure, shard 3's report should be missing and shard 4's there"
grep -q "plan-00003.yaml:.*error" "$dir/out2/shard-3.txt" ||
  fail "shard 3's output does not name the damaged file: $(head -n 3 "$dir/out2/shard-3.txt")"

# 3. Mended, shard 3 alone again, then the merge.
cp "$dir/plan-00003.yaml.good" "$plans/plan-00003.yaml"
tools/slurm-evaluate "$plans" 4 "$dir/out2" --only 3 -- --monte-carlo 2 || fail "the resubmission"
state=$(wait_job "$(last_job "$dir/out2" merge)")
[ "$state" = COMPLETED ] || fail "the merge after the resubmission ended $state, expected COMPLETED"
cmp -s "$dir/one.json" "$dir/out2/report.json" ||
  fail "the report after resubmitting shard 3 differs from the unsharded one"

echo "slurm cluster test: $failures failures, $((SECONDS - started)) s"
((failures == 0))
