"""Hostile datasets for ``synthua verify``: label PNGs swapped between two images with the manifest's checksums
rewritten to match, a record naming a class its label PNGs do not hold, counts and boxes edited. ``replay`` finds
such damage by rendering again; ``verify`` must find it without rendering, each record against its own label PNGs:
exit 1 and a problem line naming the image and the disagreement."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import pytest

from synthua_usd.model.taxonomy import ClassMap


def _records(root: Path) -> list[dict]:
    """The accepted images' records, in id order."""
    records = [json.loads(p.read_text()) for p in sorted((root / "records").glob("*.json"))]
    return [r for r in records if r["qa"]["verdict"] != "rejected"]


def _rechecksum(root: Path, *relatives: str) -> None:
    """Make the manifest agree with the files as they are now: only checks beyond checksums can notice."""
    manifest = json.loads((root / "manifest.json").read_text())
    for entry in manifest["dataset_files"] + [e for img in manifest["images"] for e in img["files"]]:
        if entry["path"] in relatives:
            data = (root / entry["path"]).read_bytes()
            entry["sha256"], entry["bytes"] = hashlib.sha256(data).hexdigest(), len(data)
    (root / "manifest.json").write_text(json.dumps(manifest))


def _rewrite_record(root: Path, record: dict) -> None:
    relative = f"records/{record['name']}.json"
    (root / relative).write_text(json.dumps(record, indent=1))
    _rechecksum(root, relative)


def _swap(root: Path, a: dict, b: dict, keys) -> None:
    """Swap the files ``keys`` of records ``a`` and ``b`` (all different), the manifest's checksums made to match."""
    for key in keys:
        pa, pb = root / a["files"][key], root / b["files"][key]
        data_a, data_b = pa.read_bytes(), pb.read_bytes()
        assert data_a != data_b
        pa.write_bytes(data_b)
        pb.write_bytes(data_a)
    _rechecksum(root, *(r["files"][k] for r in (a, b) for k in keys))


def _verify(run_cli, root: Path) -> list[str]:
    code, out, err = run_cli("verify", root)
    assert code == 1 and "Traceback" not in err, out + err
    return [line for line in out.splitlines() if line.startswith("problem: ")]


def test_label_pngs_swapped_between_two_images_fail_verify(generated_copy, run_cli):
    """class, semantic and Cityscapes PNGs of two images swapped, the manifest's checksums rewritten: verify passed."""
    a, b = _records(generated_copy)[:2]
    keys = [k for k in ("class", "semantic", "cs_labelIds", "cs_instanceIds", "cs_color") if k in a["files"]]
    assert {"class", "semantic", "cs_labelIds"} <= set(keys)
    _swap(generated_copy, a, b, keys)
    problems = _verify(run_cli, generated_copy)
    for record in (a, b):
        mine = [p for p in problems if f"image {record['id']} ({record['name']})" in p]
        assert any("its record and its label PNGs disagree" in p and "class_pixel_counts" in p for p in mine), problems
        assert any(record["files"]["class"] in p for p in mine), problems


@pytest.mark.parametrize("keys, words", [(("semantic",), ("semantic.png", "class map's colours")),
                                         (("cs_instanceIds", "cs_color"), ("gtFine_instanceIds.png", "gtFine_color.png"))])
def test_one_kind_of_label_png_swapped_alone_fails_verify(generated_copy, run_cli, keys, words):
    """semantic.png alone, or Cityscapes' instance ids and colours alone, swapped with rewritten checksums."""
    a, b = _records(generated_copy)[:2]
    _swap(generated_copy, a, b, keys)
    problems = " ".join(_verify(run_cli, generated_copy))
    assert all(w in problems for w in words) and f"image {a['id']} ({a['name']})" in problems, problems


def test_a_record_naming_a_class_its_pngs_do_not_hold_fails_verify(generated_copy, run_cli):
    """The record says manual_wheelchair where the label PNGs say person."""
    record = next(r for r in _records(generated_copy)
                  if any(i["class_name"] == "person" and i["area"] for i in r["instances"]))
    person = next(i for i in record["instances"] if i["class_name"] == "person" and i["area"])
    person["class_name"], person["category_id"] = "manual_wheelchair", ClassMap.default().resolve("manual_wheelchair").id
    _rewrite_record(generated_copy, record)
    problems = _verify(run_cli, generated_copy)
    assert any(f"image {record['id']} ({record['name']})" in p and f"instance {person['id']} is manual_wheelchair" in p
               and "person" in p for p in problems), problems


@pytest.mark.parametrize("spoil, words", [
    (lambda r: r["class_pixel_counts"].update(road=r["class_pixel_counts"].get("road", 0) + 5), ("class_pixel_counts road",)),
    (lambda r: r["instances"][0]["bbox"].__setitem__(0, r["instances"][0]["bbox"][0] + 1), ("bbox",)),
    (lambda r: r["instances"][0].update(area=r["instances"][0]["area"] + 1), ("pixels in the record",)),
    (lambda r: r["instances"].pop(0), ("does not list",)),
    (lambda r: r["instances"][0].update(id=r["instances"][0]["id"] + 900), ("pixels in the record",)),
])
def test_an_edited_record_fails_verify(generated_copy, run_cli, spoil, words):
    record = _records(generated_copy)[0]
    spoil(record)
    _rewrite_record(generated_copy, record)
    problems = _verify(run_cli, generated_copy)
    mine = [p for p in problems if f"image {record['id']} ({record['name']})" in p]
    assert any("its record and its label PNGs disagree" in p and all(w in p for w in words) for p in mine), problems


def test_the_untouched_dataset_still_verifies(generated, run_cli):
    code, out, err = run_cli("verify", generated)
    assert code == 0 and out.strip().endswith(": ok"), out + err
