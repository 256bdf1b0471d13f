#!/usr/bin/env python
"""Sim-to-real experiments (a benchmark, not a test): one detector, one budget in image-steps, several seeds.

Arms, each selectable (--arms), each starting from the same weights (--init; default from scratch), each trained once
per seed (--seeds):
  (a) synthetic only: a dataset `synthua generate` wrote (--synthetic; boxes by --convention, default wheelchair-sets);
  (b) real only: the real training photos (--real-train), or nested subsets of them (--real-sizes);
  (c) synthetic, then real: (a)'s run of the same seed fine-tuned on (b)'s photos with (b)'s budget;
  (d) real + another labelled set (--mix: composites of aid users into those photos, a `synthua composite` dataset
      or any YOLO set) mixed in one training.

The budget is image-steps (epochs x training images), the same for every arm: --budget-images 7500 trains 150 epochs
of 50 photos, 17 of 449 (7633 image-steps: rounding is said). Minutes drift 15-25 % between runs on a shared machine;
image-steps do not. The real photos are drawn once (--subset-seed) in a seeded order; a subset of n photos is the
first n of it, so the subsets are nested and the same for every arm and seed (written under WORK/subsets/, with their
photo lists, before any training: --plan-only stops there, e.g. to composite aid users into a subset for arm d).
Every model is scored by `synthua evaluate-real` on each --test (its test split, else val; the first is the one of
the plot), with --held-back also on the real training photos that no subset holds (WORK/held_back: with 50 of 449
photos trained on, 399 more test photos), and (a) also on the generated dataset's held-out split. No test photo may
be trained on: neither among the training photos or a --mix set, nor the background of a --mix set's composites.
Outputs under --work: sim2real.md (per test set, arm and real size: AP50 and AP50-95 per class as the mean over
seeds, min-max and sample standard deviation; every arm against (b): the difference of the AP50 means, seed by seed,
its 95 % interval by Welch's t and whether that lies above zero, beyond the seeds' spread; the false positives at
--confidence by what they land on: duplicates, another class's box, nothing labelled; every run), sim2real.json
(every run's `synthua train` command, seed, epochs, image-steps, seconds, device and initial weights; every score;
the comparisons) and sim2real.png (AP50 against real photos, one line per arm, the seeds' min-max shaded).
Finished runs are kept: run the same command again to resume, or to score more test sets.

Examples:
  # issue 40's low-data curve, 3 seeds, on the CPU (see docs/statistics.md for what it costs)
  nice -n 10 python tools/sim2real.py --synthetic out/sim2real --real-train real/ --test real/ \\
      --real-sizes 25,50,100,200,all --budget-images 7500 --seeds 0,1,2 --arms a,b,c --work out/s2r_curve
  # issue 45: the 50 photos alone against the 50 plus composites into them, from a COCO-pretrained checkpoint
  # (from scratch on the CPU, 7,500 image-steps left the 50 photos' detector undertrained: compare at 15,000 or more)
  python tools/sim2real.py --real-train real/ --test real/ --real-sizes 50 --budget-images 15000 --plan-only \\
      --work out/s2r_45
  synthua composite out/s2r_45/subsets/n0050 --bank out/bank --config configs/composite.json --out out/comp50
  python tools/sim2real.py --real-train real/ --test real/ --real-sizes 50 --arms b,d --mix 50=out/comp50 \\
      --budget-images 15000 --seeds 0,1,2 --init ~/weights/yolo11n.pt --device cuda --work out/s2r_45
"""

from __future__ import annotations

