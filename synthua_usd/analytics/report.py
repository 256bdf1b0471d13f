"""``synthua stats``'s outputs: the statistics as CSV and JSON, the figures, a gallery of sample images with
their labels laid over them, and one HTML page tying them together.

The report folder is self-contained: ``report.html`` uses no scripts, style sheets, fonts or images from
elsewhere; it refers only to files inside the folder, by relative paths::

    REPORT_DIR/report.html
    REPORT_DIR/statistics.json  class_statistics.csv  cooccurrence.csv
    REPORT_DIR/plots/{class_distribution,area_boxplot,cooccurrence,coverage_cdf,instances_per_image,
                      aid_area,aid_users}.png
    REPORT_DIR/gallery/{name}.png        RGB with the class colours laid over at 50 % (unlabelled left clear)
    REPORT_DIR/real_comparison.csv  plots/real_comparison.png     with a real set to compare with (--compare)

Everything is written into a staging folder and moved into place as a set (:func:`synthua_usd.core.atomic.output_set`).
"""

from __future__ import annotations

import html
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from synthua_usd.analytics import plots
from synthua_usd.analytics.csv_text import csv_text
from synthua_usd.analytics.dataset_index import DatasetIndex, ImageSummary, image_file
from synthua_usd.analytics.image_contrast import EDGE_THRESHOLD, MEASURES, SOBEL_GAIN, SPREAD
from synthua_usd.analytics.real_comparison import ALL, RealComparison
from synthua_usd.analytics.real_comparison import MEASURES as COMPARED
from synthua_usd.analytics.statistics import DatasetStatistics, mobility_aid_classes
from synthua_usd.core.atomic import output_set, write_json_atomic, write_text_atomic
from synthua_usd.model.photometry import REC709_LUMA

OVERLAY_ALPHA = 0.5
PLOTS = ("class_distribution", "area_boxplot", "cooccurrence", "coverage_cdf", "instances_per_image", "aid_area",
         "aid_users")


@dataclass(frozen=True)
class ReportFiles:
    out_dir: Path
    html: Path
    gallery: tuple[str, ...]     # names of the sample images


def gallery_images(images: tuple[ImageSummary, ...], count: int) -> list[ImageSummary]:
    """Up to ``count`` sample images: those with an aid user first, taken in turn from each condition, by id
    (deterministic: the same dataset gives the same gallery)."""
    ranked = sorted(images, key=lambda i: (not i.aid_users, i.id))
    by_condition: dict[str, list[ImageSummary]] = {}
    for img in ranked:
        by_condition.setdefault(img.condition, []).append(img)
    out: list[ImageSummary] = []
    queues = [list(v) for _, v in sorted(by_condition.items())]
    while len(out) < count and any(queues):
        for q in queues:
            if q and len(out) < count:
                out.append(q.pop(0))
    return out


def overlay(rgb: np.ndarray, class_ids: np.ndarray, palette: np.ndarray, alpha: float = OVERLAY_ALPHA) -> np.ndarray:
    """(H, W, 3) uint8 RGB with the class colours of ``class_ids`` ((H, W) ints, palette (256, 3) uint8) blended
    in at ``alpha``; pixels of class 0 (unlabelled) keep the RGB."""
    colours = palette[class_ids].astype(np.float64)
    out = rgb[..., :3].astype(np.float64)
    labelled = class_ids > 0
    out[labelled] = (1 - alpha) * out[labelled] + alpha * colours[labelled]
    return np.round(out).astype(np.uint8)


def _read_pair(index: DatasetIndex, img: ImageSummary) -> tuple[np.ndarray, np.ndarray]:
    from synthua_usd.core.images import read_image

    paths = [image_file(index.root, img, relative) for relative in (img.rgb, img.class_png)]
    rgb, _ = read_image(paths[0])
    ids, _ = read_image(paths[1])
    return rgb, ids[..., 0].astype(np.int64)


def _csv(rows: list[dict]) -> str:
    return csv_text(list(rows[0]), [list(r.values()) for r in rows])


