# Sourced by tools/setup_cycles.sh and tools/setup_train.sh: a heavy tool's virtual environment of its own, made
# with CPython 3.11 (the Python whose wheels those tools take).
#   side_venv TAG VENV PYTHON WHAT VARIABLE
# creates VENV with PYTHON when it is missing; returns 1 with one line (TAG: WHAT not installed: ...; set VARIABLE)
# when PYTHON is not CPython 3.11.
side_venv() {
  local tag=$1 venv=$2 python=$3 what=$4 variable=$5
  if ! command -v "$python" >/dev/null 2>&1 \
     || ! "$python" -c 'import sys; sys.exit(sys.version_info[:2] != (3, 11))'; then
    echo "$tag: $what not installed: it needs CPython 3.11 ($python not found or another version; set $variable)" >&2
    return 1
  fi
  if [ ! -x "$venv/bin/python" ]; then
    echo "$tag: creating $venv with $python"
    "$python" -m venv "$venv"
  fi
}
