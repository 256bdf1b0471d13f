"""``synthua stats``: the report folder's files, the HTML opened in a real headless Chromium (every image it
references decoded by the browser), and the statistics of a dataset made by ``synthua generate`` checked
against an independent count of its PNGs and COCO files."""

from __future__ import annotations

import csv
import json
import shutil
import subprocess
from collections import Counter
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from analytics import tiny_dataset
from synthua_usd.analytics.report import overlay


class References(HTMLParser):
    def __init__(self):
        super().__init__()
        self.images: list[str] = []
        self.links: list[str] = []

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "img":
            self.images.append(a["src"])
        if tag == "a":
            self.links.append(a["href"])
        for key in ("src", "href"):
            assert not str(a.get(key, "")).startswith(("http:", "https:", "//", "/")), (tag, a)


def references(html: str) -> References:
    parser = References()
    parser.feed(html)
    return parser


def chromium() -> str:
    for name in ("chromium", "chromium-browser", "google-chrome"):
        if shutil.which(name):
            return shutil.which(name)
    pytest.skip("no Chromium on PATH (Debian: apt-get install chromium; tools/setup.sh installs it)")


#: Appended to a copy of the report: after the page has loaded, the body lists the images the browser could
#: not decode and the number it could.
PROBE = """<script>window.addEventListener('load', () => {
  const imgs = [...document.images];
  document.body.setAttribute('data-decoded', imgs.filter(i => i.complete && i.naturalWidth > 0).length);
  document.body.setAttribute('data-broken', imgs.filter(i => !(i.complete && i.naturalWidth > 0))
      .map(i => i.getAttribute('src')).join('|'));
});</script>"""


def open_in_chromium(html_path: Path) -> str:
    """The DOM of ``html_path`` after load, from headless Chromium."""
    probe = html_path.with_name("_probe.html")
    probe.write_text(html_path.read_text().replace("</body>", PROBE + "</body>"))
    done = subprocess.run([chromium(), "--headless", "--no-sandbox", "--disable-gpu", "--allow-file-access-from-files",
                           "--virtual-time-budget=10000", "--dump-dom", probe.as_uri()],
                          capture_output=True, text=True, timeout=120)
    probe.unlink()
    assert done.returncode == 0, done.stderr[-2000:]
    return done.stdout


def test_report_files_and_html_in_a_real_browser(run_cli, tmp_path):
    root = tiny_dataset.write(tmp_path / "ds")
    out = tmp_path / "report"
    code, stdout, err = run_cli("stats", root, "--out", out)
    assert code == 0, err
    assert "2 images (1 QA-rejected left out), 8 objects" in stdout and "50.0 % of images show" in stdout
    html = (out / "report.html").read_text()
    stats = json.loads((out / "statistics.json").read_text())
    contrast = stats["summary"]["image_contrast"]
    (c1, e1), (c2, e2) = tiny_dataset.kept_contrast_and_edges(root).values()
    assert contrast["rms_contrast"]["median"] == pytest.approx((c1 + c2) / 2)
    assert contrast["per_split"]["val"]["edge_density"]["p90"] == pytest.approx(e2)
    assert [r["edge_density"] for r in stats["image_contrast_per_image"]] == pytest.approx([e1, e2])
    assert (f"images: RMS contrast median {(c1 + c2) / 2:.3f} (p10-p90 {min(c1, c2) + 0.1 * abs(c1 - c2):.3f}-"
            f"{min(c1, c2) + 0.9 * abs(c1 - c2):.3f}), edge density median {(e1 + e2) / 2:.3f}") in stdout
    refs = references(html)
    for src in refs.images + refs.links:
        assert (out / src).is_file(), src
    assert len(refs.images) == 7 + 2                              # seven figures, two gallery images
    assert {Path(s).stem for s in refs.images if s.startswith("gallery/")} == set(tiny_dataset.NAMES[:2])
    # the legend: the classes in the gallery's images, each with its colour
    for name, (r, g, b) in (("Road", (128, 64, 128)), ("Manual wheelchair", (255, 170, 255))):
        assert f'<span class="item"><span class="sw" style="background:rgb({r},{g},{b})"></span>{name}</span>' in html
    dom = open_in_chromium(out / "report.html")
    assert 'data-broken=""' in dom, dom[-3000:]
    assert f'data-decoded="{len(refs.images)}"' in dom
    # the contrast table as the browser has it: a row for the dataset and one per split, 3 decimals
    cells = [f"<td>{v:.3f}</td>" for v in (c2, c2, c2, c2, e2, e2, e2, e2)]
    assert "<h2>Image contrast and edges</h2>" in dom and f"<tr><td>split val</td><td>1</td>{''.join(cells)}</tr>" in dom
    assert f"<tr><td>all</td><td>2</td><td>{(c1 + c2) / 2:.3f}</td>" in dom
    rows = list(csv.DictReader((out / "class_statistics.csv").open()))
    assert len(rows) == 36 and {r["name"]: r["instances"] for r in rows}["building"] == "3"
    assert stats["summary"]["gini_pixel_area"] == pytest.approx(2 * 1866 / (36 * 53) - 37 / 36)


