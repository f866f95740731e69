#!/usr/bin/env bash
# Runs every libFuzzer harness of a fuzz build tree (fuzz/, -DSOLIDTEX_FUZZ=ON) for SECONDS
# each, one after the other (one core), and prints per harness the executions it ran.
# Fails when any harness finds a crash, leak, timeout or out-of-memory input; the input is
# saved as BUILD/artifacts/<harness>/crash-* (or leak-, timeout-, oom-) and can be replayed
# with `BUILD/fuzz/fuzz_<harness> FILE`.
#
# Usage: scripts/run-fuzz.sh BUILD SECONDS [HARNESS...]     (default: every BUILD/fuzz/fuzz_*)
# Seeds come from fuzz/corpus/<harness>/ (read only); what the fuzzer discovers accumulates in
# BUILD/corpus/<harness>/, so later runs start where earlier ones stopped. Logs: BUILD/logs/.
# Environment: FUZZ_TIMEOUT (s per input, 10), FUZZ_RSS_MB (2048), FUZZ_ARGS (extra
# libFuzzer flags, e.g. "-seed=1"), FUZZ_SKIP (harnesses to leave out, e.g. "image mesh").
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
if [ $# -lt 2 ]; then
  echo "usage: $0 BUILD SECONDS [HARNESS...]" >&2
  exit 2
fi
build=$(cd "$1" && pwd) || exit 2
seconds=$2
shift 2
harnesses=("$@")
if [ ${#harnesses[@]} -eq 0 ]; then
  for exe in "$build"/fuzz/fuzz_*; do
    [ -x "$exe" ] && harnesses+=("$(basename "$exe" | sed 's/^fuzz_//')")
  done
fi
if [ -n "${FUZZ_SKIP:-}" ]; then
  kept=()
  for h in "${harnesses[@]}"; do
    case " $FUZZ_SKIP " in *" $h "*) echo "fuzz_$h: skipped (FUZZ_SKIP)";; *) kept+=("$h");; esac
  done
  if [ ${#kept[@]} -eq 0 ]; then echo "run-fuzz: every harness skipped"; exit 0; fi
  harnesses=("${kept[@]}")
fi
if [ ${#harnesses[@]} -eq 0 ]; then
  echo "run-fuzz: no harnesses in $build/fuzz (configure with -DSOLIDTEX_FUZZ=ON and build the 'fuzzers' target)" >&2
  exit 2
fi
if [ "$seconds" -le 0 ] 2>/dev/null; then
  echo "run-fuzz: SECONDS=$seconds, nothing to run"
  exit 0
fi

# UBSan reports abort (the tree is built with -fno-sanitize-recover); show their stacks.
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1}
mkdir -p "$build/logs"
failed=()
total_start=$(date +%s)
for h in "${harnesses[@]}"; do
  exe="$build/fuzz/fuzz_$h"
  seeds="$root/fuzz/corpus/$h"
  work="$build/corpus/$h"
  artifacts="$build/artifacts/$h"
  log="$build/logs/$h.log"
  if [ ! -x "$exe" ]; then
    echo "fuzz_$h: no such harness ($exe)"
    failed+=("$h")
    continue
  fi
  mkdir -p "$work" "$artifacts"
  dirs=("$work")
  [ -d "$seeds" ] && dirs+=("$seeds")
  # shellcheck disable=SC2086  # FUZZ_ARGS is a list of flags
  "$exe" -max_total_time="$seconds" -timeout="${FUZZ_TIMEOUT:-10}" -rss_limit_mb="${FUZZ_RSS_MB:-2048}" \
    -print_final_stats=1 -artifact_prefix="$artifacts/" ${FUZZ_ARGS:-} "${dirs[@]}" >"$log" 2>&1
  rc=$?
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  secs=$(sed -n 's/^Done [0-9]* runs in \([0-9]*\) second.*/\1/p' "$log" | tail -1)
  rss=$(sed -n 's/^stat::peak_rss_mb: *//p' "$log" | tail -1)
  corpus=$(find "$work" -type f | wc -l)
  if [ $rc -eq 0 ]; then
    rate=""
    [ -n "$secs" ] && [ "$secs" -gt 0 ] && rate=" ($((${runs:-0} / secs))/s)"
    printf 'fuzz_%-11s %10s executions in %ss%s, corpus %s, peak %s MB: ok\n' \
      "$h" "${runs:-?}" "${secs:-$seconds}" "$rate" "$corpus" "${rss:-?}"
  else
    artifact=$(sed -n 's/.*Test unit written to \(.*\)$/\1/p' "$log" | tail -1)
    summary=$(grep -m1 -E '^SUMMARY|ERROR: libFuzzer|FUZZ_CHECK failed|runtime error' "$log")
    printf 'fuzz_%-11s %10s executions: FAILED (exit %s)\n' "$h" "${runs:-?}" "$rc"
    echo "  ${summary:-see $log}"
    [ -n "$artifact" ] && echo "  input: $artifact (replay: $exe $artifact)"
    echo "  log: $log"
    failed+=("$h")
  fi
done
echo "run-fuzz: ${#harnesses[@]} harnesses, $(( $(date +%s) - total_start ))s"
if [ ${#failed[@]} -gt 0 ]; then
  echo "run-fuzz: FAILED: ${failed[*]}" >&2
  exit 1
fi
