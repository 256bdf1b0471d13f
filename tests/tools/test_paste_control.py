"""tools/paste_control.py: real boxes pasted into other photos, the pixels and both COCO scorings checked against an
independent computation (PIL's own crop and resize, box areas by hand)."""

import json
from dataclasses import replace

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


def test_the_feather_ramps_over_its_edge_pixels(tool):
    alpha = tool.feather(12, 10)
    ramp = [0.125, 0.375, 0.625, 0.875]
    assert alpha[5].tolist() == ramp + [1.0] * 4 + ramp[::-1]
    assert alpha[:, 6].tolist() == ramp + [1.0] * 2 + ramp[::-1]
    assert alpha[0, 0] == 0.125 and alpha[1, 3] == 0.375


def test_sizes_and_places_follow_the_rules(tool, photos, tmp_path):
    """The paste's height is the donor's share of its image times 0.7-1 of this one's, and of 20 draws the paste
    takes one that leaves the photo's boxes uncovered when such places are common (here: the right 80 of 160 px)."""
    from synthua_usd.analytics.detection_sets import Box, read_yolo

    found = read_yolo(photos / "data.yaml", "test")
    for seed in range(10):
        for image, paste in zip(found.images, tool.plan(found, "wheelchair", seed)):
            share = paste.source.h / found.images[paste.donor].height
            assert 0.7 * share * H - 0.5 <= paste.h <= share * H + 0.5
            assert paste.y + paste.h >= 0.55 * H and paste.x + paste.w <= W
    # one photo's boxes fill its lower-left quarter; the pastes (at most 64 px wide) fit right of x = 80 in about
    # a third of the draws: all 20 draws missing is about 0.67 ** 20, so every seed finds a free place
    blocked = replace(found.images[0], boxes=(Box("person", 0, 60, 80, 60),))
    crowded = replace(found, images=(blocked,) + found.images[1:])
    for seed in range(10):
        paste = tool.plan(crowded, "wheelchair", seed)[0]
        assert tool.cover(blocked.boxes[0], paste.x, paste.y, paste.w, paste.h) == 0.0, seed


def test_a_box_half_covered_is_kept_and_the_donor_s_neighbours_are_regions(tool, photos):
    from synthua_usd.analytics.detection_sets import Box, read_yolo

    found = read_yolo(photos / "data.yaml", "test")
    # image a's wheelchair (10, 20, 40, 60): exactly half covered by (30, 0, 40, 120), scored in photo.json
    donor = Box("wheelchair", 20.0, 30.0, 40.0, 60.0)
    neighbour = Box("person", 50.0, 10.0, 40.0, 100.0)      # its cut (20..60, 30..90) reaches x 50..60, y 30..90
    found = replace(found, images=found.images[:3] + (replace(found.images[3], boxes=(donor, neighbour)),))
    pastes = [tool.Paste(3, donor, 30, 0, 20, 30)] + [tool.Paste(0, found.images[0].boxes[0], 0, 0, 10, 10)] * 3
    photo = tool.coco(found, "wheelchair", [tool.Paste(3, donor, 30, 0, 40, 120)] + pastes[1:], "photo")
    scored = sorted((a["category_id"], a["bbox"]) for a in photo["annotations"] if a["image_id"] == 1
                    and not a["iscrowd"])
    assert scored == [(1, [100.0, 10.0, 30.0, 90.0]), (2, [10.0, 20.0, 40.0, 60.0])]
    # the paste (30, 0, 20, 30) is the cut scaled by 0.5: the neighbour's part (50..60, 30..90) lands at
    # x 30 + 30 * 0.5 = 45, y 0, 10 * 0.5 = 5 wide, 60 * 0.5 = 30 high
    pasted = tool.coco(found, "wheelchair", pastes, "pasted")
    crowd = sorted((a["category_id"], a["bbox"]) for a in pasted["annotations"] if a["image_id"] == 1
                   and a["iscrowd"])
    assert crowd == sorted([(c, [10.0, 20.0, 40.0, 60.0]) for c in (1, 2)] + [(c, [100.0, 10.0, 30.0, 90.0])
                                                                             for c in (1, 2)]
                           + [(c, [45.0, 0.0, 5.0, 30.0]) for c in (1, 2)])


