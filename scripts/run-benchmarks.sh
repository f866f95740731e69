#!/usr/bin/env bash
# Runs every benchmark in bench/ and prints one JSON document: {"analysis": [...], ...}.
set -euo pipefail
build=${1:-build}
shared=$(cd "$(dirname "$0")/../.." && pwd)/shared
echo '{"analysis": ['
first=1
for size in 96 128 256; do
  [ $first -eq 1 ] || echo ','
  first=0
  "$build/bin/bench_analysis" "$size"
done
echo ']}'
