#!/usr/bin/env bash
# Creates BUILD/venv (once) with the Python client installed in editable mode. The venv sees
# the Debian packages numpy, Pillow, requests and pytest (scripts/deb-packages.txt), so nothing
# is downloaded here; `pip install client/` elsewhere fetches them from PyPI instead.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
venv="$build/venv"
if [ ! -x "$venv/bin/python" ]; then
  # Debian's interpreter: its site-packages hold the Debian python3-* packages.
  /usr/bin/python3 -m venv --system-site-packages "$venv"
fi
if ! "$venv/bin/python" -c "import solidtex_client" 2>/dev/null; then
  "$venv/bin/python" -m pip install --quiet --no-deps --no-build-isolation --no-index -e "$root/client"
fi