def _fmt(value, digits: int = 1) -> str:
    if value is None:
        return "–"
    if isinstance(value, float):
        return f"{value:,.{digits}f}"
    return f"{value:,}" if isinstance(value, int) else html.escape(str(value))


def _swatch(color) -> str:
    r, g, b = color
    return f'<span class="sw" style="background:rgb({r},{g},{b})"></span>'


def write_report(index: DatasetIndex, stats: DatasetStatistics, out_dir: str | Path, samples: int = 8,
                 seconds: float | None = None, comparison: RealComparison | None = None) -> ReportFiles:
    """Write the report of ``stats`` (computed from ``index``; with ``comparison``, the dataset against a real set)
    into ``out_dir`` as a set."""
    cmap = index.class_map
    colors = {c.name: c.color for c in cmap.classes}
    classes = stats.classes
    names = [c.name for c in classes]
    s = stats.summary
    chosen = gallery_images(index.images, samples)
    pairs = [_read_pair(index, img) for img in chosen]   # before anything is written: a missing file stops here
    palette = cmap.palette()
    with output_set(out_dir, inputs={"DATASET": index.root}) as stage:
        document = stats.document()
        if comparison is not None:
            document["real_comparison"] = comparison.document()
            write_text_atomic(stage / "real_comparison.csv", _csv([r.row() for r in comparison.rows]))
        write_json_atomic(stage / "statistics.json", document)
        write_text_atomic(stage / "class_statistics.csv", _csv([c.csv_row() for c in classes]))
        co_rows = [{"class": n} | {m: int(stats.cooccurrence[i, j]) for j, m in enumerate(names)}
                   for i, n in enumerate(names)]
        write_text_atomic(stage / "cooccurrence.csv", _csv(co_rows))
        (stage / "plots").mkdir()
        p = stage / "plots"
        plots.class_distribution(names, [c.instances for c in classes], [c.pixel_share for c in classes],
                                 [colors[n] for n in names], p / "class_distribution.png")
        plots.area_boxplots(stats.areas, colors, p / "area_boxplot.png")
        plots.cooccurrence_heatmap(names, stats.cooccurrence, p / "cooccurrence.png")
        plots.coverage_cdf(s["coverage_curve"], s["coverage"], s["classes_for_coverage"], p / "coverage_cdf.png")
        plots.instances_histogram(stats.instances_per_image, s["instances_per_image"]["histogram"]["edges"],
                                  p / "instances_per_image.png")
        aids = mobility_aid_classes(cmap.classes)
        plots.aid_area([c.name for c in aids], [s["aid_area"][c.name]["pixels"] for c in aids],
                       [c.color for c in aids], p / "aid_area.png")
        plots.aid_users(s["aid_users"]["occlusion"]["histogram"], s["aid_users"]["visible_pixels"]["histogram"],
                        p / "aid_users.png")
        if s["diversity"]["randomised_images"]:
            plots.diversity(s["diversity"], p / "diversity.png")
        if comparison is not None:
            names = [ALL] + [r.class_name for r in comparison.rows if r.class_name != ALL and r.measure == COMPARED[0]]
            plots.distribution_comparison(comparison.samples, names, list(COMPARED), _COMPARED_LABELS,
                                          {(r.measure, r.class_name): r.ks_statistic for r in comparison.rows},
                                          p / "real_comparison.png", log_x=("aspect_ratio",))
        (stage / "gallery").mkdir()
        from synthua_usd.core.images import write_color_png

        shown_classes: set[int] = set()
        for img, (rgb, ids) in zip(chosen, pairs):
            write_color_png(stage / "gallery" / f"{img.name}.png", overlay(rgb, ids, palette))
            shown_classes |= set(np.unique(ids).tolist())
        page = _html(index, stats, chosen, sorted(shown_classes - {0}), seconds, comparison)
        write_text_atomic(stage / "report.html", page)
    out_dir = Path(out_dir)
    return ReportFiles(out_dir=out_dir, html=out_dir / "report.html", gallery=tuple(i.name for i in chosen))


