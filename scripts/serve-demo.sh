#!/usr/bin/env bash
# `make serve`: starts `solidtex serve` on PORT with a ready demo volume made from an exemplar
# solidtex generates itself (no download), prints URLs to try, and keeps serving until Ctrl-C.
# The demo data live in BUILD/demo-data and survive restarts (the demo is created once).
set -euo pipefail
build=${1:-build}
port=${2:-8080}
host=127.0.0.1
data=${SOLIDTEX_DEMO_DATA:-$build/demo-data}
demo=$build/demo
url="http://$host:$port"
mkdir -p "$demo" "$data"

"$build/bin/solidtex" serve --host "$host" --port "$port" --data "$data" &
server=$!
trap 'kill -TERM $server 2>/dev/null || true; wait $server 2>/dev/null || true' EXIT INT TERM
for _ in $(seq 1 100); do
  curl -sf "$url/healthz" >/dev/null && break
  kill -0 $server 2>/dev/null || { echo "solidtex serve did not start" >&2; exit 1; }
  sleep 0.1
done

json() { python3 -c "import json,sys; d=json.load(sys.stdin); print($1)"; }
volume=$(curl -sf "$url/v1/volumes" | json "next((v['id'] for v in d['volumes'] if v['name']=='demo-wood'), '')")
if [ -z "$volume" ]; then
  echo "creating the demo: a procedural wood exemplar, analysed, textured along a rotated grain"
  "$build/bin/solidtex" exemplar wood --size 96,96 -o "$demo/wood.png" >/dev/null
  job=$(curl -sf -X POST --data-binary @"$demo/wood.png" -H 'Content-Type: image/png' \
        "$url/v1/exemplars?name=demo-wood&grain=x" | json "d['job']['id']")
  for _ in $(seq 1 600); do
    state=$(curl -sf "$url/v1/jobs/$job" | json "d['state']")
    [ "$state" = succeeded ] && break
    [ "$state" = failed ] && { echo "demo analysis failed" >&2; exit 1; }
    sleep 0.5
  done
  exemplar=$(curl -sf "$url/v1/jobs/$job" | json "d['exemplar_id']")
  volume=$(curl -sf -X POST -H 'Content-Type: application/json' \
           -d "{\"name\": \"demo-wood\", \"exemplar\": \"$exemplar\", \"field\": {\"spec\": \"axis:0,0,1,30\"}, \"seed\": 1}" \
           "$url/v1/volumes" | json "d['id']")
fi
# Warm the cache with the browser app's first view (its 256² z cut at 0 and the 32² preview of
# pyramid dataset 3 it shows first), so that it and the cut suggested below answer at once (a
# new cut costs seconds to tens of seconds on 2 cores; repeats and overlapping cuts reuse the
# cached voxels).
cut="$url/v1/volumes/$volume/slice?axis=z&at=0&size=96,96"
for warm in "size=32,32&scale=3" "size=256,256"; do
  curl -sf -o /dev/null "$url/v1/volumes/$volume/slice?axis=z&at=0&$warm&timeout=300" ||
    echo "warning: the warm-up cut ($warm) failed" >&2
done

cat <<MSG

solidtex is serving on $url (data in $data); demo volume: $volume
open the browser app: $url/#volume=$volume
or try:
  curl -o cut.png  "$cut"                      (cached: instant)
  curl -o side.png "$url/v1/volumes/$volume/slice?axis=y&at=5&size=96,48"
  curl -o box.vdb  "$url/v1/volumes/$volume/region?min=0,0,0&size=24,24,24"
  curl "$url/v1/volumes/$volume/stats"
  curl "$url/metrics"
  API contract: $url/v1/openapi.json
Ctrl-C stops the server.
MSG
wait $server