import argparse
import json
import os
import shlex
import shutil
import sys
import tempfile
import time
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from synthua_usd.analytics.detection_metrics import FP_RULES  # noqa: E402
from synthua_usd.analytics.detection_sets import DetectionSet  # noqa: E402
from synthua_usd.analytics.detection_sources import detect_format, read_detection_set, set_id  # noqa: E402
from synthua_usd.analytics.detection_targets import targets_for  # noqa: E402
from synthua_usd.pipeline.detector.runner import find_detector_python  # noqa: E402
from synthua_usd.cli.failures import tool_main  # noqa: E402
from synthua_usd.core.atomic import write_json_atomic, write_text_atomic  # noqa: E402
from synthua_usd.core.errors import InputError  # noqa: E402
from synthua_usd.model import detection_limits as L  # noqa: E402
from synthua_usd.model.box_conventions import CONVENTIONS  # noqa: E402
from synthua_usd.pipeline import sim2real as S  # noqa: E402
from synthua_usd.pipeline.evaluate_real import EvaluateRequest, evaluate_real  # noqa: E402
from synthua_usd.pipeline.init_weights import describe, inspect_checkpoint, locate_init  # noqa: E402
from synthua_usd.pipeline.sim2real_report import curve, markdown  # noqa: E402
from synthua_usd.dataset.manifest import sha256_file  # noqa: E402
from synthua_usd.pipeline.sim2real_sets import (  # noqa: E402
    composite_backgrounds, photo_names, renamed_mix, stand_in, write_test_folder, write_training_folder)
from synthua_usd.pipeline.train import Budget, TrainRequest, train  # noqa: E402

class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line and exit 2 (main), the house's way
        raise InputError(f"{message}; expected the options of `python tools/sim2real.py --help`")


def _train_command(train_set: Path, out: Path, budget: Budget, seed: int, device: str, init: Path | None,
                   convention: str | None) -> str:
    parts = ["synthua", "train", str(train_set)] + (["--convention", convention] if convention else [])
    parts += ["--epochs", str(budget.epochs), "--close-mosaic", str(budget.close_mosaic), "--imgsz", str(budget.imgsz), "--batch", str(budget.batch),
              "--seed", str(seed), "--device", device] + (["--init", str(init)] if init else []) + ["--out", str(out)]
    return shlex.join(parts)


def _check_kept(out: Path, about: dict, expected: dict) -> None:
    # a run from before close_mosaic was recorded trained with Ultralytics' default, 10
    found = {"epochs": about["budget"]["epochs"], "close_mosaic": about["budget"].get("close_mosaic", 10),
             "imgsz": about["budget"]["imgsz"], "batch": about["budget"]["batch"],
             "seed": about["seed"], "images": about["train_set"]["images"]["train"],
             "init": (about.get("init") or {}).get("sha256")}
    if found != expected:
        diff = ", ".join(f"{k} {found[k]} (planned {expected[k]})" for k in expected if found[k] != expected[k])
        raise InputError(f"{out}: kept from an earlier run with {diff}; expected the planned run: give a new --work "
                         f"or remove that folder")


def _score(run_name: str, run: Path, test: dict, work: Path, maps: list[str], args) -> dict:
    """evaluate-real of one run on one test set, kept when the same model was scored on the same set at the same
    confidence before, its false positives sorted by the rules of this version."""
    out = work / "eval" / run_name / test["label"]
    about = json.loads((run / "train.json").read_text(encoding="utf-8"))
    kept = out / "metrics.json"
    if kept.is_file():
        doc = json.loads(kept.read_text(encoding="utf-8"))
        if (doc["model"]["train"] == about and doc["test_set"]["sha256"] == test["sha256"]
                and doc["confidence"] == args.confidence and doc.get("false_positive_kinds") == FP_RULES):
            return doc
    request = EvaluateRequest(run, test["path"], out, tuple(maps), split=test["split"], confidence=args.confidence,
                              device=args.device, python=args.python)
    result = evaluate_real(request)
    return result.document


