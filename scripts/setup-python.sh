#!/usr/bin/env bash
# Creates BUILD/venv (once) with the Python client installed in editable mode. The venv sees
# the Debian packages numpy, Pillow, requests and pytest (scripts/deb-packages.txt); on top it
# gets the pinned PyPI packages of tests/python/requirements.txt (schemathesis for the contract
# test; its pytest shadows Debian's), installed once and again whenever that file changes.
# `pip install client/` elsewhere fetches the client's own dependencies from PyPI.
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
requirements="$root/tests/python/requirements.txt"
stamp="$venv/.requirements.sha256"
want=$(sha256sum "$requirements" | cut -d' ' -f1)
if [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
  "$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r "$requirements"
  echo "$want" > "$stamp"
fi
