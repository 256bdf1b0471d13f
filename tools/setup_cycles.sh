#!/usr/bin/env bash
# Set up Blender Cycles for the side-by-side benchmark (tools/bench_targets.py): PyPI's bpy (Blender as a
# Python module, about 374 MB) in a virtual environment of its own, $CYCLES_VENV (default .venv-cycles).
# Never in synthua's .venv: bpy bundles its own USD (pxr) and OpenImageIO, which clash with usd-core and
# OpenImageIO in one process; synthua runs it in a subprocess (synthua_usd/backends/cycles/runner.py).
# bpy 5.0.1 has wheels for CPython 3.11 only. Safe to run again: it only does what is missing.
# Exit 0 when Cycles is ready, 1 (with one line saying why) when it cannot be installed here.
set -euo pipefail
cd "$(dirname "$0")/.."

CYCLES_VENV=${CYCLES_VENV:-.venv-cycles}
BPY_VERSION=${BPY_VERSION:-5.0.1}
PYTHON=${CYCLES_BASE_PYTHON:-python3.11}

if [ -x "$CYCLES_VENV/bin/python" ] && "$CYCLES_VENV/bin/python" -c 'import bpy' >/dev/null 2>&1; then
  exit 0
fi
# shellcheck source=tools/side_venv.sh
source tools/side_venv.sh
side_venv setup_cycles "$CYCLES_VENV" "$PYTHON" "Blender (bpy $BPY_VERSION)" CYCLES_BASE_PYTHON || exit 1
echo "setup_cycles: installing bpy==$BPY_VERSION (about 374 MB) into $CYCLES_VENV"
if ! "$CYCLES_VENV/bin/python" -m pip install -q "bpy==$BPY_VERSION" numpy; then
  echo "setup_cycles: Blender (bpy $BPY_VERSION) not installed: pip could not install it into $CYCLES_VENV" >&2
  exit 1
fi
"$CYCLES_VENV/bin/python" -c 'import bpy; print("setup_cycles: Blender", bpy.app.version_string, "ready")'