def _parse(argv):
    p = _Parser(prog="tools/sim2real.py", description=__doc__.split("\n\n")[0], epilog=__doc__.split("\n\n", 1)[1],
                formatter_class=argparse.RawDescriptionHelpFormatter)
    data = p.add_argument_group("data")
    data.add_argument("--synthetic", type=Path, metavar="DATASET",
                      help="dataset `synthua generate` wrote: arms a and c")
    data.add_argument("--synthetic-split", default="test", metavar="SPLIT",
                      help="held-out split of --synthetic that (a) is scored on too; 'none' for none [test]")
    data.add_argument("--convention", choices=list(CONVENTIONS), default="wheelchair-sets",
                      help="box convention of generated sets (--synthetic, a generated --mix, --stand-in) "
                           "[wheelchair-sets: the seated user inside the wheelchair's box, no person box]")
    data.add_argument("--real-train", type=Path, metavar="PATH",
                      help="real training photos, a YOLO folder (its train split) or COCO .json: arms b, c, d")
    data.add_argument("--test", type=Path, action="append", default=[], metavar="PATH",
                      help="real test set (YOLO folder: its test split, else val; or COCO .json); repeat for more; "
                           "the first is the plot's")
    data.add_argument("--held-back", action="store_true",
                      help="also score every run on the real training photos that no trained subset holds (those "
                           "after the largest --real-sizes in the draw; written under WORK/held_back as a YOLO folder "
                           "of links): a test set many times the val split's where labelled photos are few")
    data.add_argument("--mix", action="append", default=[], metavar="[SIZE=]PATH",
                      help="arm d's other labelled set (a `synthua composite` dataset or any YOLO set), mixed with "
                           "the real photos; SIZE= gives the set of one real size (e.g. 50=out/comp50), "
                           "else it goes with every size")
    data.add_argument("--mix-split", default="train", metavar="SPLIT",
                      help="split of the --mix sets trained on [train]")
    data.add_argument("--mix-map", action="append", default=[], metavar="REAL=MIX[,MIX...]",
                      help="which classes of --mix count as which real class [same names, and "
                           "wheelchair=manual_wheelchair,electric_wheelchair]")
    data.add_argument("--map", dest="maps", action="append", default=[], metavar="TEST=OURS[,OURS...]",
                      help="--map of evaluate-real for (a), whose classes are the generated set's [same names, and "
                           "wheelchair=manual_wheelchair,electric_wheelchair]")
    data.add_argument("--stand-in", type=Path, metavar="DATASET",
                      help="no real photos at hand: another generated dataset exported as a 'real' YOLO set with "
                           "classes person and wheelchair (its train split as --real-train, its test split as --test)")
    data.add_argument("--stand-in-test-split", default="test", metavar="SPLIT",
                      help="the stand-in's split used as --test [test]")
    plan = p.add_argument_group("the experiment")
    plan.add_argument("--arms", metavar="LIST", help="some of a,b,c,d [those whose data is given]")
    plan.add_argument("--budget-images", type=int, metavar="N", help="image-steps (epochs x images) of every training, "
                      "e.g. 7500 = 150 epochs of 50 photos (required)")
    plan.add_argument("--synthetic-budget-images", type=int, metavar="N",
                      help="image-steps of (a), which is also (c)'s pretraining [--budget-images]")
    plan.add_argument("--close-mosaic-share", type=float, default=S.CLOSE_MOSAIC_SHARE, metavar="F",
                      help="share of every arm's epochs trained without mosaic augmentation at the end (Ultralytics' "
                           "close_mosaic is an epoch count: 10 epochs are 7 %% of 150 epochs of 50 photos but 59 %% of "
                           "17 epochs of 450 images) [1/15: the 10 of 150]")
    plan.add_argument("--seeds", default="0,1,2", metavar="LIST",
                      help="training seeds, each arm once per seed; at least 3 for figures to quote [0,1,2]")
    plan.add_argument("--real-sizes", default=S.ALL, metavar="LIST",
                      help="real training photos per run: nested subsets, e.g. 25,50,100,200,all [all]")
    plan.add_argument("--subset-seed", type=int, default=0, metavar="N", help="seed of the draw of the subsets [0]")
    plan.add_argument("--init", type=Path, metavar="PATH",
                      help="initial weights of every arm: an Ultralytics checkpoint (.pt, e.g. a COCO-pretrained "
                           "yolo11n.pt) or a `synthua train` run [from scratch: yolo26n.yaml]")
    plan.add_argument("--imgsz", type=int, default=L.DEFAULT_IMGSZ, help=f"[{L.DEFAULT_IMGSZ}]")
    plan.add_argument("--batch", type=int, default=L.DEFAULT_BATCH, help=f"[{L.DEFAULT_BATCH}]")
    plan.add_argument("--device", choices=L.DEVICES, default="auto", help="passed to the detector [auto]")
    plan.add_argument("--python", type=Path, metavar="PYTHON",
                      help="interpreter holding Ultralytics [$SYNTHUA_TRAIN_PYTHON, else .venv-train/bin/python]")
    out = p.add_argument_group("output")
    out.add_argument("--work", type=Path, metavar="DIR", default=REPO / "out" / "sim2real_bench",
                     help="[out/sim2real_bench]")
    out.add_argument("--confidence", type=float, default=L.DEFAULT_CONFIDENCE,
                     help="of precision, recall and the false-positive counts [0.25]")
    out.add_argument("--plot-classes", default="wheelchair,person", metavar="LIST", help="classes of the plot [wheelchair,person]")
    out.add_argument("--table", type=Path, metavar="MD", help="also write the markdown here (e.g. docs/measured/...)")
    out.add_argument("--plot", type=Path, metavar="PNG", help="also write the plot here")
    out.add_argument("--plan-only", action="store_true",
                     help="write the subsets (and mixed sets), print the plan, train nothing")
    return p.parse_args(argv)


