#!/usr/bin/env bash
# Set up synthua-usd on a fresh Debian 12 machine (or any Linux with Python >= 3.11):
#   1. system libraries, when apt is available and we may use it: libllvm19 (Mitsuba's llvm_ad_rgb
#      variant needs LLVM >= 19; with only 14/15 it aborts) and python3-venv;
#   2. chromium, when apt may be used (the HTML report tests; they skip without it);
#   3. a virtual environment in .venv with the package and its test, torch and docs extras, pinned by constraints.txt.
# Safe to run again: it only does what is missing.
set -euo pipefail
cd "$(dirname "$0")/.."

VENV=${VENV:-.venv}
PYTHON=${PYTHON:-}

as_root() {
  if [ "$(id -u)" -eq 0 ]; then "$@"; elif command -v sudo >/dev/null 2>&1; then sudo -n "$@"; else return 1; fi
}

apt_install() {
  command -v apt-get >/dev/null 2>&1 || return 1
  if [ ! -f "$VENV/.apt-updated" ] && [ -z "${SYNTHUA_APT_UPDATED:-}" ]; then
    as_root apt-get update -qq || return 1
    export SYNTHUA_APT_UPDATED=1
  fi
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "$@" >/dev/null || return 1
}

# 1. libLLVM 19 for Mitsuba's LLVM variant (optional: without it synthua falls back to scalar_rgb).
# Any match is enough (ls with several patterns fails when one of them matches nothing, so look once).
if ! compgen -G "/usr/lib/*/libLLVM*.so.19*" >/dev/null && ! compgen -G "/usr/lib/libLLVM*.so.19*" >/dev/null \
   && ! compgen -G "/usr/lib/llvm-19/lib/libLLVM*.so*" >/dev/null; then
  echo "setup: installing libllvm19 for Mitsuba's llvm_ad_rgb variant"
  apt_install libllvm19 || echo "setup: warning: could not install libllvm19; rendering will use the slower scalar_rgb variant" >&2
fi

# Chromium (optional): the tests open the HTML report of `synthua stats` in a real headless browser; without it
# those tests skip with a reason.
if ! command -v chromium >/dev/null 2>&1 && ! command -v chromium-browser >/dev/null 2>&1; then
  echo "setup: installing chromium (headless browser for the report tests)"
  apt_install chromium || echo "setup: warning: could not install chromium; the HTML report tests will be skipped" >&2
fi

# 2. Python >= 3.11.
if [ -z "$PYTHON" ]; then
  for candidate in python3.11 python3.12 python3.13 python3; do
    if command -v "$candidate" >/dev/null 2>&1 && "$candidate" -c 'import sys; sys.exit(sys.version_info < (3, 11))'; then
      PYTHON=$candidate; break
    fi
  done
fi
if [ -z "$PYTHON" ]; then
  echo "setup: error: no Python >= 3.11 found; install python3 (Debian 12 ships 3.11) and run again" >&2
  exit 2
fi
if ! "$PYTHON" -c 'import ensurepip, venv' >/dev/null 2>&1; then
  echo "setup: installing python3-venv"
  apt_install python3-venv || { echo "setup: error: $PYTHON cannot create virtual environments (install python3-venv)" >&2; exit 2; }
fi

# 3. The virtual environment and the package.
if [ ! -x "$VENV/bin/python" ]; then
  echo "setup: creating $VENV with $PYTHON"
  "$PYTHON" -m venv "$VENV"
fi
stamp="$VENV/.installed"
if [ ! -f "$stamp" ] || [ pyproject.toml -nt "$stamp" ] || [ constraints.txt -nt "$stamp" ]; then
  echo "setup: installing synthua-usd and its dependencies into $VENV"
  "$VENV/bin/python" -m pip install -q --upgrade pip
  # The torch extra: torch==2.13.0 from PyPI (constraints.txt) is the CPU build on Linux x86-64.
  "$VENV/bin/python" -m pip install -q -c constraints.txt -e '.[test,torch,docs]'
  # panopticapi (the COCO panoptic reader of the tests): its PyPI wheel, panopticapi-lite, is the
  # cocodataset/panopticapi code but declares numpy<2, which the rest of the stack cannot meet; its code runs
  # on NumPy 2, and what it needs (numpy, pillow) comes with the test extra.
  "$VENV/bin/python" -m pip install -q -c constraints.txt --no-deps panopticapi-lite
  # TrackEval (the MOTChallenge reader of the tests' tracking sequences) declares opencv-python, which only its J&F
  # metric imports (and which needs libGL): its other needs come with the package and the test extra.
  "$VENV/bin/python" -m pip install -q -c constraints.txt --no-deps trackeval tabulate
  touch "$stamp"
fi
"$VENV/bin/synthua" --version
