"""The statistics as figures (matplotlib, Agg backend, PNG at 100 dpi): one function per figure, each taking
plain data and writing one file. Class colours are the class map's."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from synthua_usd.core.atomic import atomic_path


def _pyplot():
    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    return plt


def _save(fig, path: Path) -> Path:
    plt = _pyplot()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=100, bbox_inches="tight")
    plt.close(fig)
    return path


def _rgb(color) -> tuple[float, float, float]:
    return tuple(v / 255.0 for v in color)


def class_distribution(names, counts, pixel_shares, colors, path: Path) -> Path:
    """Bar charts of objects per class (log scale) and pixel share per class, classes by object count."""
    plt = _pyplot()
    order = np.argsort(-np.asarray(counts), kind="stable")
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(12, 7), sharex=True)
    x = np.arange(len(order))
    c = [_rgb(colors[i]) for i in order]
    top.bar(x, [max(counts[i], 0) for i in order], color=c, edgecolor="black", linewidth=0.4)
    top.set_yscale("symlog", linthresh=1)
    top.set_ylabel("objects (log)")
    top.set_title("Objects and pixel share per class")
    bottom.bar(x, [100 * pixel_shares[i] for i in order], color=c, edgecolor="black", linewidth=0.4)
    bottom.set_ylabel("pixel share (%)")
    bottom.set_xticks(x, [names[i] for i in order], rotation=75, ha="right", fontsize=8)
    return _save(fig, path)


def area_boxplots(areas: dict[str, list[int]], colors: dict[str, tuple], path: Path) -> Path:
    """Box plots of object areas per class on a log scale (classes with objects only, by median area)."""
    plt = _pyplot()
    names = sorted((n for n, a in areas.items() if a), key=lambda n: float(np.median(areas[n])))
    fig, ax = plt.subplots(figsize=(12, 5))
    if names:
        box = ax.boxplot([areas[n] for n in names], patch_artist=True, whis=1.5, flierprops={"markersize": 3})
        for patch, n in zip(box["boxes"], names):
            patch.set_facecolor(_rgb(colors[n]))
        ax.set_xticks(np.arange(1, len(names) + 1), names, rotation=75, ha="right", fontsize=8)
    ax.set_yscale("log")
    ax.set_ylabel("object area (px², log)")
    ax.set_title("Object areas per class")
    return _save(fig, path)


def cooccurrence_heatmap(names, matrix: np.ndarray, path: Path) -> Path:
    """Heatmap of images showing both classes (classes present in at least one image only)."""
    plt = _pyplot()
    keep = np.flatnonzero(np.diag(matrix) > 0)
    sub = matrix[np.ix_(keep, keep)]
    fig, ax = plt.subplots(figsize=(9, 8))
    im = ax.imshow(sub, cmap="viridis")
    ax.set_xticks(np.arange(len(keep)), [names[i] for i in keep], rotation=75, ha="right", fontsize=7)
    ax.set_yticks(np.arange(len(keep)), [names[i] for i in keep], fontsize=7)
    fig.colorbar(im, ax=ax, label="images with both classes")
    ax.set_title("Class co-occurrence")
    return _save(fig, path)


def coverage_cdf(curve, coverage: float, needed: int, path: Path) -> Path:
    """Cumulative pixel share of classes sorted by area, with the coverage line and the classes needed."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 4))
    k = np.arange(1, len(curve) + 1)
    ax.step(k, 100 * np.asarray(curve), where="post")
    ax.axhline(100 * coverage, color="red", linestyle="--", label=f"{100 * coverage:g} %")
    if needed:
        ax.axvline(needed, color="grey", linestyle=":", label=f"{needed} classes")
    ax.set_xlabel("classes, largest area first")
    ax.set_ylabel("cumulative pixel share (%)")
    ax.set_ylim(0, 101)
    ax.legend()
    ax.set_title("Coverage of the labelled area")
    return _save(fig, path)


def instances_histogram(per_image, edges, path: Path) -> Path:
    """Histogram of objects per image with its mean and median."""
    plt = _pyplot()
    v = np.asarray(per_image, np.float64)
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.hist(v, bins=np.asarray(edges), color="#4477aa", edgecolor="white")
    if v.size:
        ax.axvline(v.mean(), color="red", linestyle="--", label=f"mean {v.mean():.1f}")
        ax.axvline(np.median(v), color="green", linestyle="--", label=f"median {np.median(v):g}")
        ax.legend()
    ax.set_xlabel("objects per image")
    ax.set_ylabel("images")
    ax.set_title("Objects per image")
    return _save(fig, path)


def aid_area(names, pixels, colors, path: Path) -> Path:
    """Share of the mobility-aid area per device class (horizontal bars, all device classes shown)."""
    plt = _pyplot()
    total = float(sum(pixels)) or 1.0
    fig, ax = plt.subplots(figsize=(7, 4))
    y = np.arange(len(names))
    ax.barh(y, [100 * p / total for p in pixels], color=[_rgb(c) for c in colors], edgecolor="black", linewidth=0.4)
    ax.set_yticks(y, names)
    ax.invert_yaxis()
    ax.set_xlabel("share of mobility-aid pixels (%)")
    ax.set_title("Mobility-aid area")
    return _save(fig, path)