def _arms(args) -> tuple[str, ...]:
    given = {"a": args.synthetic, "b": args.real_train, "c": args.synthetic and args.real_train,
             "d": args.real_train and args.mix}
    if args.arms is None:
        arms = tuple(a for a in S.ARMS if given[a])
        if not arms:
            raise InputError("--synthetic, --real-train: none given; expected the data of an arm (see --help)")
        return arms
    arms = S.parse_arms(args.arms)
    needs = {"a": "--synthetic", "b": "--real-train", "c": "--synthetic and --real-train", "d": "--real-train and --mix"}
    for a in arms:
        if not given[a]:
            raise InputError(f"--arms {a}: arm {a} ({S.ARMS[a]}) needs {needs[a]}; expected them given, or other arms")
    return arms


def _mix_paths(values: list[str], sizes: tuple[int, ...], available: int) -> dict[int, Path]:
    general, by_size = None, {}
    for value in values:
        left, sep, right = value.partition("=")
        if sep and (left.isdigit() or left == S.ALL):
            n = available if left == S.ALL else int(left)
            if n not in sizes or n in by_size:
                raise InputError(f"--mix {value}: size {left}; expected each one of --real-sizes "
                                 f"({', '.join(map(str, sizes))}) once")
            by_size[n] = Path(right)
        elif general is None:
            general = Path(value)
        else:
            raise InputError(f"--mix {value}: a second set for every size; expected one, or SIZE=PATH per size")
    missing = [n for n in sizes if n not in by_size and general is None]
    if missing:
        raise InputError(f"--mix: no set for {', '.join(map(str, missing))} real photos; expected PATH or SIZE=PATH "
                         f"for every --real-sizes")
    return {n: by_size.get(n, general) for n in sizes}


def _test_entry(path: Path, split: str | None, label: str, targets) -> dict:
    fmt = detect_format(path)
    split = split or ("test" if fmt == "synthua" else None)
    dataset = read_detection_set(path, fmt, split, targets=targets)
    return {"label": label, "path": str(path), "split": dataset.split, "images": len(dataset.images),
            "sha256": set_id(dataset), "boxes": dataset.counts(), "_paths": {Path(im.path).resolve() for im in dataset.images}}


def _label(path: Path, split: str | None, taken: set[str]) -> str:
    name = path.parent.name if path.suffix.lower() in (".yaml", ".yml") else path.stem if path.is_file() else path.name
    label = f"{name}-{split}" if split else name
    while label in taken:
        label += "+"
    taken.add(label)
    return label


def _no_overlap(test: dict, training: set[Path], what: str) -> None:
    shared = test["_paths"] & training
    if shared:
        hint = (", or --held-back to score on the training photos no subset holds"
                if what.startswith("the real training photos") else "")
        raise InputError(f"--test {test['path']}: {len(shared)} of its {test['images']} images are among {what} (e.g. "
                         f"{sorted(shared)[0].name}); expected a held-out test set{hint}")


