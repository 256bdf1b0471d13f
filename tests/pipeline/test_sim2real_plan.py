"""The sim-to-real experiment's design without a detector: epochs of an image-step budget against numbers worked
out by hand, nested subsets of the real photos, the runs planned, the seeds' spread against NumPy, the report, and
tools/sim2real.py's plan (--plan-only) and one-line refusals on a hand-made YOLO set of tiny images."""

from __future__ import annotations

import json
import shlex
from pathlib import Path

import numpy as np
import pytest
import scipy.stats
from PIL import Image

from conftest import load_tool
from synthua_usd.analytics.detection_metrics import FP_KINDS
from synthua_usd.core.errors import InputError
from synthua_usd.pipeline import sim2real as S
from synthua_usd.pipeline.sim2real_report import cell, curve, markdown
from synthua_usd.pipeline.sim2real_sets import VAL_IMAGES


@pytest.mark.parametrize("budget, images, epochs, steps", [
    (7500, 50, 150, 7500),       # 150 epochs of the 50 photos: exact
    (7500, 25, 300, 7500),
    (7500, 100, 75, 7500),
    (7500, 200, 38, 7600),       # 37.5: halves round up
    (7500, 449, 17, 7633),       # 16.70 -> 17
    (7500, 450, 17, 7650),       # 50 photos + 400 composites: 16.67 -> 17
    (7500, 2000, 4, 8000),       # 3.75 -> 4
    (7500, 3001, 2, 6002),       # 2.499 -> 2
    (10, 40, 1, 40),             # 0.25 -> at least one epoch
    (1, 1, 1, 1),
])
def test_epochs_of_an_image_step_budget(budget, images, epochs, steps):
    b = S.epochs_for(budget, images)
    assert (b.epochs, b.image_steps, b.exact) == (epochs, steps, steps == budget)
    assert (b.note() is None) == (steps == budget)


def test_the_rounding_note_states_the_change():
    assert S.epochs_for(7500, 449).note() == ("7,500 image-steps / 449 images = 16.70 epochs, trained as 17: "
                                               "7,633 image-steps (+1.8 %)")
    assert S.epochs_for(10, 40).note().endswith("trained as 1: 40 image-steps (+300.0 %)")
    assert S.epochs_for(7500, 3001).note().endswith("6,002 image-steps (-20.0 %)")
    with pytest.raises(InputError, match="--budget-images: 0"):
        S.epochs_for(0, 10)


def test_lists_of_arms_seeds_and_sizes():
    assert S.parse_arms("d, b") == ("b", "d") and S.parse_arms("a,b,c,d") == tuple(S.ARMS)
    assert S.parse_seeds("2,0,1") == (2, 0, 1)
    assert S.parse_sizes("all,25,50", 449) == (25, 50, 449) and S.parse_sizes("449,all", 449) == (449,)
    for call, found in [(lambda: S.parse_arms("b,e"), "--arms: e; expected some of a (synthetic only)"),
                        (lambda: S.parse_arms("b,b"), "expected each value once"),
                        (lambda: S.parse_seeds("0,x"), "--seeds: 'x'"),
                        (lambda: S.parse_seeds("-1"), "--seeds: '-1'"),
                        (lambda: S.parse_seeds(" , "), "expected a comma-separated list"),
                        (lambda: S.parse_sizes("25,500", 449), "--real-sizes: '500'; expected numbers of real "
                                                               "training photos from 1 to 449"),
                        (lambda: S.parse_sizes("0", 449), "--real-sizes: '0'")]:
        with pytest.raises(InputError, match=found.replace("(", r"\(").replace(")", r"\)")):
            call()


def test_subsets_are_nested_seeded_and_independent_of_the_listing_order():
    names = [f"images/train/{k:03d}.jpg" for k in range(449)]
    subsets = S.nested_subsets(names, (25, 50, 100, 200, 449), seed=0)
    for small, large in zip((25, 50, 100, 200), (50, 100, 200, 449)):
        assert subsets[small] == subsets[large][:small] and set(subsets[small]) < set(subsets[large])
    assert sorted(subsets[449]) == names and len(set(subsets[449])) == 449
    # the draw: numpy's default_rng(seed).permutation over the sorted names
    order = np.random.default_rng(0).permutation(449)
    assert subsets[25] == tuple(names[k] for k in order[:25])
    assert S.nested_subsets(list(reversed(names)), (25,), seed=0)[25] == subsets[25]
    assert S.nested_subsets(names, (25,), seed=1)[25] != subsets[25]