def aid_users(occlusion_hist: dict, size_hist: dict, path: Path) -> Path:
    """Two bar charts: aid users per occlusion bucket and per visible-pixel bucket."""
    plt = _pyplot()
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4))
    for ax, hist, label in ((a, occlusion_hist, "occlusion"), (b, size_hist, "visible pixels (person + device)")):
        e = hist["edges"]
        ticks = [f"{e[i]:g}–{e[i + 1]:g}" if e[i + 1] < 1e9 else f"≥ {e[i]:g}" for i in range(len(e) - 1)]
        ax.bar(np.arange(len(ticks)), hist["counts"], color="#aa3377")
        ax.set_xticks(np.arange(len(ticks)), ticks, rotation=45, ha="right", fontsize=8)
        ax.set_xlabel(label)
        ax.set_ylabel("aid users")
    fig.suptitle("Mobility-aid users: occlusion and size")
    return _save(fig, path)


def confusion_heatmap(names, matrix: np.ndarray, path: Path) -> Path:
    """Row-normalised confusion matrix (ground truth rows, predictions columns) of the classes that occur."""
    plt = _pyplot()
    m = np.asarray(matrix, np.float64)
    keep = np.flatnonzero((m.sum(axis=0) + m.sum(axis=1)) > 0)
    sub = m[np.ix_(keep, keep)]
    rows = sub.sum(axis=1, keepdims=True)
    norm = np.divide(sub, rows, out=np.zeros_like(sub), where=rows > 0)
    fig, ax = plt.subplots(figsize=(9, 8))
    im = ax.imshow(norm, cmap="Blues", vmin=0, vmax=1)
    ax.set_xticks(np.arange(len(keep)), [names[i] for i in keep], rotation=75, ha="right", fontsize=7)
    ax.set_yticks(np.arange(len(keep)), [names[i] for i in keep], fontsize=7)
    ax.set_xlabel("predicted")
    ax.set_ylabel("ground truth")
    fig.colorbar(im, ax=ax, label="share of the ground-truth class's pixels")
    ax.set_title("Confusion matrix")
    return _save(fig, path)


def diversity(figures: dict, path: Path) -> Path:
    """Six bar charts of a randomised dataset's diversity (:mod:`synthua_usd.analytics.diversity`): the people
    shown by age, build and Monk skin tone, their upper garments' colours, the sun's elevation and the cameras'
    heights above the ground."""
    plt = _pyplot()
    fig, axes = plt.subplots(2, 3, figsize=(14, 7))
    people, sun = figures["people"], figures["sun"]

    def ranges(hist, unit=""):
        e = hist["edges"]
        return [f"{e[i]:g}–{e[i + 1]:g}{unit}" if e[i + 1] < 1e8 else f"≥ {e[i]:g}{unit}" for i in range(len(e) - 1)]

    panels = [
        (ranges(people["age_years"]), people["age_years"]["counts"], "age (years)", "people shown"),
        (["< 18.5", "18.5–25", "25–30", "≥ 30"], people["body_mass_index"]["counts"], "body-mass index", "people shown"),
        (list(people["monk_skin_tone"]), list(people["monk_skin_tone"].values()), "Monk skin tone", "people shown"),
        (list(people["upper_garment_colour"]), list(people["upper_garment_colour"].values()), "upper garment",
         "people shown"),
        (ranges(sun["elevation_deg"]), sun["elevation_deg"]["counts"], "sun elevation (degrees)", "images"),
        (ranges(figures["camera_height_m"], " m"), figures["camera_height_m"]["counts"], "camera height above ground",
         "images"),
    ]
    for ax, (ticks, counts, label, unit) in zip(axes.ravel(), panels):
        keep = [k for k, c in enumerate(counts) if c] or list(range(len(counts)))
        ax.bar(np.arange(len(keep)), [counts[k] for k in keep], color="#4477aa")
        ax.set_xticks(np.arange(len(keep)), [ticks[k] for k in keep], rotation=45, ha="right", fontsize=8)
        ax.set_xlabel(label)
        ax.set_ylabel(unit)
    fig.suptitle(f"Scene diversity: {figures['distinct_scenes']} scenes, {figures['distinct_view_layers']} view layers, "
                 f"{people['count']} people shown")
    fig.tight_layout()
    return _save(fig, path)


