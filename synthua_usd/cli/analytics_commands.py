"""``synthua stats`` and ``synthua eval``: a dataset's statistics as one report, and predictions scored
against a dataset's labels."""

from __future__ import annotations

import time
from pathlib import Path

import click

from synthua_usd.cli.common import EXIT_OK, say
from synthua_usd.core.dataset_folders import check_outside_datasets
from synthua_usd.core.errors import InputError


@click.command()
@click.argument("dataset", type=click.Path(path_type=Path))
@click.option("--out", "out_dir", type=click.Path(path_type=Path), required=True,
              help="Report folder (created; files of an earlier report replaced as a set).")
@click.option("--samples", type=click.IntRange(0, 64), default=8, show_default=True,
              help="Sample images in the report's gallery (aid users first, one condition after another).")
def stats(dataset: Path, out_dir: Path, samples: int) -> int:
    """The statistics of DATASET (written by `synthua generate`) as tables, plots and one HTML report.

    \b
    Example:
      synthua stats out/dataset --out out/dataset_report     # then open out/dataset_report/report.html
    \b
    Per class: objects (thing instances; stuff regions per image) and their share, imbalance ratio
    (most frequent / class), object area mean, median, standard deviation, maximum and IQR, pixel share.
    Dataset: Shannon entropy (bits) and normalised entropy and Gini coefficient of the pixel area, classes
    covering 80 % of it, objects per image (mean, median, max, histogram, density <=100 / 101-500 / >500),
    images per split, condition and rig type, share of images with a mobility-aid user, class co-occurrence,
    mobility-aid area, occlusion and size of aid users. Images: RMS contrast and edge density of the RGB (mean,
    median, p10, p90; per dataset and split). Reads the manifest, the per-image records, every RGB once, and
    the class maps of images sharing camera and time code and of the gallery's samples (their RGB again).
    QA-rejected images are left out.
    \b
    Writes statistics.json, class_statistics.csv, cooccurrence.csv, plots/*.png, gallery/*.png and
    report.html (self-contained: it refers only to files in the folder).
    """
    from synthua_usd.analytics.dataset_index import load_index
    from synthua_usd.analytics.report import write_report

    check_outside_datasets(out_dir)  # before the work: write_report would refuse it at the end
    from synthua_usd.analytics.statistics import compute

    t0 = time.perf_counter()
    index = load_index(dataset)
    result = compute(index)
    seconds = time.perf_counter() - t0
    files = write_report(index, result, out_dir, samples=samples, seconds=seconds)
    s = result.summary
    say(f"{s['images']} images ({s['rejected_images_left_out']} QA-rejected left out), {s['objects']} objects: "
               f"Gini {s['gini_pixel_area']:.4f}, entropy {s['shannon_entropy_bits']:.4f} bits (normalised "
               f"{s['normalised_entropy']:.4f}), {s['classes_for_coverage']} classes cover 80 % of the area, "
               f"{100 * s['share_images_with_aid_user']:.1f} % of images show a mobility-aid user")
    c = s["image_contrast"]
    say("images: " + ", ".join(f"{label} median {c[k]['median']:.3f} (p10-p90 {c[k]['p10']:.3f}-{c[k]['p90']:.3f})"
                               for label, k in (("RMS contrast", "rms_contrast"), ("edge density", "edge_density"))))
    say(f"statistics in {seconds:.2f} s, report in {time.perf_counter() - t0:.2f} s -> {files.html}")
    return EXIT_OK


@click.command("eval")
@click.option("--gt", "gt_dir", type=click.Path(path_type=Path), required=True,
              help="Dataset folder written by `synthua generate` (the ground truth).")
@click.option("--pred", "pred", type=click.Path(path_type=Path), required=True,
              help="Folder of {image name}.png predictions (class ids or class colours), or a COCO results .json.")
@click.option("--out", "out_dir", type=click.Path(path_type=Path), required=True,
              help="Folder for metrics.csv/.json, confusion.csv/.png (and coco.json).")
@click.option("--split", type=click.Choice(["train", "val", "test"]),
              help="Evaluate the images of one split only [default: every image not rejected by QA].")
def evaluate(gt_dir: Path, pred: Path, out_dir: Path, split: str | None) -> int:
    """Score predictions against a dataset's labels.

    \b
    Semantic segmentation (a folder of PNGs named like the dataset's images, e.g.
    000017_CCTV_t0024_clear-day_s0.png; 8/16-bit class ids or RGB in the class colours):
      synthua eval --gt out/dataset --pred out/predictions --out out/eval
    per class accuracy (one-vs-rest), IoU, precision, recall, F1; pixel accuracy, mean IoU, frequency-weighted
    IoU; the confusion matrix as a table and a heatmap. Pixels labelled unlabelled in the ground truth are void.
    \b
    Instance segmentation or detection (COCO results: image_id, category_id, score, bbox and/or RLE
    segmentation):
      synthua eval --gt out/dataset --pred results.json --out out/eval
    COCO mAP through pycocotools' COCOeval (segm and/or bbox), and AP per class.
    """
    from synthua_usd.analytics.evaluation import evaluate_coco, evaluate_semantic
    from synthua_usd.analytics.evaluation_report import EVALUATION_FILES, write_evaluation
    from synthua_usd.core.input_files import shown
    from synthua_usd.core.input_guard import check_not_inputs

    # before the work: write_evaluation would refuse either at the end
    check_outside_datasets(out_dir)
    inputs = {"--gt": gt_dir, "--pred": pred}
    check_not_inputs([out_dir / name for name in EVALUATION_FILES], inputs)
    if pred.suffix.lower() == ".json":
        coco = evaluate_coco(gt_dir, pred, split)
        write_evaluation(out_dir, None, coco, inputs)
        for iou_type, result in coco["iou_types"].items():
            st = result["stats"]
            say(f"{iou_type}: mAP {st['AP']:.4f}, AP50 {st['AP50']:.4f}, AP75 {st['AP75']:.4f} "
                       f"({coco['detections']} detections on {coco['images']} images)")
        say(f"-> {out_dir}")
        return EXIT_OK
    if not pred.exists():
        raise InputError(f"{shown(pred)}: not found; expected a folder of predictions or a COCO results .json")
    ev = evaluate_semantic(gt_dir, pred, split)
    write_evaluation(out_dir, ev, None, inputs)
    s = ev.summary
    say(f"{ev.images} images, {s['pixels']:,} pixels evaluated: pixel accuracy {s['pixel_accuracy']:.4f}, "
               f"mean IoU {s['mean_iou'] if s['mean_iou'] is None else format(s['mean_iou'], '.4f')} "
               f"({s['mean_iou_classes']} classes), frequency-weighted IoU {s['frequency_weighted_iou']:.4f}")
    say(f"{'class':22s} {'gt px':>9s} {'IoU':>7s} {'prec':>7s} {'recall':>7s} {'F1':>7s}")
    gt_px = ev.matrix.sum(axis=1)
    for c in ev.class_map.classes:
        m = ev.per_class[c.id]
        if c.id == 0 or (gt_px[c.id] == 0 and m.fp == 0):
            continue
        f = [("–" if v is None else f"{v:.4f}") for v in (m.iou, m.precision, m.recall, m.f1)]
        say(f"{c.name:22s} {gt_px[c.id]:9d} {f[0]:>7s} {f[1]:>7s} {f[2]:>7s} {f[3]:>7s}")
    if ev.ignored_predictions:
        say(f"ignored {len(ev.ignored_predictions)} prediction files not among the evaluated images, e.g. "
                   f"{ev.ignored_predictions[0]}")
    say(f"-> {out_dir}")
    return EXIT_OK
