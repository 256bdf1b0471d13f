"""``synthua stats`` and ``synthua eval``: a dataset's statistics as one report, and predictions scored
against a dataset's labels."""

from __future__ import annotations

import time
from pathlib import Path

import click

from synthua_usd.cli.common import EXIT_OK, say
from synthua_usd.cli.options import InRange
from synthua_usd.core.dataset_folders import check_outside_datasets
from synthua_usd.core.errors import InputError
from synthua_usd.model import detection_limits as L
from synthua_usd.model.box_conventions import CONVENTIONS


@click.command()
@click.argument("dataset", type=click.Path(path_type=Path))
@click.option("--out", "out_dir", type=click.Path(path_type=Path), required=True,
              help="Report folder (created; files of an earlier report replaced as a set).")
@click.option("--samples", type=click.IntRange(0, 64), default=8, show_default=True,
              help="Sample images in the report's gallery (aid users first, one condition after another).")
@click.option("--compare", "real", type=click.Path(path_type=Path),
              help="A real detection set to set DATASET beside: an Ultralytics YOLO folder (data.yaml, or images/ "
                   "and labels/; every split unless --compare-split), a COCO instances .json, or another generated "
                   "dataset.")
@click.option("--compare-split", type=click.Choice(["train", "val", "test"]),
              help="With --compare: the one split of the real set to compare with [default: all of it].")
@click.option("--map", "maps", multiple=True,
              help="With --compare: REAL_CLASS=OUR_CLASS[,OUR_CLASS...], our classes that count as a class of the "
                   "real set; repeat per class [default: same names, and wheelchair=manual_wheelchair,"
                   "electric_wheelchair]. Classes no mapping names are not compared.")
@click.option("--convention", type=click.Choice(list(CONVENTIONS)),
              help="With --compare: the box convention our boxes are drawn by (see `synthua train --help`) "
                   "[default: wheelchair-sets, the real wheelchair sets': a wheelchair's box covers its seated user, "
                   "who has no person box].")
@click.option("--min-height-px", type=InRange(L.MIN_HEIGHT_PX),
              help=f"With --compare: our boxes lower than this (pixels) are left out, as training leaves them out "
                   f"[default: {L.DEFAULT_MIN_HEIGHT_PX:g}].")
def stats(dataset: Path, out_dir: Path, samples: int, real: Path | None, compare_split: str | None,
          maps: tuple[str, ...], convention: str | None, min_height_px: float | None) -> int:
    """The statistics of DATASET (written by `synthua generate`) as tables, plots and one HTML report; with
    --compare, set beside a real detection set, measure by measure.

    \b
    Examples:
      synthua stats out/dataset --out out/dataset_report     # then open out/dataset_report/report.html
      synthua stats out/dataset --out out/report --compare ../shared/data/real_photos/wheelchair_dev
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
    --compare REAL: box height share (box height / image height), aspect ratio (width / height), boxes per
    image (per matched class and over all), RMS contrast and edge density (per image) of ours and of the real
    set side by side: count, median, p10, p90 of each, and the two-sample Kolmogorov-Smirnov statistic D (0:
    the same distribution, 1: apart) with its p-value. Our boxes are those a detector trains on (QA-rejected
    images and boxes under --min-height-px left out); our classes count as the real set's by --map.
    \b
    Writes statistics.json, class_statistics.csv, cooccurrence.csv, plots/*.png, gallery/*.png and
    report.html (self-contained: it refers only to files in the folder); with --compare also
    real_comparison.csv, plots/real_comparison.png, statistics.json's real_comparison and a section of the page.
    """
    from synthua_usd.analytics.dataset_index import load_index
    from synthua_usd.analytics.report import write_report

    check_outside_datasets(out_dir)  # before the work: write_report would refuse it at the end
    if real is None:
        given = [name for name, value in (("--compare-split", compare_split), ("--map", maps),
                                          ("--convention", convention), ("--min-height-px", min_height_px))
                 if value is not None and value != ()]
        if given:
            raise InputError(f"{given[0]}: given without --compare; expected --compare REAL_SET with it")
    else:
        from synthua_usd.analytics.class_mapping import parse_map_options

        parse_map_options(maps)    # the syntax before anything is read
    from synthua_usd.analytics.statistics import compute

    t0 = time.perf_counter()
    index = load_index(dataset)
    result = compute(index)
    comparison = None
    if real is not None:
        from synthua_usd.analytics.real_comparison import DEFAULT_COMPARE_CONVENTION, compare, read_real

        convention = convention or DEFAULT_COMPARE_CONVENTION
        comparison = compare(index, result.image_contrast, read_real(real, compare_split, convention), maps, convention,
                             L.DEFAULT_MIN_HEIGHT_PX if min_height_px is None else min_height_px)
    seconds = time.perf_counter() - t0
    files = write_report(index, result, out_dir, samples=samples, seconds=seconds, comparison=comparison)
    s = result.summary
    say(f"{s['images']} images ({s['rejected_images_left_out']} QA-rejected left out), {s['objects']} objects: "
               f"Gini {s['gini_pixel_area']:.4f}, entropy {s['shannon_entropy_bits']:.4f} bits (normalised "
               f"{s['normalised_entropy']:.4f}), {s['classes_for_coverage']} classes cover 80 % of the area, "
               f"{100 * s['share_images_with_aid_user']:.1f} % of images show a mobility-aid user")
    c = s["image_contrast"]
    say("images: " + ", ".join(f"{label} median {c[k]['median']:.3f} (p10-p90 {c[k]['p10']:.3f}-{c[k]['p90']:.3f})"
                               for label, k in (("RMS contrast", "rms_contrast"), ("edge density", "edge_density"))))
    if comparison is not None:
        for line in comparison_lines(comparison):
            say(line)
    say(f"statistics in {seconds:.2f} s, report in {time.perf_counter() - t0:.2f} s -> {files.html}")
    return EXIT_OK


def comparison_lines(comparison) -> list[str]:
    """The comparison with a real set as stdout shows it: what was compared, a table, the measures that differ
    most."""
    about, real = comparison.about, comparison.about["real"]
    lines = [f"against {real['source']} ({real['layout']}, {real['split'] or 'whole'}: {real['images']} images) as "
             f"{about['mapping_options']}, our boxes by the {about['convention']} convention"
             + (f"; not compared: {', '.join(real['classes_not_compared'])}" if real["classes_not_compared"] else ""),
             f"{'measure':17s} {'class':11s} {'ours: n':>8s} {'median (p10-p90)':>24s} {'real: n':>8s} "
             f"{'median (p10-p90)':>24s} {'KS D':>6s} {'p':>8s}"]

    def side(s):
        if not s["count"]:
            return f"{0:8d} {'-':>24s}"
        return f"{s['count']:8d} {format(s['median'], '.3f') + ' (' + format(s['p10'], '.3f') + '-' + format(s['p90'], '.3f') + ')':>24s}"

    for r in comparison.rows:
        d = "-" if r.ks_statistic is None else f"{r.ks_statistic:.3f}"
        p = "-" if r.ks_p_value is None else f"{r.ks_p_value:.2g}"
        lines.append(f"{r.measure:17s} {r.class_name:11s} {side(r.ours)} {side(r.real)} {d:>6s} {p:>8s}")
    largest = comparison.largest()
    if largest:
        lines.append("differs most: " + ", ".join(f"{r.measure} of {r.class_name} (D {r.ks_statistic:.2f})"
                                                  for r in largest))
    return lines


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
