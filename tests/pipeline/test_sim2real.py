"""The whole sim-to-real path on a tiny randomised dataset: `synthua train` (one epoch of Ultralytics YOLO, from
scratch, on the CPU) and `synthua evaluate-real` with that dataset as the "real" test set, read as a third party's
YOLO folder, as COCO JSON and as a generated dataset. No number is asserted of the model (it has barely trained):
what is checked is that the path runs, records what it trained on, fetched nothing, and that the scores are
pycocotools' (COCOeval run here on the detections it wrote gives the same AP per class).

Skips with the reason where the detector's environment (.venv-train, tools/setup_train.sh) is absent."""

from __future__ import annotations

import contextlib
import csv
import hashlib
import io
import json
from pathlib import Path

import numpy as np
import pytest

from synthua_usd.pipeline.detector.runner import DetectorUnavailable, find_detector_python
from synthua_usd.cli.main import main
from synthua_usd.pipeline.sim2real import COUNTS
from synthua_usd.analytics.detection_metrics import FP_KINDS


@pytest.fixture(scope="module")
def detector_python() -> Path:
    try:
        return find_detector_python()
    except DetectorUnavailable as exc:
        pytest.skip(str(exc))


@pytest.fixture(scope="module")
def run(detector_python, generated_random, tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("sim2real") / "run"
    code = main(["train", str(generated_random), "--epochs", "1", "--imgsz", "64", "--batch", "2", "--seed", "3",
                 "--min-height-px", "2", "--device", "cpu", "--out", str(out)])
    assert code == 0
    return out


def test_train_records_what_it_trained_on(run, generated_random):
    about = json.loads((run / "train.json").read_text())
    manifest = (generated_random / "manifest.json").read_bytes()
    assert about["train_set"]["dataset_id"] == hashlib.sha256(manifest).hexdigest()
    assert about["train_set"]["generation_config"] == json.loads(manifest)["provenance"]["config"]
    assert about["train_set"]["generation_config"]["randomise"]          # the scene randomisation made it
    assert about["budget"] == {"minutes": None, "epochs": 1, "imgsz": 64, "batch": 2, "close_mosaic": 10}
    assert about["seed"] == 3 and about["device"] == "cpu" and about["epochs_done"] == 1
    assert about["model"] == "yolo26n.yaml" and about["init"] is None
    assert about["versions"]["ultralytics"] == "8.4.190" and about["versions"]["torch"]
    assert about["downloaded"] == [] and about["network"] == []            # nothing fetched, nothing even tried
    assert about["targets"]["aid_box"] == "with_user" and about["classes"][0] == "person"
    assert (run / "weights.pt").stat().st_size > 1_000_000 and (run / "results.csv").is_file()


def _cocoeval_ap(gt_doc: dict, detections: list[dict], class_ids: dict[str, int]) -> dict[str, float | None]:
    """AP (IoU 0.50:0.95, area all, 100 detections) per class by pycocotools, straight from the files."""
    from pycocotools.coco import COCO
    from pycocotools.cocoeval import COCOeval

    results = [{"image_id": d["image_id"], "category_id": class_ids[d["class_name"]], "score": d["score"],
                "bbox": d["bbox"]} for d in detections if d["class_name"] in class_ids]
    with contextlib.redirect_stdout(io.StringIO()):
        gt = COCO()
        gt.dataset = gt_doc
        gt.createIndex()
        ev = COCOeval(gt, gt.loadRes(results), "bbox")
        ev.params.catIds = sorted(class_ids.values())
        ev.evaluate()
        ev.accumulate()
    out = {}
    for k, cat in enumerate(ev.params.catIds):
        p = ev.eval["precision"][:, :, k, 0, -1]
        name = next(n for n, c in class_ids.items() if c == cat)
        has_boxes = any(a["category_id"] == cat and not a.get("iscrowd") for a in gt_doc["annotations"])
        out[name] = float(p[p > -1].mean()) if has_boxes and (p > -1).any() else None
    return out


def test_evaluate_real_on_coco_json_is_cocoeval(run, generated_random, tmp_path):
    out = tmp_path / "eval_coco"
    coco = generated_random / "annotations" / "instances_val.json"
    assert main(["evaluate-real", str(run), str(coco), "--images", str(generated_random / "images" / "val"),
                 "--out", str(out)]) == 0
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["evaluator"].startswith("pycocotools") and metrics["downloaded"] == []
    detections = json.loads((out / "detections.json").read_text())
    gt_doc = json.loads(coco.read_text())
    # our image ids number the images by their COCO id order; the detections name their files
    ids = {im["file_name"]: im["id"] for im in gt_doc["images"]}
    for d in detections:
        d["image_id"] = ids[Path(d["file_name"]).name]
    names = {c["id"]: c["name"] for c in gt_doc["categories"]}
    scored = {n: c for c, n in names.items() if n in metrics["mapping"]}
    expected = _cocoeval_ap(gt_doc, detections, scored)
    got = {c["class"]: c["AP50_95"] for c in metrics["classes"]}
    assert set(got) == set(expected)
    for name, value in expected.items():
        assert got[name] == (None if value is None else pytest.approx(value, abs=1e-12)), name
    for name in ("per_class.csv", "false_negatives.csv", "false_negatives.png", "false_positives.csv",
                 "false_positives.png", "report.html"):
        assert (out / name).stat().st_size > 0
    assert "false_negatives.png" in (out / "report.html").read_text()
    assert "false_positives.png" in (out / "report.html").read_text()


def test_evaluate_real_on_a_yolo_folder_with_real_class_names(run, generated_random, tmp_path, capsys):
    """The generated dataset as a third party's YOLO folder, its two wheelchair classes scored as one."""
    out = tmp_path / "eval_yolo"
    assert main(["evaluate-real", str(run), str(generated_random), "--format", "yolo", "--split", "val",
                 "--map", "person=person", "--map", "manual_wheelchair=manual_wheelchair,electric_wheelchair",
                 "--confidence", "0.05", "--out", str(out)]) == 0
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["test_set"]["layout"] == "yolo" and metrics["confidence"] == 0.05
    assert [c["class"] for c in metrics["classes"]] == ["person", "manual_wheelchair"]
    assert metrics["mapping"]["manual_wheelchair"] == ["manual_wheelchair", "electric_wheelchair"]
    person = metrics["classes"][0]
    assert person["boxes"] == person["tp"] + person["fn"] and person["boxes"] > 0
    rows = (out / "false_negatives.csv").read_text().splitlines()
    assert len(rows) - 1 == sum(c["fn"] for c in metrics["classes"]) == metrics["false_negatives"]
    with (out / "false_positives.csv").open() as f:
        wrong = list(csv.DictReader(f))
    assert len(wrong) == sum(c["fp"] for c in metrics["classes"]) == metrics["false_positives"]
    for c in metrics["classes"]:          # each class's false positives, by what they land on, as its row counts them
        kinds = [r["lands_on"] for r in wrong if r["class"] == c["class"]]
        assert {k: kinds.count(k) for k in metrics["false_positive_kinds"]["kinds"]} == {
            k: c[f"fp_{k}"] for k in metrics["false_positive_kinds"]["kinds"]}
    assert [float(r["score"]) for r in wrong] == sorted((float(r["score"]) for r in wrong), reverse=True)
    out_text = capsys.readouterr().out
    assert "person" in out_text and f"{metrics['false_positives']} false positives" in out_text


def test_evaluate_real_on_the_held_out_split_uses_the_trained_boxes(run, generated_random, tmp_path):
    out = tmp_path / "eval_synthetic"
    assert main(["evaluate-real", str(run), str(generated_random), "--split", "val", "--out", str(out)]) == 0
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["test_set"]["layout"] == "synthua" and metrics["test_set"]["targets"]["aid_box"] == "with_user"
    assert metrics["test_set"]["scored_boxes"] == "all"                  # --boxes: every box of the set scored
    assert metrics["test_set"]["dataset_id"] == json.loads((run / "train.json").read_text())["train_set"]["dataset_id"]
    aps = [c["AP50"] for c in metrics["classes"] if c["AP50"] is not None]
    assert aps and all(0.0 <= v <= 1.0 for v in aps) and np.isfinite(aps).all()


def test_evaluate_real_with_the_wheelchair_sets_convention(run, generated_random, tmp_path, capsys):
    """The held-out split scored on the boxes of real wheelchair sets (the model's classes kept): no aid user is a
    person box, so fewer person boxes than with the model's own convention; on a YOLO set --convention is refused."""
    own, sets = tmp_path / "own", tmp_path / "sets"
    assert main(["evaluate-real", str(run), str(generated_random), "--split", "val", "--out", str(own)]) == 0
    assert main(["evaluate-real", str(run), str(generated_random), "--split", "val", "--convention",
                 "wheelchair-sets", "--out", str(sets)]) == 0
    a, b = (json.loads((p / "metrics.json").read_text())["test_set"] for p in (own, sets))
    assert b["targets"]["aid_users_as_person"] is False and b["targets"]["classes"] == a["targets"]["classes"]
    assert b["boxes"]["person"] < a["boxes"]["person"]
    capsys.readouterr()
    assert main(["evaluate-real", str(run), str(generated_random), "--format", "yolo", "--split", "val",
                 "--convention", "wheelchair-sets", "--out", str(tmp_path / "yolo")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "is read as a yolo set, whose boxes are its own" in err[0]


def test_fine_tuning_on_a_real_set_starts_from_the_run(run, generated_random, tmp_path):
    """A YOLO folder as the training set, from the synthetic run's weights: the classes are the set's own."""
    out = tmp_path / "tuned"
    assert main(["train", str(generated_random), "--format", "yolo", "--init", str(run), "--epochs", "1",
                 "--imgsz", "64", "--batch", "2", "--device", "cpu", "--out", str(out)]) == 0
    about = json.loads((out / "train.json").read_text())
    init = about["init"]
    assert init["kind"] == "run" and init["weights"] == str((run / "weights.pt").resolve()) and about["model"] is None
    assert init["sha256"] == hashlib.sha256((run / "weights.pt").read_bytes()).hexdigest()
    assert init["run"] == json.loads((run / "train.json").read_text())
    # the weights were taken, by Ultralytics' own count: all of them, the head's class rows matched by class name
    taken, of = init["transferred"]
    assert taken == of > 0 and f"Transferred {taken}/{of} items" in (out / "train.log").read_text()
    assert about["train_set"]["layout"] == "yolo" and about["targets"] is None
    assert about["classes"][:2] == ["curb_ramp", "crosswalk"]          # the generated data.yaml's names
    assert not list((generated_random / "labels").glob("*.cache"))      # Ultralytics' cache went to its own copy


def test_refusals_are_one_line(run, generated_random, tmp_path, capsys):
    cases = [
        (["evaluate-real", str(run), str(generated_random), "--format", "yolo", "--split", "val",
          "--map", "wheelchair=manual_wheelchair"], "'wheelchair' is not a class of the test set"),
        (["evaluate-real", str(tmp_path), str(generated_random)], "no weights.pt and train.json"),
        (["evaluate-real", str(run), str(tmp_path / "nothing")], "not found; expected an Ultralytics YOLO folder"),
        (["train", str(generated_random), "--classes", "person,road"], "not thing classes"),
        (["train", str(generated_random), "--imgsz", "100"], "multiple of 32"),
    ]
    for args, found in cases:
        assert main(args + ["--out", str(tmp_path / "out")]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("synthua: error:") and found in err[0], err
        assert not (tmp_path / "out").exists()


# --- starting from an Ultralytics checkpoint file (made here, never downloaded) ---------------------------------------

@pytest.fixture(scope="module")
def checkpoints(detector_python, tmp_path_factory) -> dict[str, Path]:
    """Checkpoints as Ultralytics saves them, of freshly built models: ``detect`` a YOLO11n detector with COCO's 80
    classes (a stand-in for a user's COCO-pretrained yolo11n.pt: same file layout, untrained weights), ``classify``
    a YOLO11n classifier, and ``garbage``, a .pt file that is no checkpoint."""
    import os
    import subprocess

    folder = tmp_path_factory.mktemp("checkpoints")
    script = ("import sys\nfrom ultralytics import YOLO\n"
              "YOLO('yolo11n.yaml').save(sys.argv[1])\nYOLO('yolo11n-cls.yaml').save(sys.argv[2])\n")
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env |= {"YOLO_OFFLINE": "1", "YOLO_CONFIG_DIR": str(folder / "settings")}
    out = {"detect": folder / "yolo11n.pt", "classify": folder / "yolo11n-cls.pt", "garbage": folder / "garbage.pt"}
    subprocess.run([str(detector_python), "-c", script, str(out["detect"]), str(out["classify"])], check=True,
                   env=env, cwd=folder, capture_output=True, timeout=300)
    out["garbage"].write_bytes(b"not a checkpoint\n")
    return out


def test_train_from_a_checkpoint_file(checkpoints, generated_random, tmp_path, capsys):
    out = tmp_path / "from_checkpoint"
    assert main(["train", str(generated_random), "--init", str(checkpoints["detect"]), "--epochs", "1", "--imgsz", "64",
                 "--batch", "2", "--device", "cpu", "--out", str(out)]) == 0
    assert "from checkpoint yolo11n.pt (yolo11n.yaml, 80 classes, sha256" in capsys.readouterr().out
    about = json.loads((out / "train.json").read_text())
    init = about["init"]
    assert init["kind"] == "checkpoint" and init["weights"] == str(checkpoints["detect"].resolve())
    assert init["sha256"] == hashlib.sha256(checkpoints["detect"].read_bytes()).hexdigest()
    assert init["checkpoint"]["task"] == "detect" and init["checkpoint"]["architecture"] == "yolo11n.yaml"
    assert len(init["checkpoint"]["names"]) == 80 and init["checkpoint"]["saved_with"] == "8.4.190"
    taken, of = init["transferred"]   # all but the head's class layers: no class name of ours is among its 0..79
    assert 0.9 * of < taken < of
    assert about["model"] is None and about["downloaded"] == [] and about["network"] == []


def test_a_checkpoint_that_cannot_start_a_detector_is_refused_in_one_line(checkpoints, generated_random, tmp_path,
                                                                         capsys):
    cases = [(checkpoints["garbage"], "garbage.pt: Ultralytics cannot load it ("),
             (checkpoints["classify"], "an Ultralytics classify checkpoint; expected a detection checkpoint"),
             (tmp_path / "yolo26n.pt", "yolo26n.pt: not found; expected a run folder of `synthua train` or an "
                                       "Ultralytics checkpoint file")]
    for path, found in cases:
        assert main(["train", str(generated_random), "--init", str(path), "--epochs", "1", "--imgsz", "64",
                     "--out", str(tmp_path / "out")]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("synthua: error: --init: ") and found in err[0], err
        assert not (tmp_path / "out").exists()


# --- tools/sim2real.py end to end: every arm from one checkpoint ------------------------------------------------------

def test_the_experiment_tool_end_to_end(checkpoints, generated_random, tmp_path, capsys):
    """The randomised dataset (train 2 images, val 4) as the synthetic set, as the stand-in "real" photos (its val
    split the test) and as the mixed set of arm d; one real photo drawn; 4 image-steps a training at imgsz 64; one
    seed (the seeds' spread is tested against NumPy in test_sim2real_plan.py). Hand-worked: (a) 4 / 2 images = 2
    epochs; (b) and (c) 4 / 1 photo = 4 epochs; (d) 1 photo + 2 mixed: 4 / 3 = 1.33 -> 1 epoch, 3 image-steps."""
    from conftest import load_tool

    tool = load_tool("sim2real.py", "sim2real_e2e")
    work = tmp_path / "work"
    args = ["--synthetic", str(generated_random), "--synthetic-split", "none", "--stand-in", str(generated_random),
            "--stand-in-test-split", "val", "--mix", str(generated_random), "--arms", "a,b,c,d", "--real-sizes", "1",
            "--seeds", "0", "--budget-images", "4", "--imgsz", "64", "--batch", "2", "--device", "cpu",
            "--close-mosaic-share", "0.5", "--init", str(checkpoints["detect"]), "--work", str(work)]
    assert tool.main(args) == 0
    doc = json.loads((work / "sim2real.json").read_text())
    plan = doc["plan"]
    assert (plan["synthetic_images"], plan["real_photos"], plan["mix_images"]) == (2, 2, {"1": 2})
    runs = {r["name"]: r for r in doc["runs"]}
    assert list(runs) == ["a_synthetic_s0", "b_n0001_s0", "c_n0001_s0", "d_n0001_s0"]
    ckpt_sha = hashlib.sha256(checkpoints["detect"].read_bytes()).hexdigest()
    for name, r in runs.items():
        epochs, images = {"a": (2, 2), "b": (4, 1), "c": (4, 1), "d": (1, 3)}[r["arm"]]
        about = json.loads((Path(r["run"]) / "train.json").read_text())
        assert (r["epochs"], r["images"], r["image_steps"]) == (epochs, images, epochs * images), name
        assert about["budget"]["epochs"] == r["epochs_done"] == epochs and about["seed"] == r["seed"] == 0
        # half of each arm's epochs without mosaic (halves up), as Ultralytics' trainer ran it
        assert about["budget"]["close_mosaic"] == r["close_mosaic"] == {1: 1, 2: 1, 4: 2}[epochs], name
        assert about["train_set"]["images"]["train"] == images and r["device"] == "cpu" and r["seconds"] > 0
        assert r["command"].startswith("synthua train ") and f"--epochs {epochs} " in r["command"]
        if r["arm"] == "c":        # (a)'s run of the same seed, fine-tuned
            a_weights = Path(runs["a_synthetic_s0"]["run"]) / "weights.pt"
            assert r["init"]["kind"] == "run" and r["init"]["sha256"] == hashlib.sha256(a_weights.read_bytes()).hexdigest()
        else:                      # every other arm from the one checkpoint
            assert r["init"]["kind"] == "checkpoint" and r["init"]["sha256"] == ckpt_sha
            assert f"--init {checkpoints['detect'].resolve()}" in r["command"]
        assert r["init"]["transferred"][0] > 0 and r["network"] == [] and r["downloaded"] == []
    assert "d_n0001_s0: 4 image-steps / 3 images = 1.33 epochs, trained as 1: 3 image-steps (-25.0 %)" in doc["notes"]
    assert "1 seed: a spread from fewer than 3 seeds is not a figure to quote" in doc["notes"]
    # the subset is stated and linked; arm d's folder holds it and the mixed set
    subset = json.loads((work / "subsets" / "n0001" / "subset.json").read_text())
    assert subset["photos"] == doc["subsets"]["1"] and len(subset["photos"]) == 1
    assert len(list((work / "mixed" / "n0001" / "images" / "train").iterdir())) == 3
    # every run scored on the stand-in test, per class
    assert {(s["arm"], s["class"]) for s in doc["summary"]} == {(a, c) for a in "abcd" for c in ("person", "wheelchair")}
    for row in doc["scores"]:
        s = next(s for s in doc["summary"] if (s["arm"], s["class"]) == (row["arm"], row["class"]))
        assert s["AP50"]["mean"] == row["AP50"] and s["AP50"]["std"] is None and s["seeds"] == [0]
    # (c) and (d) against (b) class by class, from the same scores; one seed: no interval
    ap = {(r["arm"], r["class"]): r["AP50"] for r in doc["scores"]}
    scored = {c for (arm, c), v in ap.items() if arm == "b" and v is not None}
    assert {(r["arm"], r["class"]) for r in doc["comparisons"]} == {(a, c) for a in "cd" for c in scored
                                                                     if ap[(a, c)] is not None}
    assert doc["comparisons"]
    for r in doc["comparisons"]:
        assert r["difference"] == pytest.approx(ap[(r["arm"], r["class"])] - ap[("b", r["class"])])
        assert r["per_seed"] == [pytest.approx(r["difference"])] and r["low"] is None and r["beyond"] is None
    text = (work / "sim2real.md").read_text()
    assert "| (d) real + mixed set | 1 + 2 mixed | 0 | 1 × 3 = 3 |" in text
    assert "| (c) synthetic, then real | 1 | 0 | 4 × 1 = 4 after (a)'s 4 |" in text
    assert "every arm from checkpoint yolo11n.pt (yolo11n.yaml, 80 classes" in text
    assert (work / "sim2real.png").stat().st_size > 5000
    # run again: every run and score is kept (nothing trains); another budget is refused on the first kept run
    stamps = {n: (Path(r["run"]) / "train.json").stat().st_mtime_ns for n, r in runs.items()}
    capsys.readouterr()
    assert tool.main(args) == 0
    out = capsys.readouterr().out
    assert "sim2real: training" not in out and out.count("sim2real: kept ") == 4
    assert stamps == {n: (Path(r["run"]) / "train.json").stat().st_mtime_ns for n, r in runs.items()}
    assert json.loads((work / "sim2real.json").read_text())["scores"] == doc["scores"]
    # each score row holds its report's counts at the confidence it was scored at; another confidence scores again
    for confidence in (0.25, 0.5):
        if confidence != 0.25:
            assert tool.main(args + ["--confidence", str(confidence)]) == 0
        rows = json.loads((work / "sim2real.json").read_text())["scores"]
        assert len(rows) == len(doc["scores"])
        for row in rows:
            metrics = json.loads((work / "eval" / row["run"] / row["test"] / "metrics.json").read_text())
            c = next(c for c in metrics["classes"] if c["class"] == row["class"])
            assert {k: row[k] for k in COUNTS} == {k: c[k] for k in COUNTS}
            assert row["confidence"] == metrics["confidence"] == confidence
    # kept reports whose false positives were sorted otherwise, or not at all, are scored again; the others are kept
    reports = sorted((work / "eval").glob("*/*/metrics.json"))
    for report, change in zip(reports, ("drop", "reorder")):
        old = json.loads(report.read_text())
        if change == "drop":
            del old["false_positive_kinds"]
        else:
            old["false_positive_kinds"]["kinds"].reverse()
        report.write_text(json.dumps(old))
    stamps = {r: r.stat().st_mtime_ns for r in reports[2:]}
    assert tool.main(args + ["--confidence", "0.5"]) == 0
    for report in reports[:2]:
        assert json.loads(report.read_text())["false_positive_kinds"]["kinds"] == list(FP_KINDS)
    assert stamps == {r: r.stat().st_mtime_ns for r in reports[2:]}
    assert tool.main([a if a != "4" else "8" for a in args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "a_synthetic_s0: kept from an earlier run with epochs 2 (planned 4)" in err[0], err
    # a report over those runs linked into another work folder names the sets they were trained on, not its own
    other = tmp_path / "other"
    (other / "runs").mkdir(parents=True)
    for name, r in runs.items():
        (other / "runs" / name).symlink_to(Path(r["run"]))
    assert tool.main(args[:-1] + [str(other)]) == 0
    linked = {r["name"]: r for r in json.loads((other / "sim2real.json").read_text())["runs"]}
    assert linked["d_n0001_s0"]["train_set"] == str(work / "mixed" / "n0001")
    assert linked["b_n0001_s0"]["train_set"] == str(work / "subsets" / "n0001")
    assert linked["d_n0001_s0"]["command"] == runs["d_n0001_s0"]["command"]
    assert f"`{work / 'mixed' / 'n0001'}`" in (other / "sim2real.md").read_text()
