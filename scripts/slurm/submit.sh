#!/usr/bin/env bash
# Submits a dualsplit study to Slurm: the job array of study.sbatch (one task per plan
# entry), then a `dualsplit report --from DIR` job that starts when every task succeeded
# (--dependency=afterok). Prints both job ids ("array JOBID", "report JOBID").
#
#   scripts/slurm/submit.sh DIR [extra sbatch options...]
#
# Environment: DUALSPLIT (the binary, default: `dualsplit` on PATH, made absolute),
# LIMIT (array tasks running at once, default 64), ARRAY (the task ids to run, default
# every entry: 0-(N-1); a resubmission can name only the missing ones, as report --from
# prints them). Extra options go to both sbatch calls (e.g. --partition=..., --account=...);
# --mem and --time of the array can be overridden there too.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
dir="${1:?usage: submit.sh DIR [sbatch options...]}"
shift
[ -f "$dir/plan.json" ] || { echo "submit.sh: $dir/plan.json not found (run dualsplit plan --out $dir)" >&2; exit 1; }
dir="$(cd "$dir" && pwd)"
bin="${DUALSPLIT:-dualsplit}"
if [[ "$bin" != /* ]]; then
  bin="$(command -v "$bin")" || { echo "submit.sh: $bin not found; set DUALSPLIT" >&2; exit 1; }
fi
# Entries in the plan: one `"cache_key"` per entry.
n="$(grep -c '"cache_key"' "$dir/plan.json")"
[ "$n" -gt 0 ] || { echo "submit.sh: the plan has no entries" >&2; exit 1; }
array="${ARRAY:-0-$((n - 1))}"
mkdir -p "$dir/slurm"
array_id="$(sbatch --parsable "$@" \
  --array="${array}%${LIMIT:-64}" \
  --output="$dir/slurm/task_%A_%a.out" \
  --export=ALL,STUDY_DIR="$dir",DUALSPLIT="$bin" \
  "$here/study.sbatch")"
array_id="${array_id%%;*}"
report_id="$(sbatch --parsable "$@" \
  --job-name=dualsplit-report --cpus-per-task=1 --mem=1G --time=00:30:00 \
  --dependency=afterok:"$array_id" \
  --output="$dir/slurm/report_%j.out" \
  --wrap="'$bin' --quiet report --from '$dir'")"
report_id="${report_id%%;*}"
echo "array $array_id"
echo "report $report_id"