def _no_background(test: dict, backgrounds: dict[str, str], mix: Path) -> None:
    """Refuse a mixed set whose composites were made into photos of a test set (the same bytes, by SHA-256)."""
    if not backgrounds:
        return
    if "_sha256" not in test:                 # hashed once, whatever the number of mixed sets
        test["_sha256"] = {sha256_file(p) for p in test["_paths"]}
    shared = sorted(backgrounds[h] for h in test["_sha256"] & backgrounds.keys())
    if shared:
        raise InputError(f"--mix {mix}: {len(shared)} of its composites' backgrounds are photos of the test set "
                         f"{test['label']} (e.g. {shared[0]}); expected composites into training photos only")


def _held_back(got: "Inputs", args, work: Path, taken: set[str]) -> dict:
    """The real training photos after the largest subset in the draw (none of them trained on), as a test entry
    still to be written (:func:`_write_held_back`): its label, folder, photos and their paths."""
    largest = got.sizes[-1]
    names = list(S.draw_order(list(got.photos), args.subset_seed)[largest:])
    if not names:
        raise InputError(f"--held-back: all {len(got.photos)} real training photos are trained on (--real-sizes "
                         f"{args.real_sizes}); expected a largest size below {len(got.photos)}")
    return {"label": _label(args.real_train, "held-back", taken), "path": str(work / "held_back"),
            "images": len(names), "_names": names, "_paths": {Path(got.photos[p].path).resolve() for p in names}}


def _write_held_back(entry: dict, got: "Inputs", args, targets) -> dict:
    """Write the held-back photos' test folder (links) and read it back as every --test is read."""
    names = entry["_names"]
    about = {"real_train": str(args.real_train), "real_sha256": set_id(got.real), "subset_seed": args.subset_seed,
             "held_back_after": got.sizes[-1], "photos": names}
    folder = write_test_folder(Path(entry["path"]), [got.photos[p] for p in names], got.real.names, about)
    return _test_entry(folder, None, entry["label"], targets)


def _write_outputs(document: dict, work: Path, args) -> None:
    write_json_atomic(work / "sim2real.json", document, indent=1)
    text = markdown(document)
    write_text_atomic(work / "sim2real.md", text)
    if args.table:
        args.table.parent.mkdir(parents=True, exist_ok=True)
        write_text_atomic(args.table, text)
    real_runs = any(r["arm"] != "a" for r in document["runs"])
    if document["summary"] and real_runs:
        classes = [c.strip() for c in args.plot_classes.split(",") if c.strip()]
        png = curve(document, work / "sim2real.png", classes)
        if png is not None and args.plot:
            args.plot.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(png, args.plot)


@dataclass
class Inputs:
    """What the experiment reads before it trains: the real training photos (by relative name), their nested
    subsets, the test sets, the synthetic set's size, the mixed sets and the initial weights."""

    real: DetectionSet | None = None
    photos: dict = field(default_factory=dict)
    sizes: tuple[int, ...] = ()
    subsets: dict = field(default_factory=dict)
    tests: list[dict] = field(default_factory=list)
    synthetic_images: int | None = None
    mix_paths: dict = field(default_factory=dict)
    mixes: dict = field(default_factory=dict)
    init: object = None


