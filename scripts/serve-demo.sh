#!/usr/bin/env bash
# `make serve`: builds a demo from an exemplar solidtex generates itself (no download).
set -euo pipefail
build=${1:-build}
demo=${SOLIDTEX_DEMO_DIR:-$build/demo}
mkdir -p "$demo"
"$build/bin/solidtex" exemplar wood --size 96,96 -o "$demo/wood.png"
"$build/bin/solidtex" analyze "$demo/wood.png" -o "$demo/wood.stx" --json
echo "demo table: $demo/wood.stx"