def test_the_runs_planned_seed_by_seed():
    runs = S.plan_runs(("a", "b", "c", "d"), (25, 449), (0, 1), 7500, 30000, synthetic_images=2000,
                       mixed_images={25: 200, 449: 400})
    assert [r.name for r in runs[:7]] == ["a_synthetic_s0", "b_n0025_s0", "c_n0025_s0", "d_n0025_s0", "b_n0449_s0",
                                         "c_n0449_s0", "d_n0449_s0"]
    assert len(runs) == 14 and [r.seed for r in runs] == [0] * 7 + [1] * 7
    by = {r.name: r for r in runs}
    assert (by["a_synthetic_s0"].budget.epochs, by["a_synthetic_s0"].budget.image_steps) == (15, 30000)
    assert by["c_n0025_s1"].pretraining == "a_synthetic_s1" and by["b_n0025_s1"].pretraining is None
    assert by["c_n0025_s0"].budget == by["b_n0025_s0"].budget == S.epochs_for(7500, 25)        # (b)'s budget
    assert (by["d_n0025_s0"].budget.images, by["d_n0025_s0"].budget.epochs) == (225, 33)      # 33.33 -> 33
    assert (by["d_n0449_s0"].budget.images, by["d_n0449_s0"].budget.epochs) == (849, 9)       # 8.83 -> 9
    only_c = S.plan_runs(("c",), (50,), (0,), 7500, 7500, synthetic_images=100)
    assert [r.name for r in only_c] == ["a_synthetic_s0", "c_n0050_s0"]   # (c) needs (a)'s run


def test_the_spread_over_seeds_is_numpys():
    rng = np.random.default_rng(4)
    values = list(rng.random(5))
    s = S.spread(values + [None])                     # None: no box of the class, left out
    x = np.asarray(values)
    assert s["n"] == 5
    assert s["mean"] == pytest.approx(np.mean(x), abs=1e-15) and s["std"] == pytest.approx(np.std(x, ddof=1), abs=1e-15)
    assert (s["min"], s["max"]) == (np.min(x), np.max(x))
    assert S.spread([0.3]) == {"n": 1, "mean": 0.3, "min": 0.3, "max": 0.3, "std": None}
    assert S.spread([None])["n"] == 0 and S.spread([])["mean"] is None
    # two seeds 0.35 and 0.39: mean 0.37, sample sd |a - b| / sqrt(2)
    assert S.spread([0.35, 0.39])["std"] == pytest.approx(0.04 / np.sqrt(2))


def _scores():
    """(b) and (c) over three seeds; (a), one seed, scored before the false positives were counted."""
    rows = []
    for seed, (b, c) in enumerate([(0.35, 0.40), (0.39, 0.46), (0.31, 0.49)]):
        for arm, v in (("b", b), ("c", c)):
            fp = [10 + seed, 0, 2 * seed, 1, 0, 9 - seed] if arm == "b" else [20, 1, 5, 2, 2, 10]
            rows.append({"run": f"{arm}_n0050_s{seed}", "arm": arm, "real_images": 50, "seed": seed, "test": "dev-val",
                         "class": "wheelchair", "AP50": v, "AP50_95": v / 2, "confidence": 0.25, "tp": 30 + seed,
                         "fn": 5} | dict(zip(("fp",) + tuple(f"fp_{k}" for k in FP_KINDS), fp)))
    rows.append({"run": "a_synthetic_s0", "arm": "a", "real_images": None, "seed": 0, "test": "dev-val",
                 "class": "wheelchair", "AP50": 0.1, "AP50_95": None})
    return rows


def test_summaries_group_runs_over_seeds():
    summary = S.summarise(_scores())
    assert [(s["arm"], s["real_images"]) for s in summary] == [("b", 50), ("c", 50), ("a", None)]
    b = summary[0]
    assert b["seeds"] == [0, 1, 2]
    assert b["AP50"]["mean"] == pytest.approx(np.mean([0.35, 0.39, 0.31]))
    assert b["AP50"]["std"] == pytest.approx(np.std([0.35, 0.39, 0.31], ddof=1))
    assert b["AP50_95"]["max"] == pytest.approx(0.195)
    assert summary[2]["AP50_95"]["n"] == 0 and cell(summary[2]["AP50_95"]) == "–"
    assert cell(summary[2]["AP50"]) == "10.0"
    assert cell(b["AP50"]) == "35.0 (31.0–39.0) sd 4.0"
    assert b["fp"]["mean"] == 11 and (b["fp_other_class"]["min"], b["fp_other_class"]["max"]) == (0, 4)
    assert b["tp"]["mean"] == 31 and summary[2]["fp"]["n"] == 0          # (a)'s row holds no counts


