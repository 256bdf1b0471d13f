"""``synthua generate`` resumed: after SIGKILL at several points of a run, after a full disk, and over a
temporary file a killed run left; each time the dataset is the uninterrupted run's, byte for byte."""

from __future__ import annotations

import json
import signal
import subprocess

import pytest

from conftest import generate_dataset
from dataset_runs import generate_command, kill_when, tree_bytes
from synthua_usd.pipeline.verify import verify
from test_generate import _config


KILL_POINTS = {
    "planned": lambda out: (out / "generate.json").exists(),
    "mid-images": lambda out: len(list((out / "records").glob("*.json"))) >= 2 if (out / "records").exists() else False,
    "assembling": lambda out: (out / "data.yaml").exists(),
    # QA rejected an image and the plan holds its replacement (round 1), not rendered yet
    "replacing": lambda out: (out / "generate.json").exists() and '"round": 1' in (out / "generate.json").read_text(),
}


@pytest.mark.parametrize("point", list(KILL_POINTS))
def test_resume_after_kill_gives_the_same_dataset(generated, tmp_path, point):
    out = tmp_path / "killed"
    killed = kill_when(out, KILL_POINTS[point])
    assert killed or (out / "manifest.json").exists()
    generate_dataset(out)
    assert verify(out).ok
    assert tree_bytes(out) == tree_bytes(generated), "no missing, duplicate, stray or different file"


def test_disk_error_is_one_line_and_resumable(generated, tmp_path):
    """Files may not grow past 20 KiB (RLIMIT_FSIZE: writes fail with EFBIG, as on a full disk): one line,
    exit 2; the same command without the limit then finishes the dataset."""
    import resource

    def limit():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (20_000, 20_000))

    out = tmp_path / "limited"
    proc = subprocess.run(generate_command(out), capture_output=True, timeout=180, preexec_fn=limit)
    stderr = proc.stderr.decode()
    assert proc.returncode == 2, stderr
    assert "Traceback" not in stderr
    assert stderr.strip().splitlines()[-1].startswith("synthua: error: "), stderr
    generate_dataset(out)
    assert tree_bytes(out) == tree_bytes(generated)


def test_leftover_temporary_file_does_not_block_a_new_run_and_occlusion_quota_is_planned(tmp_path):
    """A run killed while writing its first generate.json leaves only a dot file: the same command then
    starts. A quota with max_occlusion is planned for (the planner knows pixels, not occlusion) and met."""
    out = tmp_path / "out"
    out.mkdir()
    (out / ".generate.k3j2.json").write_text("{")
    config = _config(tmp_path, quotas={"aid_users": {"min_share": 0.5, "min_pixels": 5, "max_occlusion": 0.95}})
    generate_dataset(out, config=config)
    assert not (out / ".generate.k3j2.json").exists()
    job = json.loads((out / "generate.json").read_text())
    assert job["pool"]["aid_users"] > 0
    quotas = {q["quota"]: q for q in json.loads((out / "coverage.json").read_text())["quotas"]}
    assert quotas["aid_users"]["met"], quotas
