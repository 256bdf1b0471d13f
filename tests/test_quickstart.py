"""The README's "Your own scene, end to end": its command block, run as written, into a temporary folder outside
the repository: twin, people, an aimed camera, composition, a frame with no black pixel past the twin, a dataset
that verifies, and its statistics report."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

from conftest import MOBILITY_AIDS, REPO
from frame_checks import black_shares

MARKER = "<!-- --8<-- [start:quickstart] -->"


def quickstart_block() -> str:
    """The shell block right after the README's quickstart marker."""
    text = (REPO / "README.md").read_text(encoding="utf-8")
    match = re.search(re.escape(MARKER) + r"\s*```sh\n(.*?)```", text, re.S)
    assert match, "README.md: no ```sh block after the quickstart marker"
    return match.group(1)


def test_the_readme_quickstart_runs_from_twin_to_dataset(tmp_path):
    folder = tmp_path / "my_district"
    assert not folder.resolve().is_relative_to(REPO.resolve())
    block = quickstart_block()
    first, rest = block.split("\n", 1)
    assert first.startswith("D="), first
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"}
    script = f"set -euo pipefail\nD={folder}\n{rest}"
    result = subprocess.run(["bash", "-c", script], cwd=REPO, env=env, capture_output=True, text=True, timeout=1500)
    assert result.returncode == 0, result.stderr[-3000:]
    frames = folder / "frames"
    aid = json.loads((frames / "AidCCTV" / "0012" / "frame.json").read_text())
    aids_seen = [i for i in aid["instances"] if i["class_name"] in MOBILITY_AIDS and i["pixel_count"] > 0]
    assert aids_seen, "the aimed CCTV sees no mobility aid"
    for camera in ("AidCCTV", "PedestrianEye_Street"):
        frame = frames / camera / "0012"
        assert (frame / "instance_preview.png").exists() and (frame / "semantic.png").exists()
        if camera == "PedestrianEye_Street":  # looks along the street at the horizon
            overall, past_the_twin = black_shares(frame)
            assert past_the_twin == 0.0 and overall < 0.001, (overall, past_the_twin)
    verified = [line for line in result.stdout.splitlines() if line.startswith(f"{folder / 'dataset'}: ")]
    assert verified and verified[-1].endswith("files checked: ok"), result.stdout[-500:]  # synthua verify
    report = folder / "report"
    assert (report / "report.html").stat().st_size > 0, sorted(p.name for p in report.iterdir())  # synthua stats
