#!/usr/bin/env bash
# Runs the Python end-to-end tests (tests/python) against BUILD/bin/solidtex.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
"$root/scripts/setup-python.sh" "$build"
export SOLIDTEX_BIN="$build/bin/solidtex"
cd "$root"
exec "$build/venv/bin/python" -m pytest -q -p no:cacheprovider tests/python
