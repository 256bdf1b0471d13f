"""``synthua composite`` on bad input: one line ``synthua: error: <file or field>: <found>; <expected>``, exit 2,
and nothing written (not --out, nor a staging folder beside it)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from bank_maker import write_bank, write_photos

CONFIG = {"output": {"width": 64, "height": 48}, "images_per_background": 1}


@pytest.fixture(scope="module")
def good(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("refusal_inputs")
    write_bank(root / "bank")
    write_photos(root / "photos", 2, (96, 72), suffix=".jpg")
    labelled = root / "labelled"
    write_photos(labelled / "images", 2, (96, 72))
    (labelled / "labels").mkdir()
    for k in range(2):
        (labelled / "labels" / f"photo_{k:02d}.txt").write_text("0 0.5 0.5 0.2 0.4\n")
    (root / "config.json").write_text(json.dumps(CONFIG))
    return root


@pytest.fixture
def case(good, tmp_path) -> Path:
    """A copy of the good inputs to spoil."""
    shutil.copytree(good, tmp_path / "in")
    return tmp_path / "in"


def _refused(run_cli, case: Path, backgrounds: Path, *mentions: str, bank: Path | None = None,
             out: Path | None = None) -> str:
    out = out or case / "out"
    code, stdout, err = run_cli("composite", backgrounds, "--bank", bank or case / "bank", "--config",
                                case / "config.json", "--out", out, "--workers", "1")
    lines = err.strip().splitlines()
    assert code == 2, stdout + err
    assert "Traceback" not in err and lines and lines[-1].startswith("synthua: error: "), err
    for mention in mentions:
        assert mention in lines[-1], lines[-1]
    assert not out.exists() or (out.is_dir() and not any(out.iterdir()) or out.name == "full"), "nothing written"
    assert not [p for p in out.parent.iterdir() if ".partial-" in p.name], "no staging folder left"
    return lines[-1]


def test_a_truncated_photo(case, run_cli):
    path = case / "photos" / "photo_01.jpg"
    data = path.read_bytes()
    path.write_bytes(data[:len(data) * 2 // 3])  # its header whole: found when its composite decodes it
    _refused(run_cli, case, case / "photos", "photo_01.jpg", "truncated or damaged", "expected a complete image")


def test_an_unreadable_photo_and_a_heic_without_its_decoder(case, run_cli):
    (case / "photos" / "photo_00.jpg").write_bytes(b"plain text, not a photo")
    _refused(run_cli, case, case / "photos", "photo_00.jpg", "not an image Pillow can read")
    (case / "photos" / "photo_00.jpg").unlink()
    (case / "photos" / "IMG_1.heic").write_bytes(b"\0\0\0\x18ftypheic\0\0\0\0")
    try:
        import pillow_heif  # noqa: F401
    except ImportError:
        _refused(run_cli, case, case / "photos", "IMG_1.heic", "no HEIC decoder is installed", "pillow-heif")


def test_a_photo_smaller_than_the_output(case, run_cli):
    write_photos(case / "photos" / "small", 1, (40, 30))
    _refused(run_cli, case, case / "photos", "photo_00.png: 40x30 pixels", "expected at least the output size 64x48")


def test_a_label_naming_a_missing_image(case, run_cli):
    (case / "labelled" / "labels" / "ghost.txt").write_text("0 0.5 0.5 0.1 0.1\n")
    _refused(run_cli, case, case / "labelled", "ghost.txt", "naming image 'ghost'")


def test_boxes_outside_their_image(case, run_cli):
    (case / "labelled" / "labels" / "photo_01.txt").write_text("0 1.3 0.5 0.2 0.2\n")
    _refused(run_cli, case, case / "labelled", "photo_01.txt: line 1", "expected numbers in [0, 1]")
    coco = {"images": [{"id": 1, "file_name": "photo_00.png", "width": 96, "height": 72}],
            "annotations": [{"id": 1, "image_id": 1, "category_id": 1, "bbox": [80, 10, 30, 20]}],
            "categories": [{"id": 1, "name": "person"}]}
    (case / "labelled" / "images" / "coco.json").write_text(json.dumps(coco))
    _refused(run_cli, case, case / "labelled" / "images" / "coco.json", "annotations[0].bbox: [80, 10, 30, 20]",
             "expected a box inside its image photo_00.png (96x72 pixels)")


def test_a_bank_of_another_version_or_with_a_damaged_file(case, run_cli):
    other = write_bank(case / "bank2", fmt="synthua-cutouts/0")
    _refused(run_cli, case, case / "photos", "bank.json: format: 'synthua-cutouts/0'", "expected 'synthua-cutouts/1'",
             bank=other)
    path = case / "bank" / "cutouts" / "c000002.rgba.png"
    data = bytearray(path.read_bytes())
    data[-30] ^= 0x55
    path.write_bytes(bytes(data))
    _refused(run_cli, case, case / "photos", "c000002.rgba.png: SHA-256 differs from bank.json's")


def test_a_folder_without_photos(case, run_cli):
    (case / "empty").mkdir()
    (case / "empty" / "notes.txt").write_text("no photos here")
    _refused(run_cli, case, case / "empty", "empty: no photos", "expected JPEG, PNG")


def test_a_config_field_and_an_out_that_is_not_empty(case, run_cli):
    (case / "config.json").write_text(json.dumps({**CONFIG, "pastes": {"per_image": [3, 1]}}))
    _refused(run_cli, case, case / "photos", "config.json: pastes.per_image: [3, 1]")
    (case / "config.json").write_text(json.dumps(CONFIG))
    (case / "full").mkdir()
    (case / "full" / "mine.txt").write_text("keep me")
    _refused(run_cli, case, case / "photos", "full: not empty", "expected an empty folder", out=case / "full")
    assert (case / "full" / "mine.txt").read_text() == "keep me"


def test_a_yolo_sets_val_photos_are_not_pasted_into_unless_asked(tmp_path):
    """The photos a detector trained on composites is scored on must not become composites: of a YOLO data.yaml
    naming train and val splits, only the train photos are backgrounds by default."""
    from synthua_usd.pipeline.backgrounds import read_backgrounds

    root = tmp_path / "set"
    from PIL import Image

    for split, names in (("train", ("a", "b")), ("val", ("c",))):
        (root / "images" / split).mkdir(parents=True)
        (root / "labels" / split).mkdir(parents=True)
        for name in names:
            Image.new("RGB", (96, 72), (120, 120, 120)).save(root / "images" / split / f"{name}.png")
            (root / "labels" / split / f"{name}.txt").write_text("0 0.5 0.5 0.2 0.4\n")
    (root / "data.yaml").write_text("path: .\ntrain: images/train\nval: images/val\nnames:\n  0: person\n")
    assert [b.relative for b in read_backgrounds(root, (64, 48)).images] == ["images/train/a.png", "images/train/b.png"]
    assert [b.relative for b in read_backgrounds(root, (64, 48), "val").images] == ["images/val/c.png"]
    assert len(read_backgrounds(root, (64, 48), "all").images) == 3


def _yolo_set(root: Path, train: str = "images/train") -> None:
    from PIL import Image

    (root / "images" / "train").mkdir(parents=True)
    (root / "labels" / "train").mkdir(parents=True)
    Image.new("RGB", (96, 72), (120, 120, 120)).save(root / "images" / "train" / "a.png")
    (root / "labels" / "train" / "a.txt").write_text("0 0.5 0.5 0.2 0.4\n")
    (root / "data.yaml").write_text(f"path: .\ntrain: {train}\nnames:\n  0: person\n")


def test_a_set_of_links_to_photos_elsewhere_is_read_and_a_split_outside_it_is_refused(tmp_path):
    """A nested subset (tools/sim2real.py's) links its photos to the whole set's: a photo listed below the set's
    folder is the set's, wherever its link points; a data.yaml whose split climbs out of the folder is refused."""
    from synthua_usd.core.errors import InputError
    from synthua_usd.pipeline.backgrounds import read_backgrounds

    _yolo_set(tmp_path / "whole")
    subset = tmp_path / "subset"
    for kind, name in (("images", "a.png"), ("labels", "a.txt")):
        (subset / kind / "train").mkdir(parents=True)
        (subset / kind / "train" / name).symlink_to(tmp_path / "whole" / kind / "train" / name)
    (subset / "data.yaml").write_text("path: .\ntrain: images/train\nnames:\n  0: person\n")
    read = read_backgrounds(subset, (64, 48))
    assert [b.relative for b in read.images] == ["images/train/a.png"] and read.images[0].boxes
    climbing = tmp_path / "climbing"
    _yolo_set(climbing / "inner", train="../../whole/images/train")
    with pytest.raises(InputError, match="outside"):
        read_backgrounds(climbing / "inner", (64, 48))


def test_a_file_name_that_is_not_utf8(case, run_cli):
    """A Latin-1 name (old zips, SMB shares) cannot be recorded in UTF-8 JSON: refused, the name escaped."""
    import os

    (case / "photos" / "photo_00.jpg").rename(case / "photos" / os.fsdecode(b"caf\xe9.jpg"))
    _refused(run_cli, case, case / "photos", "caf\\udce9.jpg: a file name that is not UTF-8", "expected UTF-8 names")


def test_images_is_for_a_coco_json_only(case, run_cli):
    code, _, err = run_cli("composite", case / "photos", "--bank", case / "bank", "--config", case / "config.json",
                           "--out", case / "out", "--images", case / "photos")
    assert code == 2 and err.strip().splitlines()[-1].startswith("synthua: error: --images: ")
    assert "expected only with a COCO .json" in err and not (case / "out").exists()


def test_backgrounds_below_a_folder_links_followed_hidden_files_and_datasets_left_out(tmp_path):
    """Every photo below a folder: linked folders followed (each real folder once, a link back to an ancestor
    walked no further), hidden files and folders and the datasets synthua wrote there (a manifest and records:
    their images and label maps are no photos) left out and the datasets named."""
    from synthua_usd.pipeline.backgrounds import read_backgrounds

    root, elsewhere = tmp_path / "photos", tmp_path / "elsewhere"
    write_photos(root, 1, (96, 72))
    write_photos(elsewhere, 2, (96, 72), suffix=".jpg")
    (root / "linked").symlink_to(elsewhere, target_is_directory=True)
    (root / "again").symlink_to(elsewhere, target_is_directory=True)     # the same real folder: walked once
    (root / "loop").symlink_to(root, target_is_directory=True)
    write_photos(root / "z_real", 1, (96, 72))
    (root / "a_link").symlink_to(root / "z_real", target_is_directory=True)   # into the folder: walked as z_real
    write_photos(root / ".hidden", 1, (96, 72))
    (root / "._photo_00.png").write_bytes(b"AppleDouble")
    dataset = root / "composites"
    write_photos(dataset / "images" / "train", 1, (96, 72))
    (dataset / "records").mkdir()
    (dataset / "manifest.json").write_text("{}")
    read = read_backgrounds(root, (64, 48))
    assert [b.relative for b in read.images] == ["again/photo_00.jpg", "again/photo_01.jpg", "photo_00.png",
                                                 "z_real/photo_00.png"]
    assert read.skipped == ("composites",)


def test_replay_reads_the_photos_as_the_job_listed_them(tmp_path):
    """A composite's names count the photos of its job's list (generate.json: job_key.backgrounds): replay takes
    that list, reading a photo the folder's walk leaves out today (a dataset made before the walk left out the
    datasets synthua wrote) by its recorded name; a labelled set's photo must still be in the set, and a listed
    name may not climb out of the folder."""
    from synthua_usd.core.errors import InputError
    from synthua_usd.pipeline.backgrounds import listed_backgrounds, read_backgrounds

    root = tmp_path / "photos"
    write_photos(root, 2, (96, 72))
    write_photos(root / "old" / "images", 1, (80, 60))
    (root / "old" / "records").mkdir()
    (root / "old" / "manifest.json").write_text("{}")
    now = read_backgrounds(root, (64, 48))
    assert [b.relative for b in now.images] == ["photo_00.png", "photo_01.png"]
    listed = [["old/images/photo_00.png", 80, 60], ["photo_00.png", 96, 72], ["photo_01.png", 96, 72]]
    then = listed_backgrounds(now, listed)
    assert [(b.relative, b.width, b.height) for b in then.images] == [tuple(item) for item in listed]
    for hostile in (["../photos/photo_00.png", 96, 72], ["/etc/passwd", 1, 1], "photo_00.png"):
        with pytest.raises(InputError, match="job_key.backgrounds"):
            listed_backgrounds(now, [hostile])
    _yolo_set(tmp_path / "set")
    with pytest.raises(InputError, match="not among the photos of"):
        listed_backgrounds(read_backgrounds(tmp_path / "set", (64, 48)), [["images/train/b.png", 96, 72]])


def test_a_yolo_folder_given_by_a_relative_path_and_a_data_yaml_whose_path_points_elsewhere(tmp_path, monkeypatch):
    """A YOLO folder without data.yaml (classes.txt) given as a relative path (its images' paths were joined to it
    twice); a data.yaml whose ``path`` names the set's folder elsewhere (Ultralytics' own layout): the photos are
    named below that folder."""
    from synthua_usd.pipeline.backgrounds import read_backgrounds

    _yolo_set(tmp_path / "set")
    (tmp_path / "set" / "data.yaml").unlink()
    (tmp_path / "set" / "classes.txt").write_text("person\n")
    monkeypatch.chdir(tmp_path)
    read = read_backgrounds(Path("set"), (64, 48))
    assert [(b.relative, b.boxes[0].label) for b in read.images] == [("images/train/a.png", "person")]
    (tmp_path / "cfg").mkdir()
    (tmp_path / "cfg" / "set.yaml").write_text("path: ../set\ntrain: images/train\nnames:\n  0: person\n")
    read = read_backgrounds(tmp_path / "cfg" / "set.yaml", (64, 48))
    assert read.folder == tmp_path / "set" and [b.relative for b in read.images] == ["images/train/a.png"]


def test_classes_of_a_labelled_set_the_bank_does_not_know_are_named_all_at_once(case, run_cli):
    """A COCO-style set of many classes: the error names every class to map (up to 8, then how many more), and
    ``"*": null`` leaves out every class not listed (its boxes dropped as unmapped: ``person`` is listed to keep it)."""
    names = ["person", "dog", "traffic light", "bench", "cat", "bird", "horse", "sheep", "cow", "kite", "pizza"]
    labelled = case / "labelled"
    (labelled / "classes.txt").write_text("\n".join(names) + "\n")
    (labelled / "labels" / "photo_01.txt").write_text("0 0.5 0.5 0.2 0.4\n1 0.3 0.7 0.1 0.1\n")
    line = _refused(run_cli, case, labelled, "background_labels.classes: 'dog', 'traffic light', 'bench', 'cat', "
                    "'bird', 'horse', 'sheep', 'cow' and 2 more (classes of", "): not thing classes of the bank's",
                    "\"*\": null leaves out every class not listed")
    assert "'kite'" not in line and "'person'" not in line
    (case / "config.json").write_text(json.dumps({**CONFIG, "background_labels": {"classes": {"person": "person",
                                                                                              "*": None}}}))
    code, out, err = run_cli("composite", labelled, "--bank", case / "bank", "--config", case / "config.json",
                             "--out", case / "out", "--workers", "1")
    assert code == 0, out + err
    boxes = [b for p in sorted((case / "out" / "records").glob("*.json"))
             for b in json.loads(p.read_text())["composite"]["background_boxes"]]
    assert sorted((b["label"], b["reason"]) for b in boxes) == [("dog", "unmapped"), ("person", None),
                                                                   ("person", None)]
    (case / "config.json").write_text(json.dumps({**CONFIG, "background_labels": {"classes": {"dog": "dogs",
                                                                                              "*": None}}}))
    _refused(run_cli, case, labelled, "classes: 'dog' -> 'dogs' (a class of", "): not a thing class",
             out=case / "out3")
    (case / "config.json").write_text(json.dumps({**CONFIG, "background_labels": {"classes": {"*": "person"}}}))
    _refused(run_cli, case, labelled, "config.json: background_labels.classes.*", out=case / "out2")
