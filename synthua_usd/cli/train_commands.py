"""``synthua train`` and ``synthua evaluate-real``: a detector trained on a generated dataset, and scored on real
photos (or any detection set)."""

from __future__ import annotations

from pathlib import Path

import click

from synthua_usd.cli.common import EXIT_OK
from synthua_usd.cli.options import InRange, seed_option
from synthua_usd.model import detection_limits as L
from synthua_usd.model.box_conventions import CONVENTIONS, DEFAULT_CONVENTION

_FORMAT = click.Choice(["auto", "yolo", "coco", "synthua"])
_DEVICE = click.Choice(L.DEVICES)


@click.command()
@click.argument("train_set", type=click.Path(path_type=Path))
@click.option("--out", "out_dir", type=click.Path(path_type=Path), required=True,
              help="Run folder (weights.pt, train.json, results.csv, train.log), written when training ends.")
@click.option("--minutes", type=InRange(L.MINUTES), default=L.DEFAULT_MINUTES, show_default=True,
              help="Training budget in wall-clock minutes (Ultralytics stops mid-epoch when it is spent and fits its "
                   "learning-rate schedule to it).")
@click.option("--epochs", type=InRange(L.EPOCHS),
              help="Train this many epochs instead of a time budget (--minutes is then ignored).")
@click.option("--imgsz", type=InRange(L.IMGSZ), default=L.DEFAULT_IMGSZ, show_default=True,
              help="Training image size in pixels (long side; a multiple of 32).")
@click.option("--batch", type=InRange(L.BATCH), default=L.DEFAULT_BATCH, show_default=True, help="Images per step.")
@click.option("--close-mosaic", type=InRange(L.CLOSE_MOSAIC), default=L.DEFAULT_CLOSE_MOSAIC, show_default=True,
              help="The last N epochs train without mosaic augmentation (Ultralytics' close_mosaic). An epoch count: "
                   "when comparing trainings of the same image-steps over sets of other sizes, give each the same "
                   "share of its epochs (tools/sim2real.py does).")
@click.option("--device", type=_DEVICE, default="auto", show_default=True,
              help="auto: CUDA when torch sees a GPU, else the CPU.")
@seed_option(help="Ultralytics' seed (deterministic mode on).")
@click.option("--model", default=L.DEFAULT_MODEL, show_default=True,
              help="Architecture shipped inside the Ultralytics wheel, trained from scratch (e.g. yolo26s.yaml, "
                   "yolo11n.yaml); no weights are downloaded.")
@click.option("--init", "init", type=click.Path(path_type=Path),
              help="Start from these weights instead of from scratch (--model): an Ultralytics checkpoint file on "
                   "this machine, e.g. a COCO-pretrained yolo11n.pt or yolo26n.pt (the usual start; its architecture "
                   "is the checkpoint's), or a run folder of `synthua train` (fine-tuning). Nothing is downloaded: "
                   "a missing file is refused. train.json records its kind, path and SHA-256.")
@click.option("--convention", type=click.Choice(list(CONVENTIONS)),
              help="Box convention of a generated TRAIN_SET, named: " + "; ".join(
                  f"{name}: {c.about}" for name, c in CONVENTIONS.items())
                   + f" [default: {DEFAULT_CONVENTION}, whose choices --aid-box, --aid-users-as-person and --classes "
                     f"may change; a named convention's --aid-box and --aid-users-as-person cannot be].")
@click.option("--classes",
              help="Classes to train, of a generated dataset's class map, comma-separated [default: the convention's; "
                   "synthua: person and the eight mobility aids, manual_wheelchair, electric_wheelchair, walker, "
                   "crutch and the four canes].")
@click.option("--aid-box", type=click.Choice(["with_user", "device"]),
              help="A mobility aid's box: with_user covers the aid and its user (what a real 'wheelchair' box "
                   "covers); device the aid alone (as our COCO instances) [default: the convention's, with_user].")
@click.option("--aid-users-as-person/--no-aid-users-as-person", default=None,
              help="Whether a user of a trained mobility-aid class is also a person box [default: the convention's; "
                   "synthua: yes, wheelchair-sets: no].")
@click.option("--min-height-px", type=InRange(L.MIN_HEIGHT_PX), default=L.DEFAULT_MIN_HEIGHT_PX, show_default=True,
              help="Boxes lower than this (pixels of the generated image) are not trained on, nor scored.")
@click.option("--format", "fmt", type=_FORMAT, default="auto", show_default=True,
              help="How TRAIN_SET is read: auto picks synthua for a generated dataset, coco for a .json, yolo for a "
                   "data.yaml folder.")
@click.option("--images", "images_dir", type=click.Path(path_type=Path),
              help="Folder of a COCO set's images [default: the .json's folder].")
