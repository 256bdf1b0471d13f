"""The report of a sim-to-real experiment (``tools/sim2real.py``): its markdown tables and its low-data curve, both
from the experiment's JSON document (``sim2real.json``: ``plan``, ``runs``, ``scores``, ``summary``, ``comparisons``,
``notes``).

Each score cell is the mean over seeds in %, then the seeds' min–max and sample standard deviation (n − 1):
``35.0 (31.0–39.0) sd 4.0``; one seed gives the value alone, no seed (no box of the class) ``–``.
"""

from __future__ import annotations

from pathlib import Path

from synthua_usd.analytics.detection_metrics import FP_KINDS
from synthua_usd.analytics.detection_report import FP_KIND_TEXT
from synthua_usd.analytics.plots import low_data_curve
from synthua_usd.pipeline.init_weights import describe
from synthua_usd.pipeline.sim2real import ARMS


def cell(s: dict) -> str:
    """One :func:`~synthua_usd.pipeline.sim2real.spread` in %."""
    if not s["n"]:
        return "–"
    if s["n"] == 1:
        return f"{100 * s['mean']:.1f}"
    return f"{100 * s['mean']:.1f} ({100 * s['min']:.1f}–{100 * s['max']:.1f}) sd {100 * s['std']:.1f}"


def arm_label(arm: str) -> str:
    return f"({arm}) {ARMS[arm]}"


def _steps(run: dict, runs: dict[str, dict]) -> str:
    text = f"{run['epochs']} × {run['images']:,} = {run['image_steps']:,}"
    if run.get("pretraining"):
        a = runs.get(run["pretraining"])
        text += f" after (a)'s {a['image_steps']:,}" if a else f" after {run['pretraining']}"
    return text


def _score_tables(document: dict) -> list[str]:
    runs = {r["name"]: r for r in document["runs"]}
    lines = []
    for test in document["plan"]["tests"]:
        rows = [s for s in document["summary"] if s["test"] == test["label"]]
        if not rows:
            continue
        classes = list(dict.fromkeys(s["class"] for s in rows))
        lines += [f"**{test['label']}**: `{test['path']}` ({test['split'] or 'whole'} split, {test['images']} images)", "",
                  "| arm | real images | seeds | epochs × images = image-steps | "
                  + " | ".join(f"{c} AP50 | {c} AP50-95" for c in classes) + " |",
                  "|---|---|---|---|" + "---|---|" * len(classes)]
        groups = list(dict.fromkeys((s["arm"], s["real_images"]) for s in rows))
        for arm, n in groups:
            by_class = {s["class"]: s for s in rows if (s["arm"], s["real_images"]) == (arm, n)}
            seeds = next(iter(by_class.values()))["seeds"]
            first = next(r for r in document["runs"] if r["arm"] == arm and r["real_images"] == n)
            mixed = f" + {first['mixed_images']:,} mixed" if first.get("mixed_images") else ""
            cells = [arm_label(arm), ("–" if n is None else f"{n:,}") + mixed, ",".join(map(str, seeds)),
                     _steps(first, runs)]
            for c in classes:
                s = by_class.get(c)
                cells += [cell(s["AP50"]), cell(s["AP50_95"])] if s else ["–", "–"]
            lines.append("| " + " | ".join(cells) + " |")
        lines.append("")
    return lines


def _signed(x: float) -> str:
    return f"{100 * x:+.1f}"


def _comparison_table(document: dict) -> list[str]:
    """Each arm against (b): :func:`~synthua_usd.pipeline.sim2real.compare`'s rows, in points."""
    rows = document.get("comparisons") or []
    if not rows:
        return []
    first = rows[0]
    lines = [f"**Against {arm_label(first['baseline'])}**, {first['measure']} in points (the arm minus "
             f"({first['baseline']}); {100 * first['confidence']:.0f} % interval of the difference of the means by "
             f"Welch's t, unequal variances):", "",
             "| test | class | real images | arm | difference of the means | seed by seed | interval | beyond the "
             "seeds' spread | seeds' ranges overlap |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        by_seed = (", ".join(map(_signed, r["per_seed"])) + f" (seeds {','.join(map(str, r['common_seeds']))})"
                   if r["per_seed"] else "–")
        if r["low"] is None:
            interval, beyond = "– (under 2 seeds)", "–"
        else:
            interval = f"{_signed(r['low'])} to {_signed(r['high'])}" + (f" (df {r['df']:.1f})" if r["df"] else "")
            beyond = "yes" if r["beyond"] else "no"
        size = "–" if r["real_images"] is None else f"{r['real_images']:,}"
        lines.append(f"| {r['test']} | {r['class']} | {size} | "
                     f"{arm_label(r['arm'])} | {_signed(r['difference'])} | {by_seed} | {interval} | {beyond} | "
                     f"{'yes' if r['ranges_overlap'] else 'no'} |")
    return lines + ["", "Beyond the seeds' spread: the whole interval above zero, a difference the seeds' scatter "
                    "does not explain. A difference of at least X beyond the spread, read strictly: the interval's "
                    "lower end at X or above.", ""]


#: The false-positive table's columns: a count of :data:`~synthua_usd.pipeline.sim2real.COUNTS` and its heading.
FP_COLUMNS = (("tp", "TP"), ("fp", "FP")) + tuple((f"fp_{kind}", FP_KIND_TEXT[kind]) for kind in FP_KINDS)


