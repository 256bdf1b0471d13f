"""``synthua stats DATASET --compare REAL`` on hand-made sets: the dataset of tiny_dataset.py (one wheelchair user in
image 1, a walker alone in image 2, image 3 rejected) against a hand-written YOLO set, every figure worked out below
by hand; the KS statistic against one computed here from the two empirical distribution functions, and its p-value
against scipy's own ks_2samp on the hand-worked samples; the same set without data.yaml, with and without
classes.txt; the command's outputs; and the real wheelchair set where ../shared holds it (box counts against its
label files, read here)."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from scipy.stats import ks_2samp

from analytics import tiny_dataset
from conftest import SHARED
from synthua_usd.analytics.dataset_index import load_index
from synthua_usd.analytics.real_comparison import compare, read_real
from synthua_usd.analytics.statistics import compute

# The real set, 40x30 images unless said. train/a.png: left half black, right half white (RMS contrast 0.5; edge
# density: columns 19 and 20 of every row read a unit step, 2/40 = 0.05), a person 6x15 px (height share 0.5,
# aspect 0.4) and a wheelchair 18x24 (0.8, 0.75). train/b.png: flat grey (0 and 0), a person 3x6 (0.2, 0.5).
# val/c.png: 20x20 flat, only a dog (a class nothing maps to).
LABELS = {"train/a": "0 0.5 0.5 0.15 0.5\n1 0.25 0.5 0.45 0.8\n", "train/b": "0 0.5 0.5 0.075 0.2\n",
          "val/c": "2 0.5 0.5 0.2 0.2\n"}
REAL = {  # (measure, class) -> values, by hand
    ("box_height_share", "all"): [0.5, 0.8, 0.2], ("box_height_share", "person"): [0.5, 0.2],
    ("box_height_share", "wheelchair"): [0.8], ("aspect_ratio", "all"): [0.4, 0.75, 0.5],
    ("aspect_ratio", "person"): [0.4, 0.5], ("aspect_ratio", "wheelchair"): [0.75],
    ("boxes_per_image", "all"): [2, 1, 0], ("boxes_per_image", "person"): [1, 1, 0],
    ("boxes_per_image", "wheelchair"): [1, 0, 0], ("rms_contrast", "all"): [0.5, 0.0, 0.0],
    ("edge_density", "all"): [0.05, 0.0, 0.0]}
# Ours (wheelchair-sets, no height floor): image 1's wheelchair box is the chair's (2, 3) 3x1 with its user's
# (0, 3) 2x1 = (0, 3) 5x1 of an 8x6 image (1/6, aspect 5); the user has no person box; image 2's walker is not
# compared; image 3 is rejected.
OURS = {("box_height_share", "all"): [1 / 6], ("box_height_share", "person"): [],
        ("box_height_share", "wheelchair"): [1 / 6], ("aspect_ratio", "all"): [5.0], ("aspect_ratio", "person"): [],
        ("aspect_ratio", "wheelchair"): [5.0], ("boxes_per_image", "all"): [1, 0],
        ("boxes_per_image", "person"): [0, 0], ("boxes_per_image", "wheelchair"): [1, 0]}


def write_real(root: Path, data_yaml: bool = True, classes_txt: bool = False) -> Path:
    for rel, text in LABELS.items():
        split, name = rel.split("/")
        size = (20, 20) if name == "c" else (30, 40)
        pixels = np.full(size + (3,), 128, np.uint8)
        if name == "a":
            pixels[:, :20], pixels[:, 20:] = 0, 255
        (root / "images" / split).mkdir(parents=True, exist_ok=True)
        (root / "labels" / split).mkdir(parents=True, exist_ok=True)
        Image.fromarray(pixels).save(root / "images" / split / f"{name}.png")
        (root / "labels" / split / f"{name}.txt").write_text(text)
    if data_yaml:
        (root / "data.yaml").write_text("path: .\ntrain: images/train\nval: images/val\nnames: [person, wheelchair, dog]\n")
    if classes_txt:
        (root / "classes.txt").write_text("person\nwheelchair\ndog\n")
    return root


def _ecdf_gap(a, b) -> float:
    """sup |F_a - F_b| over every value of either sample, the two distribution functions counted here."""
    points = sorted(set(a) | set(b))
    return max(abs(sum(v <= x for v in a) / len(a) - sum(v <= x for v in b) / len(b)) for x in points)


@pytest.fixture()
def tiny(tmp_path):
    root = tiny_dataset.write(tmp_path / "ds")
    index = load_index(root)
    return index, compute(index)


def _rows(comparison) -> dict:
    return {(r.measure, r.class_name): r for r in comparison.rows}


def _check(comparison, ours_contrast):
    rows = _rows(comparison)
    ours = dict(OURS)
    ours["rms_contrast", "all"] = [c for c, _ in ours_contrast]
    ours["edge_density", "all"] = [e for _, e in ours_contrast]
    assert set(rows) == set(REAL)
    for key, row in rows.items():
        for side, values in ((row.ours, ours[key]), (row.real, REAL[key])):
            assert side["count"] == len(values), key
            if values:
                assert side["median"] == pytest.approx(float(np.median(values)), abs=1e-12), key
        if ours[key]:
            assert row.ks_statistic == pytest.approx(_ecdf_gap(ours[key], REAL[key]), abs=1e-12), key
            assert row.ks_p_value == pytest.approx(ks_2samp(ours[key], REAL[key]).pvalue, abs=1e-12), key
        else:
            assert row.ks_statistic is None and row.ks_p_value is None


def test_the_hand_made_sets_compare_as_worked_out(tiny, tmp_path):
    index, stats = tiny
    real = read_real(write_real(tmp_path / "real"))
    assert real.split == "train+val" and len(real.images) == 3
    comparison = compare(index, stats.image_contrast, real, min_height_px=0)
    _check(comparison, list(tiny_dataset.kept_contrast_and_edges(index.root).values()))
    rows = _rows(comparison)
    assert rows["boxes_per_image", "all"].ks_statistic == pytest.approx(1 / 3)     # F: (1/2, 1) against (1/3, 2/3, 1)
    assert rows["box_height_share", "wheelchair"].ks_statistic == 1.0
    doc = comparison.document()
    assert doc["real"]["classes_not_compared"] == ["dog"] and doc["real"]["boxes"] == {"person": 2, "wheelchair": 1}
    assert doc["ours"]["boxes"] == {"person": 0, "wheelchair": 1} and doc["ours"]["images"] == 2
    assert doc["mapping"] == {"person": ["person"], "wheelchair": ["manual_wheelchair", "electric_wheelchair"]}
    assert doc["targets"]["aid_users_as_person"] is False and doc["convention"] == "wheelchair-sets"
    assert comparison.largest(1)[0].ks_statistic == 1.0


def test_the_synthua_convention_keeps_the_user_a_person(tiny, tmp_path):
    """The same sets, our boxes by the synthua convention: the wheelchair user is also a person, (0, 3) 2x1."""
    index, stats = tiny
    comparison = compare(index, stats.image_contrast, read_real(write_real(tmp_path / "real")), convention="synthua",
                         min_height_px=0)
    rows = _rows(comparison)
    assert rows["aspect_ratio", "person"].ours["median"] == 2.0
    assert rows["box_height_share", "all"].ours["count"] == 2
    assert rows["boxes_per_image", "all"].ks_statistic == pytest.approx(_ecdf_gap([2, 0], [2, 1, 0]))


def test_boxes_under_the_height_floor_are_left_out(tiny, tmp_path):
    index, stats = tiny
    comparison = compare(index, stats.image_contrast, read_real(write_real(tmp_path / "real")))   # 8 px: all of ours
    rows = _rows(comparison)
    assert rows["box_height_share", "all"].ours["count"] == 0 and rows["box_height_share", "all"].ks_statistic is None
    assert comparison.document()["ours"]["ignored_boxes_left_out"] == 1


def test_a_yolo_folder_without_data_yaml(tiny, tmp_path):
    """Named by classes.txt: as with data.yaml. Without it the classes are their indices and --map names them."""
    index, stats = tiny
    contrast = list(tiny_dataset.kept_contrast_and_edges(index.root).values())
    named = read_real(write_real(tmp_path / "named", data_yaml=False, classes_txt=True))
    assert named.names == ("person", "wheelchair", "dog") and named.split == "all"
    _check(compare(index, stats.image_contrast, named, min_height_px=0), contrast)
    bare = read_real(write_real(tmp_path / "bare", data_yaml=False))
    assert bare.names == ("0", "1", "2")
    comparison = compare(index, stats.image_contrast, bare, ("0=person", "1=manual_wheelchair,electric_wheelchair"),
                         min_height_px=0)
    rows = _rows(comparison)
    assert rows["box_height_share", "1"].real["count"] == 1 and rows["box_height_share", "1"].ours["count"] == 1
    assert rows["aspect_ratio", "0"].real["median"] == pytest.approx(0.45)
    only_train = read_real(tmp_path / "bare", split="train")
    assert len(only_train.images) == 2


def test_the_command_writes_the_comparison_everywhere(tmp_path, run_cli):
    root = tiny_dataset.write(tmp_path / "ds")
    real = write_real(tmp_path / "real")
    code, out, err = run_cli("stats", root, "--out", tmp_path / "report", "--compare", real, "--min-height-px", "0")
    assert code == 0, err
    assert "--map person=person --map wheelchair=manual_wheelchair,electric_wheelchair" in out
    line = next(s for s in out.splitlines() if s.startswith("boxes_per_image   all"))
    assert line.split()[-2:] == ["0.333", f"{ks_2samp([1, 0], [2, 1, 0]).pvalue:.2g}"]
    assert "differs most: box_height_share of all (D 1.00)" in out
    doc = json.loads((tmp_path / "report" / "statistics.json").read_text())["real_comparison"]
    by = {(m["measure"], m["class"]): m for m in doc["measures"]}
    assert by["edge_density", "all"]["real_median"] == 0.0 and by["edge_density", "all"]["real_p90"] == pytest.approx(
        np.percentile([0.05, 0, 0], 90))
    with open(tmp_path / "report" / "real_comparison.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == len(REAL) and float(rows[0]["ks_statistic"]) == 1.0
    page = (tmp_path / "report" / "report.html").read_text()
    assert "Against a real set" in page and 'src="plots/real_comparison.png"' in page
    assert (tmp_path / "report" / "plots" / "real_comparison.png").stat().st_size > 10_000


@pytest.mark.parametrize("args, found", [
    (["--map", "person=person"], "--map: given without --compare; expected --compare REAL_SET with it"),
    (["--convention", "synthua"], "--convention: given without --compare"),
    (["--compare", "REAL", "--map", "cat=person"], "'cat' is not a class of the real set"),
    (["--compare", "REAL", "--map", "person=sofa"], "sofa: not a class of the dataset's class map"),
    (["--compare", "REAL", "--map", "person"], "--map: 'person'; expected TEST_CLASS=MODEL_CLASS"),
    (["--compare", "NOWHERE"], "not found; expected an Ultralytics YOLO folder"),
    (["--compare", "REAL", "--compare-split", "test"], "test: not in the file (splits: train, val)"),
])
def test_refusals_are_one_line(tmp_path, run_cli, args, found):
    root = tiny_dataset.write(tmp_path / "ds")
    real = write_real(tmp_path / "real")
    args = [str(real) if a == "REAL" else str(tmp_path / "nowhere") if a == "NOWHERE" else a for a in args]
    code, out, err = run_cli("stats", root, "--out", tmp_path / "report", *args)
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and lines[0].startswith("synthua: error:") and found in lines[0], err
    assert not (tmp_path / "report").exists()


WHEELCHAIR_DEV = SHARED / "data" / "real_photos" / "wheelchair_dev"


@pytest.mark.skipif(not WHEELCHAIR_DEV.is_dir(), reason="../shared/data/real_photos/wheelchair_dev is not here")
def test_the_real_wheelchair_set_is_read_whole(tiny):
    """Both splits, every box: the counts per class against the label files' lines, counted here; the photos read
    in place."""
    index, stats = tiny
    real = read_real(WHEELCHAIR_DEV)
    counts = {"0": 0, "1": 0}
    for label in (WHEELCHAIR_DEV / "labels").rglob("*.txt"):
        for line in label.read_text().splitlines():
            if line.split():
                counts[line.split()[0]] += 1
    images = [p for p in (WHEELCHAIR_DEV / "images").rglob("*") if p.is_file()]
    assert real.split == "train+val" and len(real.images) == len(images)
    comparison = compare(index, stats.image_contrast, real, min_height_px=0)
    assert comparison.about["real"]["boxes"] == {"person": counts["0"], "wheelchair": counts["1"]}
    rows = _rows(comparison)
    assert rows["rms_contrast", "all"].real["count"] == len(images)
    assert 0 < rows["rms_contrast", "all"].real["median"] < 0.5
