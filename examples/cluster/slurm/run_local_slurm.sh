#!/bin/bash
# One command: start a real single-node Slurm (Debian's slurm-wlm, with munge) in a temporary
# folder, convert a dataset with the array in convert.sbatch (3 tasks) plus merge.sbatch, convert
# it again with one process, check that the merged summary equals the one-process run (but for
# times) and that every scene file is the same byte for byte, and print the timings.
#
#   bash examples/cluster/slurm/run_local_slurm.sh [ROOT] [TASKS] [-- more batch options]
#
# ROOT defaults to ../shared/datasets/scenes, TASKS to 3. Needs root (the daemons run as root in
# a throw-away configuration), `apt-get install slurm-wlm munge` (done here if missing) and a
# release build (made here if missing). Slow (the real scenes take minutes): not part of CI.
set -euo pipefail
repo=$(cd "$(dirname "$0")/../../.." && pwd)
here="$repo/examples/cluster/slurm"
ROOT=$(realpath "${1:-$repo/../shared/datasets/scenes}")
TASKS=${2:-3}
shift $(( $# > 2 ? 2 : $# ))
[ "${1:-}" = "--" ] && shift
EXTRA=("$@")

if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurm-wlm munge >/dev/null
fi
if [ ! -x "$repo/target/release/interact3d" ]; then
  (cd "$repo" && cargo build --release --quiet)
fi
export PATH="$repo/target/release:$PATH"

T=$(mktemp -d /tmp/interact3d-slurm.XXXXXX)
chmod 700 "$T"
mkdir -p "$T/state" "$T/spool" "$T/munge" "$T/jobs"
chmod 700 "$T/munge"
cleanup() {
  set +e
  [ -n "${SLURM_CONF:-}" ] && scancel --quiet --user=root 2>/dev/null
  for p in slurmd slurmctld munged; do
    [ -f "$T/$p.pid" ] && kill "$(cat "$T/$p.pid")" 2>/dev/null
  done
  sleep 1
  echo "logs and outputs kept in $T"
}
trap cleanup EXIT

# munge: a fresh key and socket of our own, so no system daemon is touched.
dd if=/dev/urandom of="$T/munge/munge.key" bs=1024 count=1 status=none
chmod 400 "$T/munge/munge.key"
munged --force --key-file="$T/munge/munge.key" --socket="$T/munge/munge.socket" \
  --pid-file="$T/munged.pid" --log-file="$T/munged.log" --seed-file="$T/munge/munged.seed"

node=$(hostname -s)
cpus=$(nproc)
port=$((20000 + RANDOM % 20000))
cat > "$T/slurm.conf" <<CONF
ClusterName=interact3d
SlurmctldHost=$node
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$T/munge/munge.socket
CredType=cred/munge
SlurmctldPort=$port
SlurmdPort=$((port + 1))
StateSaveLocation=$T/state
SlurmdSpoolDir=$T/spool
SlurmctldPidFile=$T/slurmctld.pid
SlurmdPidFile=$T/slurmd.pid
SlurmctldLogFile=$T/slurmctld.log
SlurmdLogFile=$T/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
NodeName=$node NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=local Nodes=$node Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$T/slurm.conf"
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"
for _ in $(seq 60); do
  sinfo -h -o %t 2>/dev/null | grep -q idle && break
  sleep 1
done
sinfo -h -o %t | grep -q idle || { echo "slurm did not come up; see $T/*.log" >&2; exit 1; }
echo "slurm $(sinfo -V | cut -d' ' -f2) up on $node ($cpus CPUs), state in $T"

now() { date +%s.%N; }
export LOAD_BEFORE=$(cut -d' ' -f1 /proc/loadavg)
# The array: TASKS tasks of one CPU each into one shared OUT, then the merge.
cd "$T/jobs"
t0=$(now)
read -r _ array _ merge < <("$here/submit.sh" "$ROOT" "$T/shared" "$TASKS" "${EXTRA[@]}")
while squeue -h -j "$array,$merge" 2>/dev/null | grep -q .; do sleep 0.5; done
t1=$(now)
echo "--- slurm logs"
tail -n 3 "$T"/jobs/interact3d-*.log
merged_code=$(grep -h "^merged" "$T"/jobs/interact3d-merge-*.log >/dev/null && echo ok || echo missing)
[ "$merged_code" = ok ] || { echo "the merge job did not run; see $T/jobs" >&2; exit 1; }

# The reference: one process with every CPU.
t2=$(now)
set +e
interact3d batch "$ROOT" -o "$T/single" --jobs "$cpus" --progress quiet "${EXTRA[@]}"
single_code=$?
set -e
t3=$(now)

python3 - "$T/single" "$T/shared" "$t0" "$t1" "$t2" "$t3" "$TASKS" "$cpus" <<'PY'
import csv, io, json, os, sys
single, shared = sys.argv[1], sys.argv[2]
t0, t1, t2, t3 = map(float, sys.argv[3:7])
tasks, cpus = int(sys.argv[7]), int(sys.argv[8])

def stable(s):
    s = dict(s); s.pop("run")
    s["scenes"] = [{k: v for k, v in r.items() if k not in ("time_s", "reused")} for r in s["scenes"]]
    return s

def rows(d):
    r = list(csv.reader(io.StringIO(open(os.path.join(d, "summary.csv")).read())))
    drop = [r[0].index("time_s"), r[0].index("reused")]
    return [[f for i, f in enumerate(x) if i not in drop] for x in r]

def files(d):
    out = {}
    for dp, dn, fn in os.walk(d):
        dn[:] = [x for x in dn if not x.startswith(".")]
        for f in fn:
            rel = os.path.relpath(os.path.join(dp, f), d)
            if f.startswith(".") or (dp == d and f.startswith("summary")) or rel == "index.html":
                continue
            out[rel] = open(os.path.join(dp, f), "rb").read()
    return out

def page(d):
    html = open(os.path.join(d, "index.html")).read()
    i = html.index("const DATA = ") + len("const DATA = ")
    j = html.index(";\nconst COLS", i)
    return html[:i] + html[j:], stable(json.loads(html[i:j]))

a = json.load(open(os.path.join(single, "summary.json")))
b = json.load(open(os.path.join(shared, "summary.json")))
ok = stable(a) == stable(b)
ok_csv = rows(single) == rows(shared)
ok_html = page(single) == page(shared)
fa, fb = files(single), files(shared)
ok_files = fa == fb
shards = sorted(f for f in os.listdir(shared) if f.startswith("summary.shard-"))
el = [json.load(open(os.path.join(shared, f)))["run"]["elapsed_s"] for f in shards]
n = a["counts"]["scenes"]
print(f"--- {n} scenes: {a['counts']['pass']} pass, {a['counts']['fail']} fail, {a['counts']['error']} error")
print(f"merged summary equals the one-process summary (times aside): {ok}")
print(f"summary.csv equal (times aside): {ok_csv}")
print(f"index.html equal (times aside): {ok_html}")
print(f"scene files byte for byte: {ok_files} ({len(fa)} files)")
print()
print("| run | wall (s) | scenes/min |")
print("|---|---:|---:|")
print(f"| one process, --jobs {cpus} | {t3 - t2:.1f} | {n * 60 / (t3 - t2):.1f} |")
print(f"| Slurm array, {tasks} tasks x 1 CPU, submit to merged | {t1 - t0:.1f} | {n * 60 / (t1 - t0):.1f} |")
for f, e in zip(shards, el):
    print(f"| {f} (inside the task) | {e:.1f} | |")
print(f"| sum of shard times / {cpus} CPUs (ideal packing) | {sum(el) / cpus:.1f} | {n * 60 * cpus / sum(el):.1f} |")
print(f"load average (1 min) before / after: {os.environ.get('LOAD_BEFORE')} / {os.getloadavg()[0]:.1f}")
sys.exit(0 if ok and ok_csv and ok_html and ok_files else 1)
PY
