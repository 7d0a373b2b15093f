#!/usr/bin/env bash
# The workflow on a real one-node Slurm cluster: Debian's slurm-wlm and munge,
# with munged, slurmctld and slurmd started on localhost by this script (their
# own key, sockets, ports, state and logs in a temporary folder) and stopped
# at its end.
#  - dynsub-bids's participant level through Workflows/profiles/slurm (a copy
#    whose config sets a partition, an account and a time limit) submits
#    every segmentation with sbatch; each job completes under Slurm with the
#    profile's partition, account and time; the derivatives are those of a
#    local run (check_derivatives.py, the caudate's Dice), and the group
#    level then writes the table;
#  - a job Slurm ends (here: cancelled) counts as failed through the
#    profile's status.py, and the run exits non-zero instead of waiting.
# Exits 77 (skipped) with the reason where the daemons cannot be started,
# e.g. without root. Needs DYNSUB_BIDS, DATA, WORKFLOWS; slurm-wlm, munge.
set -u
source "$DATA/../Applications/dynsub/test/Checks.sh"
require_colin27
here=$(dirname "${BASH_SOURCE[0]}")
python=/usr/bin/python3
for program in munged slurmctld slurmd sbatch scontrol; do
  command -v "$program" >/dev/null || { echo "FAILED: $program is missing (install slurm-wlm and munge; ./run does)"; exit 1; }
done
skip() { echo "SKIPPED: $*"; exit 77; }
[ "$(id -u)" -eq 0 ] || skip "starting slurmd needs root"

cluster=$(mktemp -d /tmp/dynsub-slurm.XXXXXX)
work=$(mktemp -d)
stop_cluster() {
  for daemon in slurmd slurmctld; do
    [ -f "$cluster/$daemon.pid" ] && kill "$(cat "$cluster/$daemon.pid")" 2>/dev/null
  done
  munged --socket="$cluster/munge.socket" --stop >/dev/null 2>&1
  sleep 1
  rm -rf "$cluster" "$work"
}
trap stop_cluster EXIT

# munge: a key of this cluster's own, and its own socket.
mkdir -m 700 "$cluster/munge" "$cluster/state" "$cluster/spool"
head -c 1024 /dev/urandom >"$cluster/munge/munge.key" && chmod 400 "$cluster/munge/munge.key"
munged --force --socket="$cluster/munge.socket" --key-file="$cluster/munge/munge.key" \
  --pid-file="$cluster/munge/munged.pid" --log-file="$cluster/munged.log" --seed-file="$cluster/munge/seed" ||
  skip "munged did not start: $(tail -2 "$cluster/munged.log" 2>/dev/null)"

# Two free ports for slurmctld and slurmd.
read -r controller_port node_port < <("$python" -c '
import socket
sockets = [socket.socket() for _ in range(2)]
for s in sockets: s.bind(("127.0.0.1", 0))
print(*(s.getsockname()[1] for s in sockets))')
host=$(hostname -s)
memory=$(awk '/MemTotal/ {print int($2 / 1024 / 2)}' /proc/meminfo)
export SLURM_CONF="$cluster/slurm.conf"
cat >"$SLURM_CONF" <<EOF
ClusterName=dynsubtest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$controller_port
SlurmdPort=$node_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$cluster/munge.socket
StateSaveLocation=$cluster/state
SlurmdSpoolDir=$cluster/spool
SlurmctldPidFile=$cluster/slurmctld.pid
SlurmdPidFile=$cluster/slurmd.pid
SlurmctldLogFile=$cluster/slurmctld.log
SlurmdLogFile=$cluster/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU_Memory
MpiDefault=none
ReturnToService=2
MinJobAge=3600
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) RealMemory=$memory State=UNKNOWN
PartitionName=dynsubtest Nodes=ALL Default=NO MaxTime=60 State=UP
EOF
slurmctld || skip "slurmctld did not start: $(tail -3 "$cluster/slurmctld.log" 2>/dev/null)"
slurmd || skip "slurmd did not start: $(tail -3 "$cluster/slurmd.log" 2>/dev/null)"
for _ in $(seq 30); do
  sinfo -h -p dynsubtest -o %t 2>/dev/null | grep -q idle && break
  sleep 1