@click.option("--python", "python", type=click.Path(path_type=Path),
              help="Interpreter holding Ultralytics [default: $SYNTHUA_TRAIN_PYTHON, else .venv-train/bin/python].")
def train(train_set: Path, out_dir: Path, minutes: float, epochs: int | None, imgsz: int, batch: int,
          close_mosaic: int, device: str, seed: int, model: str, init: Path | None, convention: str | None, classes: str | None, aid_box: str | None,
          aid_users_as_person: bool | None, min_height_px: float, fmt: str, images_dir: Path | None,
          python: Path | None) -> int:
    """Train an object detector (Ultralytics YOLO) on TRAIN_SET within a bounded budget, from scratch or from
    weights (--init).

    \b
    Examples:
      synthua generate stages/district/scenario.usda --config configs/sim2real.json --out out/sim2real
      synthua train out/sim2real --minutes 30 --imgsz 320 --out out/runs/synthetic
      synthua evaluate-real out/runs/synthetic real_photos/ --out out/eval_real
      synthua train real_photos/ --init out/runs/synthetic --minutes 10 --out out/runs/finetuned
      synthua train real_photos/ --init ~/weights/yolo11n.pt --epochs 50 --out out/runs/from_coco
      synthua train out/sim2real --convention wheelchair-sets --out out/runs/as_wheelchair_sets
    \b
    TRAIN_SET is a dataset `synthua generate` wrote (trained on its train split; boxes from its records: by
    default a wheelchair's box covers its user, as a real photo's 'wheelchair' box does, and a wheelchair user
    is a person too; --convention wheelchair-sets boxes them as the public wheelchair photo sets do, the
    seated user inside the wheelchair's box and no person box), or an Ultralytics YOLO folder or COCO .json of
    real photos (whose boxes are their own). Its val split is what the last epoch is validated on (the train
    split when the set has none); both are read whole, every image decoded, or refused naming the file before
    training starts. Ultralytics runs in its own environment, .venv-train (tools/setup_train.sh; AGPL-3.0); on a
    GPU when one is present. train.json
    records the set (its SHA-256, a generated dataset's id and config), classes, budget, seed, device and
    library versions.
    """
    from synthua_usd.analytics.detection_targets import targets_for
    from synthua_usd.pipeline.init_weights import describe
    from synthua_usd.pipeline.train import Budget, TrainRequest
    from synthua_usd.pipeline.train import train as run

    chosen = tuple(c.strip() for c in classes.split(",") if c.strip()) if classes is not None else None
    targets = targets_for(convention, chosen, aid_box, aid_users_as_person, min_height_px)
    budget = Budget(minutes=None if epochs is not None else minutes, epochs=epochs or 300, imgsz=imgsz, batch=batch,
                    close_mosaic=close_mosaic)
    doc = run(TrainRequest(train_set, out_dir, budget, targets, model, init, fmt, images_dir, device, seed,
                           python=python))
    final = doc["final"] or {}
    losses = ", ".join(f"{k.split('/')[-1]} {float(v):.3f}" for k, v in final.items() if k.startswith("train/"))
    images = doc["train_set"]["images"]
    click.echo(f"trained {', '.join(doc['classes'])} on {images['train']} images (validated on {images['val']}) "
               f"from {describe(doc['init'], doc['model'])} for {doc['epochs_done']} epochs in {doc['seconds']:.0f} s "
               f"on {doc['device']} (Ultralytics {doc['versions']['ultralytics']}, torch {doc['versions']['torch']})"
               f"{': ' + losses if losses else ''}")
    click.echo(f"-> {out_dir}")
    return EXIT_OK


@click.command("evaluate-real")
@click.argument("model", type=click.Path(path_type=Path))
@click.argument("test_set", type=click.Path(path_type=Path))
@click.option("--out", "out_dir", type=click.Path(path_type=Path), required=True,
              help="Report folder (metrics.json, per_class.csv, false_negatives.csv/.png, false_positives.csv/.png, "
                   "detections.json, report.html).")
@click.option("--map", "maps", multiple=True,
              help="TEST_CLASS=MODEL_CLASS[,MODEL_CLASS...]: the model classes that score as a class of the test set; "
                   "repeat per class [default: same names, and wheelchair=manual_wheelchair,electric_wheelchair].")
@click.option("--format", "fmt", type=_FORMAT, default="auto", show_default=True,
              help="How TEST_SET is read: auto picks synthua for a generated dataset, coco for a .json, yolo for a "
                   "data.yaml folder.")
@click.option("--split", type=click.Choice(["train", "val", "test"]),
              help="Split of a YOLO set or generated dataset [default: test, else val; a generated dataset: test].")
@click.option("--images", "images_dir", type=click.Path(path_type=Path),
              help="Folder of a COCO set's images [default: the .json's folder].")
@click.option("--confidence", type=InRange(L.CONFIDENCE), default=L.DEFAULT_CONFIDENCE,
              show_default=True, help="Confidence of precision, recall and the false negatives (AP uses every score).")
