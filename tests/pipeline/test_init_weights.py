"""Where a training starts (synthua_usd/pipeline/init_weights.py), without the detector: the kind a path names, its
SHA-256, the record and its words, and the one-line refusals of what is not on this machine. Loading a checkpoint
in Ultralytics is tested with the detector in test_sim2real.py."""

from __future__ import annotations

import hashlib
import json

import pytest

from synthua_usd.core.errors import InputError
from synthua_usd.pipeline.init_weights import InitWeights, describe, inspect_checkpoint, locate_init


@pytest.fixture
def run_folder(tmp_path):
    folder = tmp_path / "runs" / "a_synthetic_s0"
    folder.mkdir(parents=True)
    (folder / "weights.pt").write_bytes(b"weights of a run")
    (folder / "train.json").write_text(json.dumps({"model": "yolo26n.yaml", "seed": 0}))
    return folder


def test_scratch_run_and_checkpoint(run_folder, tmp_path):
    scratch = locate_init(None)
    assert (scratch.kind, scratch.model, scratch.document()) == ("scratch", "yolo26n.yaml", None)
    assert locate_init(None, "yolo11n.yaml").model == "yolo11n.yaml"
    sha = hashlib.sha256(b"weights of a run").hexdigest()
    for path in (run_folder, run_folder / "weights.pt"):
        run = locate_init(path)
        assert (run.kind, run.weights, run.sha256, run.run) == ("run", (run_folder / "weights.pt").resolve(), sha,
                                                                {"model": "yolo26n.yaml", "seed": 0})
        assert run.model == str(run.weights) and run.architecture is None
    ckpt = tmp_path / "yolo11n.pt"
    ckpt.write_bytes(b"a checkpoint")
    found = locate_init(ckpt)
    assert (found.kind, found.weights, found.sha256) == ("checkpoint", ckpt.resolve(),
                                                         hashlib.sha256(b"a checkpoint").hexdigest())
    # a weights.pt without a train.json beside it is a checkpoint like any other
    (tmp_path / "loose").mkdir()
    (tmp_path / "loose" / "weights.pt").write_bytes(b"x")
    assert locate_init(tmp_path / "loose" / "weights.pt").kind == "checkpoint"


def test_the_record_and_its_words(run_folder):
    run = locate_init(run_folder)
    doc = run.document([499, 499])
    assert doc["kind"] == "run" and doc["sha256"] == run.sha256 and doc["transferred"] == [499, 499]
    assert doc["run"]["seed"] == 0 and "checkpoint" not in doc
    assert describe(doc) == f"run a_synthetic_s0 (sha256 {run.sha256[:8]})"
    assert describe(None) == "scratch (yolo26n.yaml)" and describe(None, "yolo11n.yaml") == "scratch (yolo11n.yaml)"
    ckpt = InitWeights("checkpoint", run_folder / "yolo11n.pt", "ab" * 32,
                       checkpoint={"names": ["person"] * 80, "architecture": "yolo11n.yaml", "trained_on": "coco.yaml"})
    assert describe(ckpt.document()) == "checkpoint yolo11n.pt (yolo11n.yaml, 80 classes, trained on coco.yaml, " \
                                        "sha256 abababab)"
    # a checkpoint inspected once is not inspected again (no interpreter is asked)
    assert inspect_checkpoint(ckpt, python=None, scratch=None) is ckpt
    with pytest.raises(ValueError, match="kind 'best'"):
        InitWeights("best")


def test_what_is_not_on_this_machine_is_refused_in_one_line(tmp_path):
    (tmp_path / "notes.txt").write_text("x")
    (tmp_path / "empty").mkdir()
    cases = [(tmp_path / "yolo11n.pt", "yolo11n.pt: not found; expected a run folder of `synthua train` or an "
                                       "Ultralytics checkpoint file (.pt, e.g. a COCO-pretrained yolo11n.pt) on this "
                                       "machine (nothing is downloaded: put the file there first)"),
             ("yolo26n.pt", "--init: yolo26n.pt: not found"),              # a bare name is never fetched
             ("https://github.com/ultralytics/assets/releases/download/v8.4.0/yolo11n.pt", "not found"),
             (tmp_path / "notes.txt", "notes.txt: not a .pt file"),
             (tmp_path / "empty", "no weights.pt and train.json; expected a run folder")]
    for path, found in cases:
        with pytest.raises(InputError) as info:
            locate_init(path)
        message = str(info.value)
        assert found in message and "\n" not in message, message