_STYLE = """
body{font-family:sans-serif;margin:1.5em;max-width:1300px;color:#222}
table{border-collapse:collapse;font-size:0.85em;margin:0.5em 0 1.5em}
td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}
td:first-child,th:first-child{text-align:left}
th[colspan]{text-align:center}
.sw{display:inline-block;width:0.9em;height:0.9em;border:1px solid #555;margin-right:4px;vertical-align:middle}
figure{display:inline-block;margin:4px;vertical-align:top}
figure img{max-width:100%}
.figs figure{width:calc(50% - 12px)}
.figs img{width:100%}
.gallery img{width:320px}
figcaption{font-size:0.75em;max-width:320px}
.legend span.item{display:inline-block;margin:2px 10px 2px 0;font-size:0.85em}
"""


def _contrast_section(c: dict) -> list[str]:
    """The RMS contrast and edge density of the images, over the dataset and per split, as a table."""
    head = "".join(f"<th>{q}</th>" for q in SPREAD)
    weights = " + ".join(f"{w:g} {channel}" for w, channel in zip(REC709_LUMA, "RGB"))
    out = ["<h2>Image contrast and edges</h2><p>Of each image's RGB as stored (display sRGB): RMS contrast is the "
           f"standard deviation of its Rec. 709 luma ({weights} of the values / 255; 0.5 for half black, half "
           "white); edge density is the share of its pixels whose Sobel gradient magnitude of "
           f"that luma, divided by {SOBEL_GAIN:g} (a black-to-white step gives 1), exceeds {EDGE_THRESHOLD:g}, the "
           "border replicated. Spread over the images.</p>",
           f'<table><tr><th rowspan="2">images</th><th rowspan="2">count</th><th colspan="{len(SPREAD)}">RMS '
           f'contrast</th><th colspan="{len(SPREAD)}">edge density</th></tr><tr>{head}{head}</tr>']
    for label, part in [("all", c)] + [(f"split {k}", v) for k, v in c["per_split"].items()]:
        cells = "".join(f"<td>{_fmt(part[m][q], 3)}</td>" for m in MEASURES for q in SPREAD)
        out.append(f"<tr><td>{html.escape(label)}</td><td>{part[MEASURES[0]]['count']:,}</td>{cells}</tr>")
    out.append("</table>")
    return out


_COMPARED_LABELS = {"box_height_share": "box height / image height", "aspect_ratio": "box width / height",
                    "boxes_per_image": "boxes per image", "rms_contrast": "RMS contrast", "edge_density": "edge density"}


def _comparison_section(c: RealComparison) -> list[str]:
    """The dataset against a real set: what was compared, a table of both sides and the KS statistic per measure
    (the three largest in bold), and the figure of the distribution functions."""
    e = html.escape
    real, ours = c.about["real"], c.about["ours"]
    largest = {(r.measure, r.class_name) for r in c.largest()}
    head = "".join(f"<th>{q}</th>" for q in ("count", "median", "p10–p90"))
    out = ["<h2>Against a real set</h2>",
           f"<p>Real: {e(real['source'])} ({e(real['layout'])}, {e(str(real['split'] or 'whole'))}), "
           f"{real['images']:,} images; ours: {ours['images']:,} images (QA-rejected left out), our boxes as a "
           f"detector trains on them by the <code>{e(c.about['convention'])}</code> convention (boxes lower than "
           f"{ours['min_height_px']:g} px left out: {ours['ignored_boxes_left_out']:,}). Classes matched "
           f"<code>{e(c.about['mapping_options'])}</code>"
           + (f"; not compared: {e(', '.join(real['classes_not_compared']))}" if real["classes_not_compared"] else "")
           + ". Box height share = box height / image height, aspect ratio = width / height, per box; boxes per "
           "image, RMS contrast and edge density per image (defined above). KS D is the two-sample "
           "Kolmogorov–Smirnov statistic (scipy.stats.ks_2samp: the largest gap between the two distribution "
           "functions, 0 the same, 1 apart), p its two-sided p-value; the three largest D in bold. File: "
           '<a href="real_comparison.csv">real_comparison.csv</a>.</p>',
           f'<table><tr><th rowspan="2">measure</th><th rowspan="2">class</th><th colspan="3">ours</th>'
           f'<th colspan="3">real</th><th rowspan="2">KS D</th><th rowspan="2">p</th></tr><tr>{head}{head}</tr>']
    for r in c.rows:
        cells = "".join(f"<td>{side['count']:,}</td><td>{_fmt(side['median'], 3)}</td>"
                        f"<td>{_fmt(side['p10'], 3)}–{_fmt(side['p90'], 3)}</td>" for side in (r.ours, r.real))
        d = "–" if r.ks_statistic is None else f"{r.ks_statistic:.3f}"
        if (r.measure, r.class_name) in largest:
            d = f"<b>{d}</b>"
        p = "–" if r.ks_p_value is None else f"{r.ks_p_value:.2g}"
        out.append(f"<tr><td>{e(_COMPARED_LABELS[r.measure])}</td><td>{e(r.class_name)}</td>{cells}<td>{d}</td>"
                   f"<td>{p}</td></tr>")
    out.append('</table><figure><img src="plots/real_comparison.png" alt="distribution functions, ours and real">'
               "<figcaption>ours (blue) and real (orange): the share of values at or below each x</figcaption>"
               "</figure>")
    return out