def test_arms_against_b_with_welchs_interval_as_scipy_computes_it():
    rows = S.compare(_scores())
    # (a) has no real size, so no (b) beside it
    assert [(r["arm"], r["class"], r["real_images"]) for r in rows] == [("c", "wheelchair", 50)]
    r, c, b = rows[0], [0.40, 0.46, 0.49], [0.35, 0.39, 0.31]
    welch = scipy.stats.ttest_ind(c, b, equal_var=False)
    interval = welch.confidence_interval(0.95)
    assert r["difference"] == pytest.approx(np.mean(c) - np.mean(b))
    assert (r["low"], r["high"], r["df"]) == pytest.approx((interval.low, interval.high, welch.df))
    assert r["common_seeds"] == [0, 1, 2] and r["per_seed"] == pytest.approx([0.05, 0.07, 0.18])
    assert r["beyond"] is True and r["ranges_overlap"] is False            # 40-49 against 31-39
    # arms inside each other's spread: the interval holds zero
    mixed = [x | {"AP50": v} for x, v in zip(_scores(), [0.35, 0.30, 0.39, 0.45, 0.31, 0.38, 0.1])]
    near = S.compare(mixed)[0]
    welch = scipy.stats.ttest_ind([0.30, 0.45, 0.38], b, equal_var=False)
    assert near["low"] == pytest.approx(welch.confidence_interval(0.95).low) and near["low"] < 0 < near["high"]
    assert near["beyond"] is False and near["ranges_overlap"] is True
    # one seed of the arm: the difference, no interval; a seed without a box of the class (None) is left out
    one = S.compare([x for x in _scores() if not (x["arm"] == "c" and x["seed"] > 0)])[0]
    assert one["difference"] == pytest.approx(0.40 - np.mean(b)) and one["low"] is None and one["beyond"] is None
    none = S.compare([x | {"AP50": None} if x["arm"] == "c" and x["seed"] == 2 else x for x in _scores()])[0]
    assert none["seeds"] == [0, 1] and none["difference"] == pytest.approx(np.mean(c[:2]) - np.mean(b))
    # no spread at all: the interval is the difference itself
    flat = S.compare([x | {"AP50": 0.5 if x["arm"] == "c" else 0.3} for x in _scores() if x["arm"] != "a"])[0]
    assert (flat["low"], flat["high"], flat["df"], flat["beyond"]) == pytest.approx((0.2, 0.2, None, True))


def _document():
    runs = []
    for seed in range(3):
        runs.append({"name": "a_synthetic_s0", "arm": "a", "real_images": None, "mixed_images": 0, "seed": seed,
                     "train_set": "out/sim", "images": 2000, "epochs": 4, "image_steps": 8000, "pretraining": None,
                     "init": None, "model": "yolo26n.yaml", "seconds": 700.0, "images_per_s": 11.4, "device": "cpu",
                     "versions": {"ultralytics": "8.4.190", "torch": "2.14.1"}})
        for arm in ("b", "c"):
            runs.append({"name": f"{arm}_n0050_s{seed}", "arm": arm, "real_images": 50, "mixed_images": 0, "seed": seed,
                         "train_set": "work/subsets/n0050", "images": 50, "epochs": 150, "image_steps": 7500,
                         "pretraining": "a_synthetic_s0" if arm == "c" else None, "init": None, "model": "yolo26n.yaml",
                         "seconds": 680.0, "images_per_s": 11.0, "device": "cpu"})
    scores = _scores()
    return {"date": "2026-12-05T10:00:00+00:00", "command": "python tools/sim2real.py ...",
            "plan": {"arms": ["a", "b", "c"], "seeds": [0, 1, 2], "budget_images": 7500,
                     "synthetic_budget_images": 8000, "imgsz": 320, "batch": 16, "init": None, "model": "yolo26n.yaml",
                     "subset_seed": 0, "real_photos": 449,
                     "tests": [{"label": "dev-val", "path": "real/", "split": "val", "images": 53}]},
            "runs": runs, "scores": scores, "summary": S.summarise(scores), "comparisons": S.compare(scores),
            "notes": ["a note"]}