def box_panels(panels: list[tuple[np.ndarray, tuple, tuple | None, str]], path: Path, empty: str,
               columns: int = 4) -> Path:
    """A grid of crops, ``empty`` written when there are none: per panel an (h, w, 3) uint8 crop, the box it shows
    (x, y, w, h in crop pixels, drawn red: a missed box, a false positive), another box or None (dashed yellow: the
    detection nearest the miss, the box the false positive lands on) and a caption."""
    from matplotlib.patches import Rectangle

    plt = _pyplot()
    rows = max(1, -(-len(panels) // columns))
    fig, axes = plt.subplots(rows, columns, figsize=(3.2 * columns, 3.4 * rows), squeeze=False)
    for ax in axes.ravel():
        ax.axis("off")
    for ax, (crop, box, detection, caption) in zip(axes.ravel(), panels):
        ax.imshow(crop, interpolation="nearest")
        ax.add_patch(Rectangle(box[:2], box[2], box[3], fill=False, edgecolor="red", linewidth=2))
        if detection is not None:
            ax.add_patch(Rectangle(detection[:2], detection[2], detection[3], fill=False, edgecolor="yellow",
                                   linewidth=1.5, linestyle="--"))
        ax.set_title(caption, fontsize=7)
    if not panels:
        axes[0, 0].text(0.5, 0.5, empty, ha="center", va="center")
    return _save(fig, path)


def distribution_comparison(samples: dict, rows: list[str], measures: list[str], labels: dict[str, str],
                            statistics: dict, path: Path, log_x: tuple[str, ...] = ()) -> Path:
    """Empirical distribution functions of two samples per panel (ours blue, real orange): one row per class name of
    ``rows``, one column per measure of ``measures``; ``samples`` (measure, row) -> (ours, real) arrays (a panel
    without samples is left blank), ``labels`` measure -> axis label, ``statistics`` (measure, row) -> the KS
    statistic shown in the panel's title (the largest vertical gap between the two curves); measures in ``log_x`` on
    a logarithmic axis (ratios)."""
    plt = _pyplot()
    fig, axes = plt.subplots(len(rows), len(measures), figsize=(3.3 * len(measures), 2.6 * len(rows)), squeeze=False)
    for r, name in enumerate(rows):
        for c, measure in enumerate(measures):
            ax = axes[r, c]
            if (measure, name) not in samples:
                ax.axis("off")
                continue
            for values, colour, side in zip(samples[measure, name], ("#4477aa", "#ee7733"), ("ours", "real")):
                if len(values):
                    x = np.sort(values)
                    ax.step(x, np.arange(1, len(x) + 1) / len(x), where="post", color=colour,
                            label=f"{side} ({len(x)})")
            d = statistics.get((measure, name))
            ax.set_title(f"{name}: D = {d:.2f}" if d is not None else f"{name}: no values", fontsize=9)
            ax.set_xlabel(labels[measure], fontsize=8)
            ax.set_ylim(0, 1.02)
            if measure in log_x:
                ax.set_xscale("log")
            ax.tick_params(labelsize=7)
            ax.legend(fontsize=7, loc="lower right")
    fig.suptitle("Ours against the real set: empirical distribution functions (KS statistic D)")
    fig.tight_layout()
    return _save(fig, path)


def low_data_curve(panels: dict[str, dict[str, dict]], title: str, path: Path, measure: str = "AP50") -> Path:
    """One panel per class (``panels``: class -> arm label -> series): a series with ``x`` (real training images)
    draws its ``mean`` as a line with markers and its ``lo``..``hi`` (e.g. the seeds' min and max) as error bars and
    shaded; one without ``x`` (an arm that sees no real image) is a dashed level across the panel, its range shaded the
    same way. Values are fractions, drawn in %; x on a log scale, ticked at the sizes."""
    plt = _pyplot()
    fig, axes = plt.subplots(1, max(1, len(panels)), figsize=(5.2 * max(1, len(panels)), 4.2), squeeze=False)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    sizes = sorted({x for series in panels.values() for s in series.values() for x in (s.get("x") or [])})
    for ax, (name, series) in zip(axes[0], panels.items()):
        for k, (label, s) in enumerate(series.items()):
            colour = colours[k % len(colours)]
            mean, lo, hi = (100 * np.asarray(s[key], dtype=float) for key in ("mean", "lo", "hi"))
            if s.get("x"):
                ax.errorbar(s["x"], mean, yerr=[mean - lo, hi - mean], fmt="o-", capsize=3, color=colour, label=label)
                ax.fill_between(s["x"], lo, hi, color=colour, alpha=0.2, linewidth=0)
            else:
                ax.axhline(float(mean[0]), color=colour, linestyle="--", label=label)
                ax.axhspan(float(lo[0]), float(hi[0]), color=colour, alpha=0.15, linewidth=0)
        if len(sizes) > 1:
            ax.set_xscale("log")
        if sizes:
            ax.set_xticks(sizes)
            ax.set_xticklabels([str(x) for x in sizes])
            ax.minorticks_off()
        ax.set_xlabel("real training images")
        ax.set_ylabel(f"{name} {measure} (%)")
        ax.set_ylim(0, max(1.0, ax.get_ylim()[1]))      # all zeros still shows a scale in %
        ax.grid(alpha=0.3)
        ax.set_title(name)
        ax.legend(fontsize=8)
    fig.suptitle(title, fontsize=10)
    return _save(fig, path)
