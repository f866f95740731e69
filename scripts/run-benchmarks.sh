#!/usr/bin/env bash
# Runs every benchmark in bench/ and prints one JSON document:
#   {"analysis": [...], "slice": {...}, "coherence": {...}, "field": {...}, "surface": {...},
#    "service": {...}, "arrays": {...}, "quality": {...}, "reference_solids": {...}, "rss": {...}}. Takes about two hours on 2 cores (QUALITY_SIZE=128 for a quicker
#    quality run; RSS_QUICK=1 for smaller memory probes).
# Uses ../shared/data/exemplars/wood_grain.png when present, else a procedural wood exemplar.
set -euo pipefail
build=${1:-build}
quick=${2:-}
shared=$(cd "$(dirname "$0")/../.." && pwd)/shared
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo '{"analysis": ['
first=1
for size in 96 128 256; do
  [ $first -eq 1 ] || echo ','
  first=0
  "$build/bin/bench_analysis" "$size"
done
echo '],'
exemplar="$shared/data/exemplars/wood_grain.png"
if [ ! -f "$exemplar" ]; then
  "$build/bin/solidtex" exemplar wood --size 96,96 -o "$tmp/wood.png" 2>/dev/null
  exemplar="$tmp/wood.png"
fi
"$build/bin/solidtex" analyze "$exemplar" --grain x -o "$tmp/wood.stx" >/dev/null
echo '"slice":'
"$build/bin/bench_slice" "$tmp/wood.stx" $quick
echo ', "coherence":'
"$build/bin/bench_coherence" "$tmp/wood.stx"
echo ', "field":'
"$build/bin/bench_field"
echo ', "surface":'
if [ -d "$shared/data/meshes" ]; then
  "$build/bin/bench_surface" "$tmp/wood.stx" "$shared/data/meshes" --resolutions 512,1024 --synthesize-up-to 4000000
else
  echo '{"skipped": "no ../shared/data/meshes"}'
fi
echo ', "service":'
"$(cd "$(dirname "$0")/.." && pwd)/scripts/setup-python.sh" "$(cd "$build" && pwd)"
"$build/venv/bin/python" "$(dirname "$0")/../bench/bench_service.py" "$build"
echo ', "arrays":'
"$build/venv/bin/python" "$(dirname "$0")/../bench/bench_arrays.py" "$build"
echo ', "quality":'
"$build/venv/bin/python" "$(dirname "$0")/../bench/bench_quality.py" "$build" --size "${QUALITY_SIZE:-256}"
echo ', "reference_solids":'
"$build/venv/bin/python" "$(dirname "$0")/../bench/bench_reference_solids.py" --size "${QUALITY_SIZE:-256}" 2>/dev/null
echo ', "rss":'
"$build/venv/bin/python" "$(dirname "$0")/../bench/bench_rss.py" "$build" --cache-mb "${RSS_CACHE_MB:-256}" \
  ${RSS_QUICK:+--quick} 2>/dev/null
echo '}'
