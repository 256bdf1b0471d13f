#!/usr/bin/env python
"""Sim-to-real comparison (a benchmark, not a test): one detector, one budget, one test set, three trainings.

  (a) synthetic only: `synthua train` on a generated dataset (its train split);
  (b) real only (with ``--real-train``): the same model from scratch on a few real images;
  (c) synthetic, then fine-tuned on those real images: (a)'s weights trained on (b)'s set with (b)'s budget
      (``--real-minutes``, default ``--minutes``).

Each model is scored by `synthua evaluate-real` on ``--test`` (a YOLO folder or COCO .json of real photos; with
``--map`` for (a), whose classes are ours, while (b) and (c) learn the real set's own names), and (a) also on the
generated dataset's held-out test split (the boxes it was trained with). The synthetic set's boxes follow
``--convention`` (default ``wheelchair-sets``, the real wheelchair sets': the seated user inside the wheelchair's box,
no person box; :mod:`synthua_usd.model.box_conventions`), and so do the stand-in's. The table (markdown and JSON) gives per
scored class AP50, AP50-95, precision and recall at the fixed confidence, with each run's epochs, seconds and
device, and the command lines; every run folder keeps its train.json (dataset id, config, versions, seed, budget).

Usage:
  nice -n 10 python tools/sim2real.py --synthetic out/sim2real --minutes 30 --imgsz 320 --work out/sim2real_bench \\
      [--test REAL_TEST] [--real-train REAL_TRAIN] [--map wheelchair=manual_wheelchair,electric_wheelchair ...] \\
      [--table docs/measured/sim2real.md]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from synthua_usd.analytics.detection_targets import targets_for  # noqa: E402
from synthua_usd.model.box_conventions import CONVENTIONS  # noqa: E402
from synthua_usd.pipeline.evaluate_real import EvaluateRequest, evaluate_real  # noqa: E402
from synthua_usd.pipeline.train import Budget, TrainRequest, train  # noqa: E402


def stand_in(dataset: Path, out: Path, test_split: str = "test", convention: str = "wheelchair-sets") -> tuple[Path, Path]:
    """A generated dataset written as a third party's YOLO sets (train, test) with the classes ``person`` and
    ``wheelchair`` (both wheelchair classes, each box covering the chair and its user, as a real annotator draws
    it; the seated user a person too or not, by ``convention``): no synthua file is read through them, only
    data.yaml, images/ and labels/."""
    from dataclasses import replace

    from synthua_usd.analytics.detection_targets import read_generated
    from synthua_usd.backends.detector.yolo_data import write_yolo_boxes

    targets = targets_for(convention, ("person", "manual_wheelchair", "electric_wheelchair"))
    rename = {"manual_wheelchair": "wheelchair", "electric_wheelchair": "wheelchair"}
    folders = []
    for split in ("train", test_split):
        s = read_generated(dataset, split, targets)
        images = tuple(replace(im, boxes=tuple(replace(b, label=rename.get(b.label, b.label)) for b in im.boxes))
                       for im in s.images)
        folders.append(write_yolo_boxes(out / split, {split: replace(s, images=images)}, ("person", "wheelchair")).parent)
    return folders[0], folders[1]


def _fmt(v) -> str:
    return "–" if v is None else f"{100 * v:.1f}"


def score(name: str, run: Path, test: Path, out: Path, maps, confidence: float, split: str | None = None) -> dict:
    result = evaluate_real(EvaluateRequest(run, test, out, tuple(maps), split=split, confidence=confidence))
    doc = result.document
    return {"model": name, "run": str(run), "test_set": doc["test_set"]["source"],
            "test_layout": doc["test_set"]["layout"], "test_split": doc["test_set"]["split"],
            "test_images": doc["test_set"]["images"], "mapping": doc["mapping_options"], "report": str(out),
            "coco_AP": doc["coco_stats"]["AP"], "coco_AP50": doc["coco_stats"]["AP50"], "classes": doc["classes"]}


def _score_table(rows: list[dict]) -> list[str]:
    if len(rows) == 1:      # one model on the set: a row per class
        r = rows[0]
        split = f" ({r['test_split']})" if r["test_split"] else ""
        lines = [f"{r['model']} on {r['test_layout']} {Path(r['test_set']).name}{split}, {r['test_images']} images:", "",
                 "| class | boxes | AP50 | AP50-95 | P | R |", "|---|---|---|---|---|---|"]
        lines += [f"| {c['class']} | {c['boxes']} | {_fmt(c['AP50'])} | {_fmt(c['AP50_95'])} | {_fmt(c['precision'])} | "
                  f"{_fmt(c['recall'])} |" for c in r["classes"]]
        return lines + [""]
    classes = list(dict.fromkeys(c["class"] for r in rows for c in r["classes"]))
    head = ["model", "test set", "images"] + [f"{c} {m}" for c in classes for m in ("AP50", "AP50-95", "P", "R")]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in rows:
        by = {c["class"]: c for c in r["classes"]}
        split = f" ({r['test_split']})" if r["test_split"] else ""
        cells = [r["model"], f"{r['test_layout']} {Path(r['test_set']).name}{split}", str(r["test_images"])]
        for c in classes:
            row = by.get(c, {})
            cells += [_fmt(row.get("AP50")), _fmt(row.get("AP50_95")), _fmt(row.get("precision")), _fmt(row.get("recall"))]
        lines.append("| " + " | ".join(cells) + " |")
    return lines + [""]


def table(rows: list[dict], runs: dict[str, dict], confidence: float, commands: list[str]) -> str:
    """One table of scores per test set, then the runs and the command."""
    lines = []
    for key in dict.fromkeys((r["test_set"], r["test_split"]) for r in rows):
        lines += _score_table([r for r in rows if (r["test_set"], r["test_split"]) == key])
    lines += [f"AP by pycocotools' COCOeval (bbox), in %; P and R at confidence {confidence:g}, IoU 0.5.", "",
              "| run | trained on | images (train) | from | budget | epochs done | seconds | device |", "|---|---|---|---|---|---|---|---|"]
    for name, about in runs.items():
        ts, b = about["train_set"], about["budget"]
        budget = f"{b['minutes']:g} min" if b["minutes"] is not None else f"{b['epochs']} epochs"
        start = "scratch (" + about["model"] + ")" if about["init"] is None else "run " + Path(about["init"]["weights"]).parent.name
        lines.append(f"| {name} | {ts['layout']} {Path(ts['source']).name} | {ts['images']['train']} | {start} | "
                     f"{budget}, imgsz {b['imgsz']}, batch {b['batch']} | {about['epochs_done']} | {about['seconds']:.0f} | "
                     f"{about['device']} |")
    v = next(iter(runs.values()))["versions"]
    lines += ["", f"Ultralytics {v['ultralytics']}, torch {v['torch']}, torchvision {v['torchvision']}; seed "
              f"{next(iter(runs.values()))['seed']}.", "", "```"] + commands + ["```"]
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--synthetic", type=Path, required=True, help="dataset written by `synthua generate`")
    p.add_argument("--synthetic-split", default="test", help="held-out split of --synthetic scored too [test]")
    p.add_argument("--test", type=Path, help="real test set (YOLO folder or COCO .json) [default: none]")
    p.add_argument("--real-train", type=Path, help="a few real training images (YOLO folder or COCO .json)")
    p.add_argument("--stand-in", type=Path,
                   help="no real photos at hand: another generated dataset exported as a 'real' YOLO set with classes "
                        "person and wheelchair (its train split as --real-train, its test split as --test)")
    p.add_argument("--stand-in-test-split", default="test", help="the stand-in's split used as --test [test]")
    p.add_argument("--map", dest="maps", action="append", default=[], help="--map of evaluate-real for (a) on --test")
    p.add_argument("--convention", choices=list(CONVENTIONS), default="wheelchair-sets",
                   help="box convention of --synthetic's training boxes and of the stand-in [wheelchair-sets]")
    p.add_argument("--minutes", type=float, default=30.0, help="budget of every training [30]")
    p.add_argument("--real-minutes", type=float, help="budget of (b) and (c), the same for both [--minutes]")
    p.add_argument("--imgsz", type=int, default=320)
    p.add_argument("--batch", type=int, default=16)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--confidence", type=float, default=0.25)
    p.add_argument("--work", type=Path, default=REPO / "out" / "sim2real_bench")
    p.add_argument("--table", type=Path, help="also write the markdown table here")
    args = p.parse_args(argv)
    budget = Budget(minutes=args.minutes, imgsz=args.imgsz, batch=args.batch)
    real_budget = Budget(minutes=args.real_minutes or args.minutes, imgsz=args.imgsz, batch=args.batch)
    work = args.work
    runs, rows = {}, []
    commands = [" ".join(["python tools/sim2real.py"] + (sys.argv[1:] if argv is None else argv))]
    t0 = time.perf_counter()
    if args.stand_in:
        args.real_train, args.test = stand_in(args.stand_in, work / "stand_in", args.stand_in_test_split, args.convention)

    def trained(name: str, train_set: Path, init: Path | None = None, budget: Budget = budget) -> Path:
        out = work / "runs" / name
        if not (out / "train.json").is_file():          # a finished run is kept: rerun to redo the scoring only
            train(TrainRequest(train_set, out, budget, targets_for(args.convention), init=init, seed=args.seed))
        runs[name] = json.loads((out / "train.json").read_text())
        return out

    synthetic = trained("a_synthetic", args.synthetic)
    rows.append(score("(a) synthetic", synthetic, args.synthetic, work / "eval" / "a_on_synthetic_test", [],
                      args.confidence, split=args.synthetic_split))
    if args.test:
        rows.append(score("(a) synthetic", synthetic, args.test, work / "eval" / "a_on_test", args.maps, args.confidence))
    if args.real_train:
        real = trained("b_real", args.real_train, budget=real_budget)
        tuned = trained("c_finetuned", args.real_train, init=synthetic, budget=real_budget)
        if args.test:
            rows.append(score("(b) real only", real, args.test, work / "eval" / "b_on_test", [], args.confidence))
            rows.append(score("(c) synthetic + fine-tuned", tuned, args.test, work / "eval" / "c_on_test", [],
                              args.confidence))
    text = table(rows, runs, args.confidence, commands)
    work.mkdir(parents=True, exist_ok=True)
    (work / "sim2real.json").write_text(json.dumps({"rows": rows, "runs": runs}, indent=1), encoding="utf-8")
    (work / "sim2real.md").write_text(text, encoding="utf-8")
    if args.table:
        args.table.parent.mkdir(parents=True, exist_ok=True)
        args.table.write_text(text, encoding="utf-8")
    print(text)
    print(f"sim2real: {time.perf_counter() - t0:.0f} s -> {work}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