@click.option("--imgsz", type=InRange(L.IMGSZ), help="Prediction image size [default: the training's].")
@click.option("--device", type=_DEVICE, default="auto", show_default=True, help="auto: CUDA when present, else CPU.")
@click.option("--convention", type=click.Choice(list(CONVENTIONS)),
              help="A generated TEST_SET's boxes drawn by this box convention (see `synthua train --help`), the "
                   "model's classes kept [default: the one the model was trained with]; other sets keep their own.")
@click.option("--boxes", type=click.Choice(list(L.SCORED_BOXES)), default="all", show_default=True,
              help="Of a composite TEST_SET (synthua composite): score its pasted instances alone (pasted) or its "
                   "photos' own boxes alone (photo), the others ignored: neither found nor missed.")
@click.option("--python", "python", type=click.Path(path_type=Path),
              help="Interpreter holding Ultralytics [default: $SYNTHUA_TRAIN_PYTHON, else .venv-train/bin/python].")
def evaluate_real(model: Path, test_set: Path, out_dir: Path, maps: tuple[str, ...], fmt: str, split: str | None,
                  images_dir: Path | None, confidence: float, imgsz: int | None, device: str,
                  convention: str | None, boxes: str, python: Path | None) -> int:
    """Score the detector of run folder MODEL (`synthua train`) on TEST_SET: real photos or a held-out split.

    \b
    Examples:
      synthua evaluate-real out/runs/synthetic real_photos/ --out out/eval_real \\
          --map wheelchair=manual_wheelchair,electric_wheelchair --map person=person
      synthua evaluate-real out/runs/synthetic photos/instances.json --images photos/ --out out/eval_coco
      synthua evaluate-real out/runs/synthetic out/sim2real --split test --out out/eval_synthetic
      synthua evaluate-real out/runs/real out/comp --split train --convention wheelchair-sets --boxes pasted \\
          --map manual_wheelchair=wheelchair --out out/eval_pastes     # are the pastes wheelchairs to it?
    \b
    TEST_SET: an Ultralytics YOLO folder (data.yaml + images/ + labels/; box or polygon labels), a COCO
    instances .json, or a generated dataset (scored on the boxes the model was trained with, or those of
    --convention, e.g. wheelchair-sets: the seated user inside the wheelchair's box, no person box). Per mapped
    class: AP50 and AP50-95 by pycocotools' COCOeval (bbox), precision and recall at --confidence (IoU 0.5),
    a page of the worst false negatives (report.html, false_negatives.png), and the false positives by what they
    land on (a duplicate, another class's box, nothing labelled; false_positives.csv/.png). Test classes no --map names
    are not scored. TEST_SET is read whole before the detector runs, or refused naming the file: every image
    decoded, a COCO image's size its file's, every box on an image of the set and inside it.
    """
    from synthua_usd.analytics.detection_report import FP_KIND_TEXT
    from synthua_usd.pipeline.evaluate_real import evaluate_real as run
    from synthua_usd.pipeline.evaluate_real import EvaluateRequest

    result = run(EvaluateRequest(model, test_set, out_dir, maps, fmt, split, images_dir, confidence,
                                 imgsz=imgsz, device=device, python=python, convention=convention, boxes=boxes))
    ev = result.evaluation
    click.echo(f"{ev.images} images ({result.document['test_set']['layout']}), mapping "
               f"{result.document['mapping_options']}: COCO AP {ev.stats['AP']:.4f}, AP50 {ev.stats['AP50']:.4f}")
    if boxes != "all":
        scored = "the pasted instances" if boxes == "pasted" else "the photos' own boxes"
        click.echo(f"scored: {scored} alone; the others ignored")
    click.echo(f"{'class':20s} {'boxes':>6s} {'AP50':>7s} {'AP50-95':>8s} {'P@' + format(confidence, 'g'):>7s} "
               f"{'R@' + format(confidence, 'g'):>7s}")
    for c in ev.classes:
        f = [("–" if v is None else f"{v:.4f}") for v in (c.ap50, c.ap50_95, c.precision, c.recall)]
        click.echo(f"{c.name:20s} {c.boxes:6d} {f[0]:>7s} {f[1]:>8s} {f[2]:>7s} {f[3]:>7s}")
    for c in ev.classes:
        if c.fp:
            kinds = ", ".join(f"{n} {FP_KIND_TEXT[k]}" for k, n in c.fp_kinds.items() if n)
            click.echo(f"{c.name}: {c.fp} false positives at confidence {confidence:g}: {kinds}")
    click.echo(f"{len(ev.misses)} false negatives and {len(ev.false_positives)} false positives at confidence "
               f"{confidence:g}; the worst of each in {out_dir}/report.html")
    return EXIT_OK