def test_a_coco_set_s_crowd_box_is_no_donor_and_stays_its_own_class_s_region(tool, photos, tmp_path):
    import shutil

    root = tmp_path / "coco"
    root.mkdir()
    images, annotations = [], []
    for k, (stem, boxes) in enumerate(BOXES.items(), 1):
        shutil.copy(photos / "images" / "test" / f"{stem}.png", root / f"{stem}.png")
        images.append({"id": k, "file_name": f"{stem}.png", "width": W, "height": H})
        for c, x, y, w, h in boxes:
            annotations.append({"id": len(annotations) + 1, "image_id": k, "category_id": 1 + (c == "wheelchair"),
                                "bbox": [x, y, w, h], "area": w * h, "iscrowd": 0})
    crowd_box = [100, 20, 50, 80]                           # a wheelchair crowd on image d: big enough to paste
    annotations.append({"id": len(annotations) + 1, "image_id": 4, "category_id": 2, "bbox": crowd_box,
                        "area": 4000, "iscrowd": 1})
    (root / "set.json").write_text(json.dumps({"images": images, "annotations": annotations, "categories": [
        {"id": 1, "name": "person"}, {"id": 2, "name": "wheelchair"}]}))
    for seed in range(6):
        out = tmp_path / f"c{seed}"
        assert tool.main([str(root / "set.json"), "--class", "wheelchair", "--out", str(out), "--seed", str(seed)]) == 0
        record = json.loads((out / "control.json").read_text())
        assert all(p["donor_box"] != crowd_box for p in record["pastes"])
        photo = json.loads((out / "photo.json").read_text())
        paste = record["pastes"][3]["box"]
        rows = sorted(a["category_id"] for a in photo["annotations"] if a["image_id"] == 4 and a["bbox"] == crowd_box)
        covered = _cover(("wheelchair", *crowd_box), paste) > 0.5
        assert rows == ([1, 2] if covered else [2]), seed


def test_photos_are_read_as_the_composites_read_them(tool, photos, tmp_path):
    """A 16-bit grey photo: its pixels x / 257, rounded, in all three channels, and the paste made grey too."""
    raw = np.random.default_rng(3).integers(0, 65536, (H, W), dtype=np.uint16)
    Image.fromarray(raw).save(photos / "images" / "test" / "a.png")         # replaces a (its labels kept)
    out = tmp_path / "control"
    assert tool.main([str(photos), "--class", "wheelchair", "--out", str(out)]) == 0
    x, y, w, h = json.loads((out / "control.json").read_text())["pastes"][0]["box"]
    made = np.asarray(Image.open(out / "images" / "000001.png").convert("RGB")).astype(int)
    outside = np.ones((H, W), bool)
    outside[y:y + h, x:x + w] = False
    expected = (raw.astype(int) + 128) // 257
    for channel in range(3):
        assert np.array_equal(made[..., channel][outside], expected[outside])
    assert np.array_equal(made[..., 0], made[..., 1]) and np.array_equal(made[..., 1], made[..., 2])


@pytest.mark.parametrize("argv, message", [
    (["--class", "wheelchair", "--seed", "-1"], "--seed: -1; expected a whole number >= 0"),
    (["--class", "wheelchair", "--out", "EXISTS"], ": exists; expected a new folder"),
])
def test_a_negative_seed_and_an_existing_folder_are_refused(tool, photos, tmp_path, capsys, argv, message):
    out = tmp_path / "control"
    if "EXISTS" in argv:
        out.mkdir()
        (out / "kept.txt").write_text("mine")
        argv = [str(out) if a == "EXISTS" else a for a in argv]
    assert tool.main([str(photos), "--out", str(out)] + argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("synthua: error: ") and message in err and "\n" not in err
    assert not out.exists() or sorted(p.name for p in out.iterdir()) == ["kept.txt"]


def test_a_photo_too_small_to_paste_into_is_refused(tool, photos, tmp_path, capsys):
    Image.new("RGB", (20, 20)).save(photos / "images" / "test" / "e.png")
    assert tool.main([str(photos), "--class", "wheelchair", "--out", str(tmp_path / "control")]) == 2
    err = capsys.readouterr().err.strip()
    assert "e.png: 20x20 pixels; expected at least 32x32 to paste into" in err and not (tmp_path / "control").exists()


def test_a_generated_dataset_is_refused(tool, generated, tmp_path, capsys):
    assert tool.main([str(generated), "--class", "manual_wheelchair", "--out", str(tmp_path / "control")]) == 2
    assert "a dataset synthua wrote; expected real labelled photos" in capsys.readouterr().err