def _count(s: dict) -> str:
    if not s["n"]:
        return "–"
    return f"{s['mean']:.0f}" if s["n"] == 1 else f"{s['mean']:.1f} ({s['min']:.0f}–{s['max']:.0f})"


def _false_positive_table(document: dict) -> list[str]:
    """Per test set, arm and class: true and false positives at the detection confidence, the false positives by
    what they land on (``synthua evaluate-real``'s kinds); the mean over seeds, then the seeds' min–max."""
    rows = [s for s in document["summary"] if s.get("fp", {}).get("n")]
    if not rows:
        return []
    confidence = {r.get("confidence") for r in document["scores"]} - {None}
    at = f"at confidence {confidence.pop():g}" if len(confidence) == 1 else "at the detection confidence"
    lines = [f"**False positives {at}** (IoU 0.5), by what they land on, the first that holds (TIDE's rules): IoU "
             "0.1 to 0.5 with a box of their class; 0.5 or more with another class's; 0.5 or more with one of their "
             "class another detection took; 0.1 or less with every box; else 0.1 to 0.5 with another class's. The "
             "mean over seeds, then the seeds' min–max:", "",
             "| test | class | arm | real images | " + " | ".join(h for _, h in FP_COLUMNS) + " |",
             "|---|---|---|---|" + "---|" * len(FP_COLUMNS)]
    for s in rows:
        size = "–" if s["real_images"] is None else f"{s['real_images']:,}"
        lines.append(f"| {s['test']} | {s['class']} | {arm_label(s['arm'])} | {size} | "
                     + " | ".join(_count(s[k]) for k, _ in FP_COLUMNS) + " |")
    return lines + [""]


def _run_table(document: dict) -> list[str]:
    lines = ["| run | trained on | images | epochs (last without mosaic) | image-steps | from | seconds | images/s | device |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in document["runs"]:
        speed = f"{r['images_per_s']:.1f}" if r.get("images_per_s") else "–"
        lines.append(f"| {r['name']} | `{r['train_set']}` | {r['images']:,} | {r['epochs']} ({r.get('close_mosaic', 10)}) | "
                     f"{r['image_steps']:,} | "
                     f"{describe(r['init'], r['model'])} | {r['seconds']:.0f} | {speed} | {r['device']} |")
    return lines + [""]


def markdown(document: dict) -> str:
    """The experiment's tables: scores per test set (arms × real sizes, mean and spread over seeds), then every run,
    the notes (rounding of epochs, too few seeds) and the command."""
    plan = document["plan"]
    versions = next((r["versions"] for r in document["runs"] if r.get("versions")), {})
    lines = [f"Sim-to-real, {document['date'][:10]}: arms {', '.join(arm_label(a) for a in plan['arms'])}; "
             f"{plan['budget_images']:,} image-steps a training"
             + (f" ({plan['synthetic_budget_images']:,} for (a))" if plan.get("synthetic_budget_images") not in
                (None, plan["budget_images"]) else "")
             + f", imgsz {plan['imgsz']}, batch {plan['batch']}; seeds {', '.join(map(str, plan['seeds']))}; every arm "
               f"from {describe(plan['init'], plan['model'])}"
             + (f"; real subsets drawn with seed {plan['subset_seed']} from {plan['real_photos']:,} photos"
                if plan.get("real_photos") else "")
             + (f"; Ultralytics {versions.get('ultralytics')}, torch {versions.get('torch')}" if versions else "")
             + ".", ""]
    lines += _score_tables(document)
    lines += ["AP by pycocotools' COCOeval (bbox, area all, 100 detections an image), in %: the mean over seeds, "
              "(min–max) and sd, the sample standard deviation (n − 1).", ""]
    lines += _comparison_table(document)
    lines += _false_positive_table(document)
    lines += _run_table(document)
    if document.get("notes"):
        lines += [f"- {note}" for note in document["notes"]] + [""]
    lines += ["```", document["command"], "```"]
    return "\n".join(lines) + "\n"


def curve(document: dict, path: Path, classes: list[str], test: str | None = None, measure: str = "AP50") -> Path | None:
    """The low-data curve of test set ``test`` (default: the first): ``measure`` of each of ``classes`` (those the
    test scores) against real training images, a line per arm with the seeds' min–max; (a) as a level. None when
    the test scores none of the classes."""
    test = test or document["plan"]["tests"][0]["label"]
    rows = [s for s in document["summary"] if s["test"] == test and s["class"] in classes]
    panels: dict[str, dict[str, dict]] = {}
    for name in (c for c in classes if any(s["class"] == c for s in rows)):
        series: dict[str, dict] = {}
        for arm in ARMS:
            mine = sorted((s for s in rows if s["class"] == name and s["arm"] == arm and s[measure]["n"]),
                          key=lambda s: -1 if s["real_images"] is None else s["real_images"])
            if mine:
                series[arm_label(arm)] = {"x": [s["real_images"] for s in mine] if arm != "a" else None,
                                          "mean": [s[measure]["mean"] for s in mine],
                                          "lo": [s[measure]["min"] for s in mine],
                                          "hi": [s[measure]["max"] for s in mine]}
        panels[name] = series
    if not panels:
        return None
    plan = document["plan"]
    title = (f"{test}: {measure}, mean and min–max over seeds {', '.join(map(str, plan['seeds']))}; "
             f"{plan['budget_images']:,} image-steps a training, from {describe(plan['init'], plan['model'])}")
    return low_data_curve(panels, title, path, measure)