def test_the_markdown_and_the_curve(tmp_path):
    text = markdown(_document())
    assert "| (b) real only | 50 | 0,1,2 | 150 × 50 = 7,500 | 35.0 (31.0–39.0) sd 4.0 |" in text
    assert "| (c) synthetic, then real | 50 | 0,1,2 | 150 × 50 = 7,500 after (a)'s 8,000 |" in text
    assert "every arm from scratch (yolo26n.yaml)" in text and "(8,000 for (a))" in text and "- a note" in text
    assert ("| dev-val | wheelchair | 50 | (c) synthetic, then real | +10.0 | +5.0, +7.0, +18.0 (seeds 0,1,2) | "
            "+0.2 to +19.8 (df 3.9) | yes | no |") in text
    assert "**False positives at confidence 0.25** (IoU 0.5)" in text
    assert ("| dev-val | wheelchair | (b) real only | 50 | 31.0 (30–32) | 11.0 (10–12) | 0.0 (0–0) | 2.0 (0–4) | "
            in text)
    assert "| dev-val | wheelchair | (c) synthetic, then real | 50 | 31.0 (30–32) | 20.0 (20–20) | 1.0 (1–1) | " in text
    assert "| dev-val | wheelchair | (a)" not in text
    png = curve(_document(), tmp_path / "curve.png", ["wheelchair", "person"])
    assert png.stat().st_size > 5000 and Image.open(png).size[0] > 300
    assert curve(_document(), tmp_path / "none.png", ["bicycle"]) is None


# --- tools/sim2real.py without a detector: the plan and the refusals -------------------------------------------------

@pytest.fixture(scope="module")
def tool():
    return load_tool("sim2real.py", "sim2real_tool")


@pytest.fixture(scope="module")
def real(tmp_path_factory) -> Path:
    """A YOLO set of tiny images: train 20 (one person box each, every fourth a wheelchair too), val 3 (greys no train
    photo has)."""
    root = tmp_path_factory.mktemp("real")
    for split, count in (("train", 20), ("val", 3)):
        (root / "images" / split).mkdir(parents=True)
        (root / "labels" / split).mkdir(parents=True)
        for k in range(count):
            grey = 10 * k + (5 if split == "val" else 0)           # no val photo the same as a train photo
            Image.fromarray(np.full((48, 64, 3), grey, np.uint8)).save(root / "images" / split / f"{split}{k:02d}.png")
            lines = "0 0.5 0.5 0.25 0.5\n" + ("1 0.3 0.6 0.3 0.4\n" if k % 4 == 0 else "")
            (root / "labels" / split / f"{split}{k:02d}.txt").write_text(lines)
    (root / "data.yaml").write_text("path: .\ntrain: images/train\nval: images/val\nnames: [person, wheelchair]\n")
    return root


