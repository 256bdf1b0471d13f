"""A wheel built from the tree works on its own: installed (not editable) into a fresh virtual environment, run from a
folder outside the source tree, ``synthua create district`` writes the district and ``synthua generate`` makes a
small dataset of it that verifies. What the wheel must carry (every subpackage, the schemas and class map, the body
bank, textures) is what this needs.

The fresh environment gets the wheel alone (``--no-deps``); the dependencies are the test environment's own, reached
through a ``.pth`` line naming its site-packages (a path listed in a ``.pth`` file is added to ``sys.path``, but the
``.pth`` files inside it, among them the editable install's finder, are not run: the source tree stays out)."""

from __future__ import annotations

import json
import os
import site
import subprocess
import sys
import zipfile
from pathlib import Path

from conftest import REPO


def run(args, cwd: Path, timeout: int = 600) -> subprocess.CompletedProcess:
    result = subprocess.run([str(a) for a in args], cwd=cwd, capture_output=True, text=True, timeout=timeout,
                            env={k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")})
    assert result.returncode == 0, (args, result.stdout[-2000:], result.stderr[-2000:])
    return result


def test_the_wheel_installed_alone_creates_the_district_and_generates_from_it(tmp_path):
    wheels = tmp_path / "wheels"
    run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q", "-w", wheels, REPO], REPO)
    (wheel,) = wheels.glob("synthua_usd-*.whl")
    with zipfile.ZipFile(wheel) as archive:
        carried = set(archive.namelist())
    sources = {p.relative_to(REPO).as_posix() for p in (REPO / "synthua_usd").rglob("*.py")}
    schemas = {f"synthua_usd/schema_files/{p.name}" for p in (REPO / "schemas").glob("*.json")}
    data = {p.relative_to(REPO).as_posix() for p in (REPO / "synthua_usd" / "assets" / "data").rglob("*") if p.is_file()}
    assert len(data) > 10 and "synthua_usd/assets/data/bodies.npz" in data  # the body bank and the look images
    assert sources | schemas | data <= carried, sorted(sources | schemas | data - carried)
    venv = tmp_path / "venv"
    run([sys._base_executable, "-m", "venv", venv], tmp_path)
    python = venv / "bin" / "python"
    run([python, "-m", "pip", "install", "-q", "--no-deps", "--no-index", wheel], tmp_path)
    own = Path(run([python, "-c", "import site; print(site.getsitepackages()[0])"], tmp_path).stdout.strip())
    (own / "synthua_test_dependencies.pth").write_text(site.getsitepackages()[0] + "\n")

    work = tmp_path / "elsewhere"
    work.mkdir()
    where = run([python, "-c", "import synthua_usd; print(synthua_usd.__file__)"], work).stdout.strip()
    assert Path(where).is_relative_to(venv) and not Path(where).is_relative_to(REPO), where
    synthua = venv / "bin" / "synthua"
    run([synthua, "create", "district", "district"], work)
    config = work / "small.json"
    config.write_text(json.dumps({"name": "wheel-smoke", "images": 2, "cameras": ["/World/Cameras/CCTV_Largo"],
                                  "render": {"width": 64, "height": 48, "spp": 1, "denoise": False},
                                  "time_codes": [24], "conditions": ["clear_day"], "seeds": [0, 1], "quotas": {},
                                  "split": {"train": 1.0, "val": 0.0, "test": 0.0}, "qa": {"reject": []},
                                  "workers": 1}))
    run([synthua, "generate", "district/scenario.usda", "--config", config, "--out", "dataset"], work)
    assert run([synthua, "verify", "dataset"], work).stdout.rstrip().endswith(": ok")