def _html(index: DatasetIndex, stats: DatasetStatistics, chosen: list[ImageSummary], legend_ids: list[int],
          seconds: float | None, comparison: RealComparison | None = None) -> str:
    s = stats.summary
    e = html.escape
    cmap = index.class_map
    ipi = s["instances_per_image"]
    summary_rows = [
        ("images (QA-rejected left out)", f"{s['images']:,} ({s['rejected_images_left_out']:,} left out)"),
        ("objects (instances of things, regions of stuff per image)", f"{s['objects']:,}"),
        ("labelled pixels / unlabelled share", f"{s['labelled_pixels']:,} / {100 * s['unlabelled_share']:.1f} %"),
        ("Shannon entropy of pixel area (bits)", f"{s['shannon_entropy_bits']:.4f}"),
        (f"normalised entropy (H / log2 {s['classes']})", f"{s['normalised_entropy']:.4f}"),
        ("Gini coefficient of pixel area", f"{s['gini_pixel_area']:.4f}"),
        (f"classes covering {100 * s['coverage']:g} % of the labelled area", f"{s['classes_for_coverage']}"),
        ("objects per image: mean / median / max", f"{_fmt(ipi['mean'])} / {_fmt(ipi['median'])} / {_fmt(ipi['max'])}"),
        ("scene density (images): ≤100 / 101–500 / >500",
         " / ".join(str(v) for v in ipi["density_buckets"].values())),
        ("images with a mobility-aid user", f"{s['images_with_aid_user']:,} ({100 * s['share_images_with_aid_user']:.1f} %)"),
        ("images with a mobility-aid class", f"{s['images_with_aid_class']:,} ({100 * s['share_images_with_aid_class']:.1f} %)"),
        ("aid users: count / median occlusion / median visible pixels",
         f"{s['aid_users']['count']} / {_fmt(s['aid_users']['occlusion']['median'], 3)} / "
         f"{_fmt(s['aid_users']['visible_pixels']['median'], 0)}"),
        ("images per split", ", ".join(f"{k} {v}" for k, v in s["images_per_split"].items())),
        ("images per condition", ", ".join(f"{k} {v}" for k, v in s["images_per_condition"].items())),
        ("images per rig type", ", ".join(f"{k} {v}" for k, v in s["images_per_rig_type"].items())),
    ]
    d = s["diversity"]
    disagree = d["class_map_disagreement"]
    summary_rows.append(("randomised images / distinct scenes / districts / view layers",
                         f"{d['randomised_images']} / {d['distinct_scenes']} / {d['distinct_districts']} / "
                         f"{d['distinct_view_layers']}"))
    summary_rows.append(("class-map disagreement of images sharing camera and time code (pairs: mean)",
                         f"{disagree['pairs']}: {_fmt(disagree['mean'], 3)}" if disagree["pairs"] else "no such pairs"))
    if d["randomised_images"]:
        people, devices = d["people"], d["devices"]
        summary_rows.append(("people shown / devices shown (finishes)",
                             f"{people['count']} / {devices['count']} ("
                             + ", ".join(f"{k} {v}" for k, v in devices["finish"].items()) + ")"))
    if seconds is not None:
        summary_rows.append(("statistics computed in", f"{seconds:.2f} s"))
    out = ["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
           f"<title>synthua stats: {e(index.root.name)}</title><style>{_STYLE}</style></head><body>",
           f"<h1>Dataset statistics: {e(str(index.root.name))}</h1>",
           "<p>Definitions: objects are panoptic segments (each thing instance; each stuff class's region in one "
           "image); pixel shares are of labelled pixels; balance measures run over all classes of the class map "
           "except unlabelled, absent ones as zeros; mobility-aid classes are the device classes. Files: "
           '<a href="statistics.json">statistics.json</a>, <a href="class_statistics.csv">class_statistics.csv</a>, '
           '<a href="cooccurrence.csv">cooccurrence.csv</a>.</p>',
           "<h2>Summary</h2><table>"]
    out += [f"<tr><td>{e(k)}</td><td>{e(v)}</td></tr>" for k, v in summary_rows]
    out.append("</table>")
    out += _contrast_section(s["image_contrast"])
    if comparison is not None:
        out += _comparison_section(comparison)
    out.append("<h2>Gallery</h2><p>RGB with the class colours laid over at 50 %; unlabelled pixels left clear.</p>"
               '<div class="legend">')
    for cid in legend_ids:
        c = cmap.by_id(cid)
        out.append(f'<span class="item">{_swatch(c.color)}{e(c.display_name)}</span>')
    out.append('</div><div class="gallery">')
    for img in chosen:
        users = f", {len(img.aid_users)} aid user{'s' if len(img.aid_users) != 1 else ''}" if img.aid_users else ""
        out.append(f'<figure><img src="gallery/{e(img.name)}.png" alt="{e(img.name)}"><figcaption>{e(img.name)}: '
                   f"{e(img.condition)}, {e(img.rig_type)}, {e(img.split)}{e(users)}</figcaption></figure>")
    out.append("</div>")
    out.append('<h2>Figures</h2><div class="figs">')
    titles = {"class_distribution": "objects and pixel share per class", "area_boxplot": "object areas (log scale)",
              "cooccurrence": "class co-occurrence", "coverage_cdf": "coverage CDF",
              "instances_per_image": "objects per image", "aid_area": "mobility-aid area",
              "aid_users": "aid users: occlusion and size"}
    for name in PLOTS:
        out.append(f'<figure><img src="plots/{name}.png" alt="{e(titles[name])}"><figcaption>{e(titles[name])}'
                   f"</figcaption></figure>")
    d = s["diversity"]
    if d["randomised_images"]:
        out.append('<figure><img src="plots/diversity.png" alt="scene diversity"><figcaption>scene diversity'
                   "</figcaption></figure>")
    out.append("</div><h2>Classes</h2><table><tr><th>class</th><th>group</th><th>objects</th><th>share %</th>"
               "<th>IR</th><th>area mean</th><th>median</th><th>std</th><th>max</th><th>IQR</th>"
               "<th>pixel share %</th><th>images</th></tr>")
    for c in stats.classes:
        a = c.area
        out.append(f"<tr><td>{_swatch(cmap.by_id(c.id).color)}{e(c.display_name)}</td><td>{e(c.group)}</td>"
                   f"<td>{c.instances:,}</td><td>{100 * c.instance_share:.2f}</td><td>{_fmt(c.imbalance_ratio, 2)}</td>"
                   f"<td>{_fmt(a.mean)}</td><td>{_fmt(a.median)}</td><td>{_fmt(a.std)}</td><td>{_fmt(a.max, 0)}</td>"
                   f"<td>{_fmt(a.iqr)}</td><td>{100 * c.pixel_share:.3f}</td><td>{c.images:,}</td></tr>")
    out.append("</table></body></html>")
    return "\n".join(out) + "\n"
