#!/usr/bin/env bash
# Runs a psa-esp grid on SLURM: a job array of N shards, then the report as
# a job that starts once every shard has succeeded.
#
#   scripts/slurm/submit.sh [--wait] N [replicate|sweep] --out DIR [options]
#
# e.g. scripts/slurm/submit.sh 16 --preset paper --out paper-grid
#
# Options of sbatch go in its environment variables (SBATCH_PARTITION,
# SBATCH_ACCOUNT, SBATCH_TIMELIMIT, ...); --cpus-per-task via
# SBATCH_CPUS_PER_TASK (each shard runs one thread per CPU). The job logs
# (psa-esp-JOB_TASK.out, psa-esp-report-JOB.out) go to the current folder.
# --wait: return when the report job ends, with its exit status.
# The binary is $PSA_ESP, else `psa-esp` on the PATH.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
usage() {
    echo "usage: $0 [--wait] N [replicate|sweep] --out DIR [options]" >&2
    exit 2
}
wait=()
if [ "${1:-}" = --wait ]; then
    wait=(--wait)
    shift
fi
[ $# -ge 1 ] || usage
shards=$1
shift
[[ $shards =~ ^[1-9][0-9]*$ ]] || { echo "N must be a whole number of shards from 1, got '$shards'" >&2; exit 2; }
out=
prev=
for arg in "$@"; do
    case $arg in
    --out=*) out=${arg#--out=} ;;
    esac
    if [ "$prev" = --out ]; then
        out=$arg
    fi
    prev=$arg
done
[ -n "$out" ] || { echo "give the grid folder with --out DIR" >&2; usage; }

array=$(sbatch --parsable --array="0-$((shards - 1))" "$here/replicate.sbatch" "$@")
array=${array%%;*}
echo "submitted job array $array: $shards shards of the grid in $out"
status=0
report=$(sbatch --parsable "${wait[@]}" --dependency="afterok:$array" --kill-on-invalid-dep=yes \
    "$here/report.sbatch" "$out") || status=$?
if [ -z "$report" ]; then
    echo "could not submit the report job; the array $array runs on (submit scripts/slurm/report.sbatch $out by hand)" >&2
    exit "$status"
fi
echo "submitted report job ${report%%;*} (after the array succeeds): $out/report.md, $out/runs.csv"
if [ ${#wait[@]} -gt 0 ]; then
    # A report job cancelled because a shard failed ends sbatch --wait with
    # status 0: its state tells.
    state=$(scontrol show job "${report%%;*}" -o 2>/dev/null | grep -o 'JobState=[A-Z_]*' || true)
    echo "report job ended: ${state:-JobState=unknown}, exit status $status"
    if [ "$state" != JobState=COMPLETED ] && [ "$status" -eq 0 ]; then
        echo "the grid did not complete: see the shards' logs (psa-esp-${array}_*.out)" >&2
        status=1
    fi
fi
exit "$status"
