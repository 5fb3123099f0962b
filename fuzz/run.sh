#!/usr/bin/env bash
# Runs every fuzz target (or those named) for FUZZ_SECONDS each, one after the other, with the
# limits the regression corpus is held to, and prints one summary line per target:
# executions, executions/s, coverage (libFuzzer's cov: edges and ft: features) and corpus size.
# New inputs go to BUILD/fuzz-corpus/<target>/ (the seeds in fuzz/corpus/ stay as they are);
# a crash, hang or over-limit allocation leaves its input in BUILD/fuzz-artifacts/<target>/ and
# makes the script fail: fix the cause, then add the input to fuzz/regressions/<target>/.
# Each run is appended to BUILD/fuzz-artifacts/ledger.tsv, and the summary adds every target's
# executions over all runs on its (kept) corpus, since fuzzing is cumulative.
#
#   fuzz/run.sh BUILD SECONDS [TARGET...]
set -uo pipefail
cd "$(dirname "$0")/.."
build=${1:?build folder}
seconds=${2:?seconds per target}
shift 2
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  targets=(rawlog carmen gfs victoria_park pose_graph tum relations ini laser_model vocabulary image_list image data_source victoria_park_zip map_file)
fi
# Inputs are written to a file per execution: keep that off the disk when we can.
if [ -z "${TMPDIR:-}" ] && [ -d /dev/shm ] && [ -w /dev/shm ]; then export TMPDIR=/dev/shm; fi
ledger="$build/fuzz-artifacts/ledger.tsv"
mkdir -p "$build/fuzz-artifacts"
[ -f "$ledger" ] || printf 'date\ttarget\tseconds\texecs\tcov\tft\tcorpus\tstatus\n' >"$ledger"
status=0
summary=()
for t in "${targets[@]}"; do
  exe="$build/fuzz/fuzz_$t"
  [ -x "$exe" ] || { echo "fuzz: $exe not built" >&2; exit 2; }
  mkdir -p "$build/fuzz-corpus/$t" "$build/fuzz-artifacts/$t"
  log="$build/fuzz-artifacts/$t.log"
  stamp="$build/fuzz-artifacts/$t.started"
  touch "$stamp"
  echo "== fuzz_$t for ${seconds}s (log: $log)"
  # Seeds second: libFuzzer writes new inputs to the first folder only.
  "$exe" "$build/fuzz-corpus/$t" fuzz/corpus/$t -dict=fuzz/dict/$t.dict \
    -max_total_time="$seconds" -timeout=20 -rss_limit_mb=1024 -malloc_limit_mb=1024 \
    -print_final_stats=1 -artifact_prefix="$build/fuzz-artifacts/$t/" >"$log" 2>&1
  rc=$?
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  rss=$(sed -n 's/^stat::peak_rss_mb: *//p' "$log" | tail -1)
  last=$(grep -E '^#[0-9]+' "$log" | tail -1)
  cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$last")
  ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$last")
  corp=$(sed -n 's/.* corp: \([0-9]*\).*/\1/p' <<<"$last")
  line=$(printf '%-14s execs %-10s exec/s %-6s cov %-6s ft %-6s corpus %-5s peak_rss_mb %-5s' \
    "$t" "${execs:-?}" "${rate:-?}" "${cov:-?}" "${ft:-?}" "${corp:-?}" "${rss:-?}")
  if [ $rc -ne 0 ]; then
    line="$line FAILED (exit $rc): $(find "$build/fuzz-artifacts/$t" -type f -newer "$stamp" | head -3 | tr '\n' ' ')"
    grep -m3 -E 'ERROR|fuzz target:|runtime error' "$log" >&2
    status=1
  fi
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$(date -u +%FT%TZ)" "$t" "$seconds" "${execs:-0}" "${cov:-?}" \
    "${ft:-?}" "${corp:-?}" "$([ $rc -eq 0 ] && echo ok || echo "failed:$rc")" >>"$ledger"
  total=$(awk -F'\t' -v t="$t" '$2 == t { n += $4 } END { print n + 0 }' "$ledger")
  line="$line total_execs $total"
  echo "$line"
  summary+=("$line")
done
echo
echo "== fuzz summary (${seconds}s per target)"
printf '%s\n' "${summary[@]}"
exit $status