def test_plan_only_writes_nested_subsets_of_links(tool, real, tmp_path, capsys):
    work = tmp_path / "work"
    args = ["--real-train", str(real), "--test", str(real), "--real-sizes", "5,12,all", "--budget-images", "30",
            "--seeds", "0,1,2", "--subset-seed", "3", "--plan-only", "--work", str(work)]
    assert tool.main(args) == 0
    out = [" ".join(line.split()) for line in capsys.readouterr().out.splitlines()]
    assert "b_n0012_s0 3 epochs x 12 images = 36 image-steps, the last 0 without mosaic (30 image-steps / 12 images = 2.50 epochs, trained as " \
           "3: 36 image-steps (+20.0 %))" in out                        # 2.5: halves up
    assert "b_n0005_s2 6 epochs x 5 images = 30 image-steps, the last 0 without mosaic" in out and len(out) == 1 + 9 + 1   # no note: 3 seeds
    doc = json.loads((work / "sim2real.json").read_text())
    assert doc["plan"]["real_sizes"] == [5, 12, 20] and doc["plan"]["real_photos"] == 20
    assert doc["plan"]["tests"][0]["split"] == "val" and doc["plan"]["init"] is None
    subsets = {int(n): names for n, names in doc["subsets"].items()}
    assert subsets[5] == subsets[12][:5] and subsets[12] == subsets[20][:12] and len(set(subsets[20])) == 20
    assert subsets[12] == list(S.nested_subsets(subsets[20], (12,), 3)[12])
    assert any("b_n0012_s0: 30 image-steps / 12 images = 2.50 epochs, trained as 3: 36" in n for n in doc["notes"])
    for n, names in subsets.items():
        folder = work / "subsets" / f"n{n:04d}"
        assert json.loads((folder / "subset.json").read_text())["photos"] == names
        links = sorted((folder / "images" / "train").iterdir())
        assert [p.is_symlink() for p in links] == [True] * n                # linked, never copied
        assert [str(p.resolve().relative_to(real)) for p in links] == names   # in the draw's order
        assert len(list((folder / "images" / "val").iterdir())) == min(n, VAL_IMAGES)
        assert (folder / "labels" / "train" / "000001.txt").read_text().startswith("0 0.5000000 0.5000000")
    # another draw into the same work folder is refused: the runs kept there were trained on this one
    assert tool.main([a if a != "3" else "4" for a in args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "holds another draw" in err[0]


def test_the_help_examples_plan_only_command_runs_as_written(tool, real, tmp_path):
    """The --help's example that writes the subsets for composites (issue 45), with its paths pointed at the
    hand-made set: it once lacked --budget-images and was refused."""
    text = tool.__doc__.replace("\\\n", " ")
    line = next(line for line in text.splitlines() if "python tools/sim2real.py" in line and "--plan-only" in line)
    args = shlex.split(line.split("tools/sim2real.py", 1)[1])
    paths = {"real/": str(real), "out/s2r_45": str(tmp_path / "w"), "50": "12"}     # the set holds 20 photos
    assert tool.main([paths.get(a, a) for a in args]) == 0
    assert (tmp_path / "w" / "subsets" / "n0012" / "subset.json").is_file()


def test_refusals_are_one_line(tool, real, tmp_path, capsys):
    work = ["--work", str(tmp_path / "w"), "--plan-only"]
    base = ["--real-train", str(real), "--test", str(real)]
    cases = [
        (base, "--budget-images: not given; expected the image-steps"),
        (base + ["--budget-images", "10", "--arms", "d"], "--arms d: arm d (real + mixed set) needs --real-train and --mix"),
        (base + ["--budget-images", "10", "--arms", "a"], "arm a (synthetic only) needs --synthetic"),
        (base + ["--budget-images", "10", "--real-sizes", "30"], "--real-sizes: '30'; expected numbers of real training "
                                                               "photos from 1 to 20"),
        (base + ["--budget-images", "10", "--seeds", "0,one"], "--seeds: 'one'"),
        (base + ["--budget-images", "10", "--imgsz", "100"], "multiple of 32"),
        (["--real-train", str(real), "--test", str(real / "data.yaml"), "--budget-images", "10", "--real-sizes", "5",
          "--mix", "6=" + str(real)], "--mix 6="),
        (["--real-train", str(real), "--budget-images", "10"], "--test: none given"),
        (base + ["--budget-images", "10", "--init", str(tmp_path / "yolo11n.pt")], "--init: "),
        (base + ["--budget-images", "10", "--bogus"], "unrecognized arguments: --bogus"),
    ]
    for args, found in cases:
        assert tool.main(args + work) == 2, args
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("synthua: error:") and found in err[0], (found, err)
    # a test set that shares photos with the training photos is no test
    (tmp_path / "leak").mkdir()
    (tmp_path / "leak" / "data.yaml").write_text(f"path: {real}\ntest: images/train\nnames: [person, wheelchair]\n")
    assert tool.main(["--real-train", str(real), "--test", str(tmp_path / "leak"), "--budget-images", "10"] + work) == 2
    assert "20 of its 20 images are among the real training photos" in capsys.readouterr().err


@pytest.mark.parametrize("budget, images, epochs, closed", [
    (7500, 50, 150, 10),         # Ultralytics' default 10 of 150: the 50-photo real arm as it was
    (7500, 450, 17, 1),          # 50 photos + 400 composites: 1.13 -> 1, not 10 of 17
    (7500, 25, 300, 20),
    (7500, 2000, 4, 0),          # 0.27 -> 0: mosaic to the end
    (10, 40, 1, 0),
])
def test_every_arm_closes_mosaic_for_the_same_share_of_its_epochs(budget, images, epochs, closed):
    b = S.epochs_for(budget, images)
    assert (b.epochs, b.close_mosaic) == (epochs, closed)
    assert S.epochs_for(budget, images, 0.0).close_mosaic == 0 and S.epochs_for(budget, images, 1.0).close_mosaic == epochs
    with pytest.raises(InputError, match="--close-mosaic-share: 1.5"):
        S.epochs_for(budget, images, 1.5)
    runs = S.plan_runs(("b", "d"), (50,), (0,), 7500, 7500, None, {50: 400})
    assert [(r.name, r.budget.epochs, r.budget.close_mosaic) for r in runs] == [("b_n0050_s0", 150, 10),
                                                                              ("d_n0050_s0", 17, 1)]


def test_held_back_photos_are_the_draws_rest(tool, real, tmp_path, capsys):
    """--held-back: the real training photos after the largest subset in the draw become a test set of links, read
    and scored as every --test; all photos trained on leaves none and is refused."""
    work = tmp_path / "work"
    args = ["--real-train", str(real), "--test", str(real), "--held-back", "--real-sizes", "5,12", "--budget-images",
            "30", "--plan-only", "--work", str(work)]
    assert tool.main(args) == 0
    doc = json.loads((work / "sim2real.json").read_text())
    val, held = doc["plan"]["tests"]
    trained = {Path(n).name for n in doc["subsets"]["12"]}
    expected = sorted({p.name for p in (real / "images" / "train").iterdir()} - trained)
    assert len(expected) == 8 and held["label"] == f"{real.name}-held-back" and held["split"] == "test"
    links = sorted((work / "held_back" / "images" / "test").iterdir())
    assert sorted(p.resolve().name for p in links) == expected and all(p.is_symlink() for p in links)
    wheelchairs = sum(int(name[5:7]) % 4 == 0 for name in expected)          # the fixture: every fourth photo
    assert held["images"] == 8 and held["boxes"] == {"person": 8, "wheelchair": wheelchairs}
    assert val["label"] == f"{real.name}-val" and val["images"] == 3
    capsys.readouterr()
    assert tool.main([a if a != "5,12" else "5,all" for a in args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--held-back: all 20 real training photos are trained on" in err[0], err


def test_no_composite_into_a_test_photo_is_trained_on(tool, real, tmp_path, run_cli, capsys):
    """A --mix set of composites is refused when any of its backgrounds (by SHA-256) is a photo of a test set: the
    --test's, or a held-back one; composites into the photos trained on are taken."""
    from bank_maker import write_bank

    write_bank(tmp_path / "bank")
    (tmp_path / "config.json").write_text(json.dumps({
        "output": {"width": 64, "height": 48}, "images_per_background": 1,
        "background_labels": {"classes": {"wheelchair": "manual_wheelchair"}},
        "split": {"train": 1.0, "val": 0.0, "test": 0.0}}))          # every composite trained on (--mix-split train)
    for name, split in (("into_val", "val"), ("into_train", "train")):
        code, out, err = run_cli("composite", real, "--bank", tmp_path / "bank", "--config", tmp_path / "config.json",
                                 "--split", split, "--out", tmp_path / name, "--workers", "1")
        assert code == 0, out + err
    base = ["--real-train", str(real), "--test", str(real), "--arms", "d", "--budget-images", "10", "--plan-only"]
    cases = [
        (base + ["--mix", str(tmp_path / "into_val"), "--work", str(tmp_path / "w1")],
         f"--mix {tmp_path / 'into_val'}: 3 of its composites' backgrounds are photos of the test set {real.name}-val"),
        (base + ["--mix", str(tmp_path / "into_train"), "--real-sizes", "5", "--held-back", "--work",
                 str(tmp_path / "w2")],
         f"--mix {tmp_path / 'into_train'}: 15 of its composites' backgrounds are photos of the test set "
         f"{real.name}-held-back"),
    ]
    for args, found in cases:
        assert tool.main(args) == 2, args
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith(f"synthua: error: {found} (e.g. images/"), err
        assert err[0].endswith("); expected composites into training photos only"), err
    assert not (tmp_path / "w2" / "held_back").exists()          # refused before anything is written
    assert tool.main(base + ["--mix", str(tmp_path / "into_train"), "--work", str(tmp_path / "w3")]) == 0
