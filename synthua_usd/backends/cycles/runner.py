"""Start Blender Cycles on an interchange folder in its own interpreter and read back what it rendered.

The Cycles interpreter is the Python of a virtual environment holding PyPI's ``bpy`` (``tools/setup_cycles.sh``
makes ``.venv-cycles`` beside the repository's ``.venv``). :func:`find_cycles_python` looks for it;
:class:`CyclesUnavailable` says in one line what is missing and how to install it.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from synthua_usd.core import images
from synthua_usd.core import json_text
from synthua_usd.core.errors import SynthuaError

REPO = Path(__file__).resolve().parents[3]
SCRIPT = Path(__file__).resolve().with_name("blender_render.py")
#: Where ``tools/setup_cycles.sh`` puts the Cycles interpreter by default (``CYCLES_VENV`` there).
DEFAULT_VENV = REPO / ".venv-cycles"
ENV_PYTHON = "SYNTHUA_CYCLES_PYTHON"
INSTALL_HINT = "run tools/setup_cycles.sh (PyPI bpy==5.0.1 for Python 3.11 in .venv-cycles)"


class CyclesUnavailable(SynthuaError):
    """No interpreter with Blender's ``bpy`` module was found, or it failed to start."""


@dataclass(frozen=True)
class CyclesJob:
    """One Cycles render of the exported scene: ``samples`` per pixel (the most, with adaptive sampling), OIDN
    denoising with albedo and normal guides when ``denoise``."""

    name: str
    samples: int
    denoise: bool = False
    adaptive: bool = False
    adaptive_threshold: float = 0.01
    seed: int = 0


@dataclass
class CyclesResult:
    """Per job name: (H, W, 3) float32 scene-linear Rec.709 image and the seconds ``bpy.ops.render.render`` took;
    ``build_s`` (reading the interchange and building the Blender scene) and ``warmup_s`` (a 1-sample render
    that syncs the scene and builds the BVH, kept for the jobs by persistent data)."""

    blender: str
    build_s: float
    warmup_s: float
    images: dict = field(default_factory=dict)
    seconds: dict = field(default_factory=dict)


def find_cycles_python(explicit: str | Path | None = None) -> Path:
    """The Cycles interpreter: ``explicit``, else ``$SYNTHUA_CYCLES_PYTHON``, else ``.venv-cycles/bin/python``
    of the repository; it must import ``bpy``."""
    candidate = Path(explicit or os.environ.get(ENV_PYTHON) or DEFAULT_VENV / "bin" / "python")
    if not candidate.exists():
        raise CyclesUnavailable(f"Blender (bpy) is not installed: no Cycles interpreter at {candidate}; {INSTALL_HINT}")
    probe = subprocess.run([str(candidate), "-c", "import bpy; print(bpy.app.version_string)"],
                           capture_output=True, text=True, timeout=120)
    if probe.returncode != 0:
        last = (probe.stderr.strip().splitlines() or ["no output"])[-1]
        raise CyclesUnavailable(f"Blender (bpy) is not installed in {candidate} ({last}); {INSTALL_HINT}")
    return candidate


def render_jobs(python: Path, interchange: Path, jobs: list[CyclesJob], out_dir: Path, threads: int,
                max_bounces: int, timeout_s: float | None = None) -> CyclesResult:
    """Render ``jobs`` of the scene in ``interchange`` with Cycles on the CPU (``threads`` threads, path length
    ``max_bounces``) in a subprocess of ``python``; images are written to and read back from ``out_dir``."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    jobs_path = out_dir / "jobs.json"
    jobs_path.write_text(json_text.dumps({"settings": {"threads": threads, "max_bounces": max_bounces},
                                          "jobs": [vars(j) for j in jobs]}, indent=1), encoding="utf-8")
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    done = subprocess.run([str(python), str(SCRIPT), str(interchange), str(jobs_path), str(out_dir)],
                          capture_output=True, text=True, timeout=timeout_s, env=env)
    if done.returncode != 0:
        tail = "\n".join((done.stdout + done.stderr).strip().splitlines()[-15:])
        raise CyclesUnavailable(f"Cycles render failed (exit {done.returncode}):\n{tail}")
    timings = json.loads((out_dir / "cycles.json").read_text(encoding="utf-8"))
    result = CyclesResult(blender=timings["blender"], build_s=timings["build_s"], warmup_s=timings["warmup_s"])
    for name, entry in timings["jobs"].items():
        pixels, _ = images.read_image(entry["path"])
        result.images[name] = np.ascontiguousarray(pixels[..., :3], np.float32)
        result.seconds[name] = float(entry["render_s"])
    return result


if __name__ == "__main__":  # pragma: no cover - a manual check: prints the interpreter or why there is none
    try:
        print(find_cycles_python(sys.argv[1] if len(sys.argv) > 1 else None))
    except CyclesUnavailable as exc:
        print(exc)
        sys.exit(1)
