"""tools/paste_control.py: real boxes pasted into other photos, the pixels and both COCO scorings checked against an
independent computation (PIL's own crop and resize, box areas by hand)."""

import json

import numpy as np
import pytest
from PIL import Image

from conftest import load_tool

W, H = 160, 120
BOXES = {  # image stem: (class, x0, y0, w, h) in pixels; image 2 has no wheelchair box fit to paste (too small)
    "a": [("wheelchair", 10, 20, 40, 60), ("person", 100, 10, 30, 90)],
    "b": [("wheelchair", 90, 50, 50, 64)],
    "c": [("wheelchair", 5, 5, 20, 30), ("person", 60, 30, 40, 80)],
    "d": [("wheelchair", 50, 30, 44, 70)],
}


@pytest.fixture(scope="module")
def tool():
    return load_tool("paste_control.py", "paste_control")


@pytest.fixture()
def photos(tmp_path):
    root = tmp_path / "photos"
    (root / "images" / "test").mkdir(parents=True)
    (root / "labels" / "test").mkdir(parents=True)
    rng = np.random.default_rng(7)
    for stem, boxes in BOXES.items():
        Image.fromarray(rng.integers(0, 256, (H, W, 3), dtype=np.uint8)).save(root / "images" / "test" / f"{stem}.png")
        lines = [f"{['person', 'wheelchair'].index(c)} {(x + w / 2) / W} {(y + h / 2) / H} {w / W} {h / H}"
                 for c, x, y, w, h in boxes]
        (root / "labels" / "test" / f"{stem}.txt").write_text("\n".join(lines) + "\n")
    (root / "data.yaml").write_text(f"path: {root}\ntest: images/test\nnames:\n  0: person\n  1: wheelchair\n")
    return root


def _cover(box, rect):
    _, x, y, w, h = box
    ix = max(0, min(x + w, rect[0] + rect[2]) - max(x, rect[0]))
    iy = max(0, min(y + h, rect[1] + rect[3]) - max(y, rect[1]))
    return ix * iy / (w * h)


def test_each_image_gets_a_real_box_from_another_photo_and_both_scorings(tool, photos, tmp_path):
    out = tmp_path / "control"
    assert tool.main([str(photos), "--class", "wheelchair", "--out", str(out), "--seed", "3"]) == 0
    record = json.loads((out / "control.json").read_text())
    stems = sorted(BOXES)
    assert [p["background"].rsplit("/", 1)[1] for p in record["pastes"]] == [f"{s}.png" for s in stems]
    docs = {g: json.loads((out / f"{g}.json").read_text()) for g in ("pasted", "photo")}
    for k, (stem, paste) in enumerate(zip(stems, record["pastes"]), 1):
        donor = paste["donor"].rsplit("/", 1)[1][:-4]
        assert donor != stem and donor != "c"                      # another photo; c's wheelchair is too small
        donor_box = next(b for b in BOXES[donor] if b[0] == "wheelchair")
        assert paste["donor_box"] == pytest.approx(list(donor_box[1:]))
        x, y, w, h = paste["box"]
        assert 0 <= x and x + w <= W and y >= 0 and y + h <= H and y + h >= 0.55 * H
        assert w / h == pytest.approx(donor_box[3] / donor_box[4], abs=0.05)
        # pixels: the background outside the rectangle, the donor's box resized inside it, beyond the feathered edge
        background = np.asarray(Image.open(photos / "images" / "test" / f"{stem}.png")).astype(int)
        made = np.asarray(Image.open(out / "images" / f"{k:06d}.png")).astype(int)
        outside = np.ones((H, W), bool)
        outside[y:y + h, x:x + w] = False
        assert np.array_equal(made[outside], background[outside])
        _, dx, dy, dw, dh = donor_box
        crop = Image.open(photos / "images" / "test" / f"{donor}.png").crop((dx, dy, dx + dw, dy + dh))
        expected = np.asarray(crop.resize((w, h), Image.Resampling.BILINEAR)).astype(int)
        edge = tool.FEATHER_PX
        assert np.abs(made[y + edge:y + h - edge, x + edge:x + w - edge] - expected[edge:-edge, edge:-edge]).max() <= 1
        # scorings: the scored group as it is, the other group (and covered photo boxes) crowd in every class
        for group, doc in docs.items():
            anns = [a for a in doc["annotations"] if a["image_id"] == k]
            scored = sorted((a["category_id"], tuple(a["bbox"])) for a in anns if not a["iscrowd"])
            crowd = sorted((a["category_id"], tuple(a["bbox"])) for a in anns if a["iscrowd"])
            paste_box = (float(x), float(y), float(w), float(h))
            own = [(2 if c == "wheelchair" else 1, (float(bx), float(by), float(bw), float(bh)))
                   for c, bx, by, bw, bh in BOXES[stem]]
            covered = [b for b, o in zip(BOXES[stem], own) if _cover(b, paste["box"]) > 0.5]
            kept = [o for b, o in zip(BOXES[stem], own) if _cover(b, paste["box"]) <= 0.5]
            if group == "pasted":
                assert scored == [(2, paste_box)]
                assert crowd == sorted((c, o[1]) for o in own for c in (1, 2))
            else:
                assert scored == sorted(kept)
                assert crowd == sorted([(c, paste_box) for c in (1, 2)]
                                       + [(c, (float(b[1]), float(b[2]), float(b[3]), float(b[4])))
                                          for b in covered for c in (1, 2)])