def test_gallery_overlay_blends_class_colours_and_keeps_unlabelled(class_map):
    rgb = np.full((2, 2, 3), 100, np.uint8)
    ids = np.array([[0, 1], [18, 0]])
    out = overlay(rgb, ids, class_map.palette())
    assert out[0, 0].tolist() == [100, 100, 100]
    assert out[0, 1].tolist() == [114, 82, 114]          # (100 + road (128, 64, 128)) / 2
    assert out[1, 0].tolist() == [160, 60, 80]           # (100 + person (220, 20, 60)) / 2


def test_stats_errors_are_one_line(run_cli, tmp_path):
    root = tiny_dataset.write(tmp_path / "ds")
    gallery_image = next((root / "images" / "train").iterdir())
    gallery_image.unlink()
    code, _, err = run_cli("stats", root, "--out", tmp_path / "r")
    assert code == 2 and err.count("synthua: error:") == 1 and "file not found; expected the image of record" in err
    assert not (tmp_path / "r").exists()
    code, _, err = run_cli("stats", tmp_path / "nothing", "--out", tmp_path / "r")
    assert code == 2 and "not a folder; expected a dataset folder written by `synthua generate`" in err


@pytest.mark.parametrize("where", [".", "report", "frames/report"])
def test_a_report_inside_a_dataset_is_refused(run_cli, tmp_path, where):
    """`stats DIR --out DIR` wrote its report into the dataset: files its manifest does not list."""
    from hostile import tree_state

    root = tiny_dataset.write(tmp_path / "ds")
    before = tree_state(root)
    code, _, err = run_cli("stats", root, "--out", root / where)
    assert code == 2 and err.count("synthua: error:") == 1 and "dataset folder" in err, err
    assert tree_state(root) == before
    code, _, err = run_cli("eval", "--gt", root, "--pred", root / "images", "--out", root / where)
    assert code == 2 and "dataset folder" in err, err
    assert tree_state(root) == before


def test_stats_of_a_generated_dataset_agree_with_its_pngs_and_coco(generated, run_cli, tmp_path, class_map):
    """Pixel counts from class.png, objects from instance.png (things) and class.png (stuff regions), aid
    classes, per-condition counts from the manifest and records: counted here without analytics code."""
    code, _, err = run_cli("stats", generated, "--out", tmp_path / "report")
    assert code == 0, err
    doc = json.loads((tmp_path / "report" / "statistics.json").read_text())
    manifest = json.loads((generated / "manifest.json").read_text())
    kept = [e for e in manifest["images"] if e["qa"] != "rejected"]
    pixels, objects, per_image = Counter(), Counter(), []
    for e in kept:
        cls = np.array(Image.open(generated / "frames" / e["name"] / "class.png"))
        inst = np.array(Image.open(generated / "frames" / e["name"] / "instance.png"))
        ids, counts = np.unique(cls, return_counts=True)
        pixels.update({class_map.by_id(int(i)).name: int(n) for i, n in zip(ids, counts)})
        n = 0
        for i in ids:
            c = class_map.by_id(int(i))
            if i == 0:
                continue
            if c.isthing:
                k = len(np.unique(inst[cls == i]))
            else:
                k = 1
            objects[c.name] += k
            n += k
        per_image.append(n)
    rows = {r["name"]: r for r in doc["classes"]}
    assert {n: r["pixels"] for n, r in rows.items() if r["pixels"]} == {n: v for n, v in pixels.items()
                                                                         if n != "unlabelled"}
    assert {n: r["instances"] for n, r in rows.items() if r["instances"]} == dict(objects)
    assert doc["instances_per_image"] == per_image
    assert doc["summary"]["images"] == len(kept)
    assert doc["summary"]["unlabelled_share"] == pytest.approx(
        pixels["unlabelled"] / sum(pixels.values()))
    conditions = Counter(json.loads((generated / "records" / f"{e['name']}.json").read_text())["condition"]["name"]
                         for e in kept)
    assert doc["summary"]["images_per_condition"] == dict(conditions)
    measured = [tiny_dataset.contrast_and_edges(generated / "images" / e["split"] / f"{e['name']}.png") for e in kept]
    assert [[r["rms_contrast"], r["edge_density"]] for r in doc["image_contrast_per_image"]] == [
        pytest.approx(list(m), abs=1e-12) for m in measured]
    html = (tmp_path / "report" / "report.html").read_text()
    for src in references(html).images:
        assert (tmp_path / "report" / src).is_file(), src