def read_inputs(args, arms: tuple[str, ...], targets, work: Path) -> Inputs:
    """Read and check every input (in one line on failure) before anything is written or trained (the held-back
    photos' folder of links last, once every check has passed)."""
    got = Inputs()
    if any(a in arms for a in S.REAL_ARMS):
        got.real = read_detection_set(args.real_train, "auto", "train", targets=targets)
        got.photos = photo_names(got.real)
        got.sizes = S.parse_sizes(args.real_sizes, len(got.photos))
        got.subsets = S.nested_subsets(list(got.photos), got.sizes, args.subset_seed)
    taken: set[str] = set()
    for path in args.test:
        entry = _test_entry(path, None, "", targets)
        entry["label"] = _label(path, entry["split"], taken)
        if got.real is not None:
            _no_overlap(entry, {Path(im.path).resolve() for im in got.real.images},
                        f"the real training photos ({args.real_train})")
        got.tests.append(entry)
    if args.held_back:
        if got.real is None:
            raise InputError("--held-back: no arm trains on real photos; expected arm b, c or d (--real-train)")
        got.tests.append(_held_back(got, args, work, taken))
    if got.real is not None and not got.tests:
        raise InputError("--test: none given; expected a real test set (or --held-back) to score the arms trained "
                         "on real photos")
    if "a" in arms or "c" in arms:
        got.synthetic_images = len(read_detection_set(args.synthetic, "auto", "train", targets=targets).images)
        if "a" in arms and args.synthetic_split != "none":
            entry = _test_entry(args.synthetic, args.synthetic_split, "", targets)
            entry["label"], entry["only"] = _label(args.synthetic, entry["split"], taken), "a"
            got.tests.append(entry)
    if "d" in arms:
        got.mix_paths = _mix_paths(args.mix, got.sizes, len(got.photos))
        for path in dict.fromkeys(got.mix_paths.values()):
            got.mixes[path] = renamed_mix(path, args.mix_split, got.real.names, args.mix_map, args.convention)
            backgrounds = composite_backgrounds(path, args.mix_split)
            for t in got.tests:
                if t.get("only", "d") != "d":
                    continue
                _no_overlap(t, {Path(im.path).resolve() for im in got.mixes[path].images}, f"the mixed set {path}")
                _no_background(t, backgrounds, path)
    got.init = locate_init(args.init)
    if got.init.kind == "checkpoint" and not args.plan_only:     # inspected once for every run
        with tempfile.TemporaryDirectory(prefix="sim2real-inspect-") as scratch:
            got.init = inspect_checkpoint(got.init, find_detector_python(args.python), Path(scratch))
    got.tests = [_write_held_back(t, got, args, targets) if "_names" in t else t for t in got.tests]   # checks passed
    return got


def write_folders(got: Inputs, args, arms: tuple[str, ...], work: Path) -> dict:
    """The training folders of arms b and c (``subsets/nNNNN``) and d (``mixed/nNNNN``), by (arm, size)."""
    folders = {}
    for n in got.sizes:
        about = {"real_train": str(args.real_train), "real_sha256": set_id(got.real), "subset_seed": args.subset_seed,
                 "size": n, "photos": list(got.subsets[n])}
        chosen = [got.photos[p] for p in got.subsets[n]]
        folders[("b", n)] = write_training_folder(work / "subsets" / f"n{n:04d}", chosen, got.real.names, about)
        if "d" in arms:
            mix = got.mixes[got.mix_paths[n]]
            folders[("d", n)] = write_training_folder(
                work / "mixed" / f"n{n:04d}", chosen + list(mix.images), got.real.names,
                about | {"mix": str(got.mix_paths[n]), "mix_split": args.mix_split, "mix_sha256": set_id(mix)})
    return folders


def plan_document(args, arms, seeds, got: Inputs, command: str, work: Path, notes: list[str]) -> dict:
    init = got.init
    return {
        "date": datetime.now(timezone.utc).isoformat(timespec="seconds"), "command": command, "work": str(work),
        "plan": {"arms": list(arms), "seeds": list(seeds), "real_sizes": list(got.sizes),
                 "real_photos": len(got.photos), "real_train": str(args.real_train) if got.real is not None else None,
                 "subset_seed": args.subset_seed, "budget_images": args.budget_images,
                 "synthetic_budget_images": args.synthetic_budget_images or args.budget_images,
                 "synthetic": str(args.synthetic) if args.synthetic else None,
                 "synthetic_images": got.synthetic_images, "convention": args.convention, "imgsz": args.imgsz,
                 "batch": args.batch, "device": args.device, "init": init.document(), "model": init.architecture,
                 "mix": {str(n): str(p) for n, p in got.mix_paths.items()},
                 "mix_images": {str(n): len(got.mixes[p].images) for n, p in got.mix_paths.items()},
                 "tests": [{k: v for k, v in t.items() if not k.startswith("_")} for t in got.tests]},
        "subsets": {str(n): list(got.subsets[n]) for n in got.sizes},
        "notes": notes, "runs": [], "scores": [], "summary": [], "comparisons": [],
    }


