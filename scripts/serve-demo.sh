#!/usr/bin/env bash
# `make serve`: builds a demo from exemplars solidtex generates itself (no download): a
# spots table and a cut through it. (The HTTP service arrives with issue #5; until then this is
# the demo.)
set -euo pipefail
build=${1:-build}
demo=${SOLIDTEX_DEMO_DIR:-$build/demo}
mkdir -p "$demo"
"$build/bin/solidtex" exemplar spots --size 64,64 -o "$demo/spots.png"
"$build/bin/solidtex" analyze "$demo/spots.png" -o "$demo/spots.stx"
"$build/bin/solidtex" slice "$demo/spots.stx" --axis z --at 0 --size 96,96 -o "$demo/cut_z.png" --stats "$demo/cut_z.json"
echo
echo "demo ready in $demo:"
echo "  table    $demo/spots.stx"
echo "  a z-cut  $demo/cut_z.png (stats: $demo/cut_z.json)"
echo "try:  $build/bin/solidtex slice $demo/spots.stx --plane 0,0,0,0.6,0.8,0,-0.48,0.36,0.8 --size 96,96 -o /tmp/oblique.png"