done
sinfo -h -p dynsubtest -o %t | grep -q idle ||
  skip "the node did not come up: $(sinfo 2>&1 | tail -2; tail -3 "$cluster/slurmd.log")"
echo "Slurm: $(sinfo -h -p dynsubtest -o '%P %D %c %t')"

# The profile as a site would set it: a partition (there is no default
# partition here, so a job without it would be refused), an account and a
# time limit.
cp -r "$WORKFLOWS/profiles/slurm" "$work/profile"
sed -i -e "s/slurm_partition=''/slurm_partition='dynsubtest'/" -e "s/slurm_account=''/slurm_account='neuro'/" \
  -e "s/segment:runtime=30/segment:runtime=20/" "$work/profile/config.yaml"
cd "$work"
bids="$work/bids"
out="$bids/derivatives/dynsub"
"$python" "$here/make_cohort.py" "$templates" "$DATA" "$bids"

"$DYNSUB_BIDS" "$bids" "$out" participant --profile "$work/profile" >"$work/run.log" 2>&1
check "participant level through Slurm: exit 0" test $? -eq 0 || tail -40 "$work/run.log"
grep -o "external jobid '[0-9]*'" "$work/run.log" | grep -o "[0-9]*" >"$work/ids"
check "3 jobs submitted with sbatch" test "$(wc -l <"$work/ids")" -eq 3
check "every job completed under Slurm, with the profile's partition, account and time" "$python" - "$work/ids" <<'PY'
import subprocess, sys
jobs = open(sys.argv[1]).read().split()
assert len(jobs) == 3, jobs
for job in jobs:
    fields = dict(f.split("=", 1) for f in subprocess.run(["scontrol", "show", "job", "-o", job], capture_output=True,
                                                          text=True, check=True).stdout.split() if "=" in f)
    print(job, fields["JobName"], fields["JobState"], fields["Partition"], fields["Account"], fields["TimeLimit"])
    assert (fields["JobState"], fields["ExitCode"]) == ("COMPLETED", "0:0"), fields
    assert (fields["Partition"], fields["Account"], fields["TimeLimit"]) == ("dynsubtest", "neuro", "00:20:00"), fields
    assert fields["JobName"] == "dynsub-segment", fields
PY
check "Slurm's job logs in the work folder" test "$(ls "$out/work/slurm-logs" | wc -l)" -eq 3
"$DYNSUB_BIDS" "$bids" "$out" group >"$work/group.log" 2>&1
check "group level: exit 0" test $? -eq 0 || tail -20 "$work/group.log"
check "derivatives as on one machine" "$python" "$here/check_derivatives.py" "$bids" "$out" 3
check "the caudate's Dice as on one machine" "$python" - "$out/segmentations.tsv" <<'PY'
import csv, sys
rows = {(r["participant_id"], r["structure"]): r for r in csv.DictReader(open(sys.argv[1]), delimiter="\t")}
assert all(r["status"] == "ok" for r in rows.values()), rows
assert float(rows[("sub-01", "caudateL")]["dice"]) >= 0.84, rows  # the workflow test's bar (0.853)
PY

# A job that Slurm ends: with the partition down, the segmentation's rerun
# waits in the queue and is cancelled there; status.py reports it failed and
# the run ends, non-zero, instead of waiting.
rm "$out"/sub-02/anat/*_dseg.nii.gz
scontrol update PartitionName=dynsubtest State=DOWN
"$DYNSUB_BIDS" "$bids" "$out" participant --participant-label 02 --profile "$work/profile" >"$work/cancel.log" 2>&1 &
run=$!
job=
for _ in $(seq 120); do
  job=$(squeue -h -p dynsubtest -o %i | head -1)
  [ -n "$job" ] && break
  sleep 0.5
done
[ -n "$job" ] && scancel "$job"
wait $run
status=$?
scontrol update PartitionName=dynsubtest State=UP
check "a job Slurm cancelled: the run exits non-zero" test $status -ne 0 -a -n "$job"
check "a job Slurm cancelled: Snakemake saw it fail" grep -q "Error in rule segment" "$work/cancel.log" ||
  tail -20 "$work/cancel.log"

echo "$failures failure(s)"
exit $((failures > 0))