def _trained_on(train_set: dict) -> tuple[Path, bool]:
    """The set a run was trained on, as its train.json records it (for a run linked from another work folder, that
    folder's set, not this one's), and whether it was read as a generated dataset. A YOLO data.yaml is named by its
    folder, unless that folder is a generated dataset (read another way)."""
    source = Path(train_set["source"])
    if train_set["layout"] == "yolo" and source.name == "data.yaml" and not (source.parent / "manifest.json").is_file():
        source = source.parent
    return source, train_set["layout"] == "synthua"


def _where(path: Path) -> Path:
    """``path`` where it really is when links lead there (a run linked from another work folder, or a linked runs
    folder), else as given. (Start weights are resolved already: :func:`locate_init`.)"""
    real = Path(os.path.realpath(path))
    return real if real != Path(os.path.abspath(path)) else path


def train_one(planned: S.PlannedRun, args, got: Inputs, folders: dict, work: Path, targets) -> dict:
    """Train one planned run (or keep it when trained before with the same plan); its record."""
    out = work / "runs" / planned.name
    budget = Budget(minutes=None, epochs=planned.budget.epochs, imgsz=args.imgsz, batch=args.batch,
                    close_mosaic=planned.budget.close_mosaic)
    if planned.arm == "a":
        train_set, start = args.synthetic, got.init
    else:
        train_set = folders[("d" if planned.arm == "d" else "b", planned.real_images)]
        start = locate_init(work / "runs" / planned.pretraining) if planned.arm == "c" else got.init
    expected = {"epochs": planned.budget.epochs, "close_mosaic": planned.budget.close_mosaic, "imgsz": args.imgsz,
                "batch": args.batch, "seed": planned.seed,
                "images": planned.budget.images, "init": start.sha256}
    wall = None
    if (out / "train.json").is_file():               # a finished run is kept: rerun to resume or to rescore
        about = json.loads((out / "train.json").read_text(encoding="utf-8"))
        _check_kept(out, about, expected)
        print(f"sim2real: kept {planned.name} (trained before)", flush=True)
    else:
        print(f"sim2real: training {planned.name} ...", flush=True)
        t = time.perf_counter()
        about = train(TrainRequest(train_set, out, budget, targets, init=start, device=args.device,
                                   seed=planned.seed, python=args.python))
        wall = round(time.perf_counter() - t, 1)
    trained_on, generated = _trained_on(about["train_set"])
    b = planned.budget
    return {"name": planned.name, "arm": planned.arm, "real_images": planned.real_images,
            "mixed_images": planned.mixed_images, "seed": planned.seed, "train_set": str(trained_on),
            "images": b.images, "epochs": b.epochs, "close_mosaic": b.close_mosaic, "image_steps": b.image_steps, "budget_images": b.budget_images,
            "rounding": b.note(), "pretraining": planned.pretraining,
            "command": _train_command(trained_on, _where(out), budget, planned.seed, args.device,
                                      start.weights if start.kind != "scratch" else None,
                                      args.convention if generated else None),
            "init": about["init"], "model": about["model"], "epochs_done": about["epochs_done"],
            "seconds": about["seconds"], "wall_s": wall,
            "images_per_s": round(b.image_steps / about["seconds"], 2) if about["seconds"] else None,
            "device": about["device"], "versions": about["versions"], "downloaded": about["downloaded"],
            "network": about.get("network"), "run": str(out)}