def test_both_files_read_by_the_project_reader_and_pycocotools(tool, photos, tmp_path):
    from pycocotools.coco import COCO

    from synthua_usd.analytics.detection_sets import read_coco

    out = tmp_path / "control"
    assert tool.main([str(photos), "--class", "wheelchair", "--out", str(out)]) == 0
    for group in ("pasted", "photo"):
        found = read_coco(out / f"{group}.json")
        assert len(found.images) == len(BOXES) and found.names == ("person", "wheelchair")
        coco = COCO(str(out / f"{group}.json"))
        assert len(coco.getImgIds()) == len(BOXES)
    scored = [b for im in read_coco(out / "pasted.json").images for b in im.boxes if not b.ignore]
    assert len(scored) == len(BOXES) and {b.label for b in scored} == {"wheelchair"}


def test_the_seed_alone_decides_the_pastes(tool, photos, tmp_path):
    for name, seed in (("one", 1), ("again", 1), ("other", 2)):
        out = tmp_path / name
        assert tool.main([str(photos), "--class", "wheelchair", "--out", str(out), "--seed", str(seed)]) == 0
    read = lambda name: json.loads((tmp_path / name / "control.json").read_text())["pastes"]  # noqa: E731
    assert read("one") == read("again") != read("other")


@pytest.mark.parametrize("argv, message", [
    (["--class", "cane"], "--class: 'cane'; expected a class of"),
    (["--class", "person"], "boxes of class 'person' fit to paste"),
])
def test_refusals_are_one_line_and_write_nothing(tool, photos, tmp_path, capsys, argv, message):
    out = tmp_path / "control"
    assert tool.main([str(photos), "--out", str(out)] + argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("synthua: error: ") and message in err and "\n" not in err
    assert not out.exists() and not [p for p in tmp_path.iterdir() if p.name.startswith(".control")]


def test_a_photo_box_the_paste_covers_is_ignored_in_both_scorings(tool, photos):
    from synthua_usd.analytics.detection_sets import read_yolo

    found = read_yolo(photos / "data.yaml", "test")
    donor = next(b for b in found.images[1].boxes if b.label == "wheelchair")
    # over image a's wheelchair (10, 20, 40, 60): 30 x 60 of its 40 x 60 covered (75 %); its person (100, 10, 30, 90)
    # 10 x 60 of 30 x 90 (22 %): kept
    pastes = [tool.Paste(1, donor, 20, 20, 60, 60)] + [tool.Paste(0, donor, 0, 0, 10, 10)] * 3
    photo = tool.coco(found, "wheelchair", pastes, "photo")
    scored = [(a["category_id"], a["bbox"]) for a in photo["annotations"] if a["image_id"] == 1 and not a["iscrowd"]]
    assert scored == [(1, [100.0, 10.0, 30.0, 90.0])]
    crowd = sorted((a["category_id"], a["bbox"]) for a in photo["annotations"] if a["image_id"] == 1 and a["iscrowd"])
    assert crowd == [(1, [10.0, 20.0, 40.0, 60.0]), (1, [20, 20, 60, 60]), (2, [10.0, 20.0, 40.0, 60.0]),
                     (2, [20, 20, 60, 60])]
