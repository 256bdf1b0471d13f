#!/usr/bin/env bash
# Set up the detector of `synthua train` and `synthua evaluate-real`: PyPI's Ultralytics YOLO (AGPL-3.0) with
# torch and torchvision in a virtual environment of its own, $TRAIN_VENV (default .venv-train).
# Never in synthua's .venv: torchvision's PyPI wheels fail to import beside the CPU torch 2.13.0 that .venv pins
# ('operator torchvision::nms does not exist'), and the pair that imports together on x86-64 Linux,
# torch 2.14.1 + torchvision 0.29.1, is a CUDA build of about 5.5 GB (it runs on the CPU too, and on a GPU when
# one is present). synthua runs Ultralytics in a subprocess of this interpreter
# (synthua_usd/pipeline/detector/runner.py). Safe to run again: it only does what is missing.
# Exit 0 when the detector is ready, 1 (with one line saying why) when it cannot be installed here.
set -euo pipefail
cd "$(dirname "$0")/.."

TRAIN_VENV=${TRAIN_VENV:-.venv-train}
PYTHON=${TRAIN_BASE_PYTHON:-python3.11}
# Every run records the versions it ran on (train.json, metrics.json).
REQUIREMENTS="torch==2.14.1 torchvision==0.29.1 ultralytics==8.4.190"
stamp="$TRAIN_VENV/.installed"

if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$REQUIREMENTS" ] && [ -x "$TRAIN_VENV/bin/python" ]; then
  exit 0
fi
# CPython 3.11: its pip takes torch and torchvision from this machine's disk.
# shellcheck source=tools/side_venv.sh
source tools/side_venv.sh
side_venv setup_train "$TRAIN_VENV" "$PYTHON" "the detector (Ultralytics)" TRAIN_BASE_PYTHON || exit 1
echo "setup_train: installing $REQUIREMENTS (about 5.9 GB with what they need) into $TRAIN_VENV"
# opencv-python (Ultralytics' requirement) links the desktop's GUI libraries (libGL, libxcb), which a server may
# lack: its headless build, the same OpenCV without them, takes its place (both own the cv2 package, so the
# headless one is reinstalled after the other is removed).
if ! "$TRAIN_VENV/bin/python" -m pip install -q $REQUIREMENTS; then
  echo "setup_train: the detector (Ultralytics) not installed: pip could not install $REQUIREMENTS into $TRAIN_VENV" >&2
  exit 1
fi
if "$TRAIN_VENV/bin/python" -m pip show -q opencv-python >/dev/null 2>&1; then
  opencv=$("$TRAIN_VENV/bin/python" -m pip show opencv-python | sed -n 's/^Version: //p')
  "$TRAIN_VENV/bin/python" -m pip uninstall -q -y opencv-python
  if ! "$TRAIN_VENV/bin/python" -m pip install -q --no-deps --force-reinstall "opencv-python-headless==$opencv"; then
    echo "setup_train: the detector (Ultralytics) not installed: pip could not install opencv-python-headless==$opencv" >&2
    exit 1
  fi
fi
# Ultralytics writes its settings file on import: into the environment, not the home folder.
export YOLO_CONFIG_DIR="$TRAIN_VENV/ultralytics-settings"
if ! "$TRAIN_VENV/bin/python" -c 'import cv2, torch, torchvision, ultralytics' >/dev/null 2>&1; then
  echo "setup_train: the detector (Ultralytics) not installed: $TRAIN_VENV/bin/python cannot import it" \
       "($("$TRAIN_VENV/bin/python" -c 'import cv2, torch, torchvision, ultralytics' 2>&1 | tail -n 1))" >&2
  exit 1
fi
echo "$REQUIREMENTS" >"$stamp"
"$TRAIN_VENV/bin/python" -c 'import torch, ultralytics; print("setup_train: Ultralytics", ultralytics.__version__,
"with torch", torch.__version__, "ready; CUDA", "available" if torch.cuda.is_available() else "not available")'