def score_one(planned: S.PlannedRun, record: dict, args, tests: list[dict], work: Path) -> list[dict]:
    """Score rows of one run on every test set it is scored on (per class)."""
    rows = []
    for test in tests:
        if test.get("only", planned.arm) != planned.arm:
            continue
        doc = _score(planned.name, Path(record["run"]), test, work, args.maps if planned.arm == "a" else [], args)
        rows += [{"run": planned.name, "arm": planned.arm, "real_images": planned.real_images, "seed": planned.seed,
                  "test": test["label"], "class": c["class"], "boxes": c["boxes"], "AP50": c["AP50"],
                  "AP50_95": c["AP50_95"], "precision": c["precision"], "recall": c["recall"],
                  "confidence": doc["confidence"]} | {k: c[k] for k in S.COUNTS}
                 for c in doc["classes"]]
    return rows


def run(argv: list[str] | None) -> int:
    args = _parse(argv)
    t0 = time.perf_counter()
    command = shlex.join(["python", "tools/sim2real.py"] + (sys.argv[1:] if argv is None else list(argv)))
    work = args.work.absolute()
    if args.stand_in:
        args.real_train, stand_test = stand_in(args.stand_in, work / "stand_in", args.stand_in_test_split,
                                               args.convention)
        args.test = [stand_test] + args.test
    arms = _arms(args)
    if args.budget_images is None or args.budget_images < 1:
        given = "not given" if args.budget_images is None else args.budget_images
        raise InputError(f"--budget-images: {given}; expected the image-steps (epochs x images) of every "
                         f"training, e.g. 7500 = 150 epochs of 50 photos")
    seeds = S.parse_seeds(args.seeds)
    Budget(minutes=None, epochs=1, imgsz=args.imgsz, batch=args.batch)           # checks imgsz and batch now
    targets = targets_for(args.convention)
    got = read_inputs(args, arms, targets, work)
    folders = write_folders(got, args, arms, work)
    runs = S.plan_runs(arms, got.sizes, seeds, args.budget_images, args.synthetic_budget_images or args.budget_images,
                       got.synthetic_images, {n: len(got.mixes[p].images) for n, p in got.mix_paths.items()},
                       args.close_mosaic_share)
    notes = [f"{len(seeds)} seed{'s' if len(seeds) > 1 else ''}: a spread from fewer than {S.MIN_SEEDS} seeds is not "
             f"a figure to quote"] if len(seeds) < S.MIN_SEEDS else []
    notes += [f"{r.name}: {r.budget.note()}" for r in runs if r.budget.note() and r.seed == seeds[0]]
    document = plan_document(args, arms, seeds, got, command, work, notes)
    print(f"sim2real: {len(runs)} trainings ({', '.join(S.ARMS[a] for a in arms)}; seeds {args.seeds}; real sizes "
          f"{', '.join(map(str, got.sizes)) or '-'}), every arm from {describe(got.init.document(), got.init.architecture)}")
    for r in runs:
        print(f"  {r.name:16s} {r.budget.epochs:5d} epochs x {r.budget.images:6,d} images = {r.budget.image_steps:9,d} "
              f"image-steps, the last {r.budget.close_mosaic} without mosaic" + (f"  ({r.budget.note()})" if r.budget.note() else ""))
    if len(seeds) < S.MIN_SEEDS:
        print(f"  note: {notes[0]}")
    if args.plan_only:
        write_json_atomic(work / "sim2real.json", document, indent=1)
        print(f"sim2real: plan only; subsets in {work / 'subsets'} -> {work / 'sim2real.json'}")
        return 0
    for planned in runs:
        record = train_one(planned, args, got, folders, work, targets)
        document["runs"].append(record)
        if planned.arm != "a" or "a" in arms:              # (a) only as (c)'s pretraining is not scored
            document["scores"] += score_one(planned, record, args, got.tests, work)
        document["summary"] = S.summarise(document["scores"])
        document["comparisons"] = S.compare(document["scores"])
        document["seconds"] = round(time.perf_counter() - t0, 1)
        _write_outputs(document, work, args)              # after every run: a long experiment shows its progress
    print((work / "sim2real.md").read_text(encoding="utf-8"))
    print(f"sim2real: {time.perf_counter() - t0:.0f} s -> {work}")
    return 0


def main(argv: list[str] | None = None) -> int:
    return tool_main(run, argv)


if __name__ == "__main__":
    sys.exit(main())
