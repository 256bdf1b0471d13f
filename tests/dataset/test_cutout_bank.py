"""Reading a bank of cut-outs (format synthua-cutouts/1): the drawn banks of tests/bank_maker.py read back as written,
and what is not such a bank refused in one line naming the file and field."""

from __future__ import annotations

import hashlib
import json

import pytest

from bank_maker import aid_user, pedestrian, write_bank
from synthua_usd.core.errors import InputError
from synthua_usd.dataset.cutout_bank import Light, check_bank_files, read_bank


@pytest.fixture
def bank_dir(tmp_path):
    return write_bank(tmp_path / "bank")


def test_a_bank_reads_back_as_written(bank_dir):
    bank = read_bank(bank_dir)
    doc = json.loads((bank_dir / "bank.json").read_text())
    assert bank.id == hashlib.sha256((bank_dir / "bank.json").read_bytes()).hexdigest()
    assert [e.id for e in bank.entries] == [c["id"] for c in doc["cutouts"]]
    first, written = bank.entries[0], doc["cutouts"][0]
    assert first.kind == "aid_user" and first.aid == "manual_wheelchair" and first.size == tuple(written["size"])
    assert [i.class_name for i in first.instances] == ["person", "manual_wheelchair"]
    assert first.instances[0].relations == (("uses", 2),)
    assert first.instances[0].bbox == tuple(written["instances"][0]["bbox"])
    assert len(first.instances[0].keypoints) == 17 and len(first.instances[1].keypoints) == 3
    assert first.camera.elevation_deg == written["camera"]["elevation_deg"]
    assert first.group_box() == (12, 3, 36, 62)  # the chair's wheel is the widest part, head top to wheel bottom
    check_bank_files(bank)


def test_a_bank_of_another_format_is_refused(tmp_path):
    root = write_bank(tmp_path / "bank", [pedestrian("p0")], fmt="synthua-cutouts/2")
    with pytest.raises(InputError, match=r"bank\.json: format: 'synthua-cutouts/2'; expected 'synthua-cutouts/1' "
                                         r"\(a bank made by another version"):
        read_bank(root)


def test_a_file_that_fails_its_checksum_is_named(bank_dir):
    path = bank_dir / "cutouts" / "c000001.ids.png"
    data = bytearray(path.read_bytes())
    data[-20] ^= 0xFF
    path.write_bytes(bytes(data))
    with pytest.raises(InputError, match=r"c000001\.ids\.png: SHA-256 differs from bank\.json's"):
        check_bank_files(read_bank(bank_dir))
    path.write_bytes(bytes(data[:-5]))
    with pytest.raises(InputError, match=r"c000001\.ids\.png: \d+ bytes; expected \d+ as bank\.json lists"):
        check_bank_files(read_bank(bank_dir))


@pytest.mark.parametrize("edit, field", [
    (lambda c: c["instances"][0].update(class_name="unicorn"), r"cutouts\[0\]\.instances\[0\]\.class_name: unicorn"),
    (lambda c: c["instances"][0].update(keypoints=[[1, 2, 2]]), r"cutouts\[0\]\.instances\[0\]\.keypoints"),
    (lambda c: c["camera"].update(elevation_deg=95), r"cutouts\[0\]\.camera\.elevation_deg: 95"),
    (lambda c: c.update(kind="cyclist"), r"cutouts\[0\]\.kind: cyclist"),
    (lambda c: c["instances"][0]["relations"].update(uses=7), r"cutouts\[0\]\.instances\[0\]\.relations"),
    (lambda c: c.update(subject_height_m=0), r"cutouts\[0\]\.subject_height_m: 0"),
])
def test_a_bad_entry_is_named_with_its_field(tmp_path, edit, field):
    root = write_bank(tmp_path / "bank", [aid_user("a0")])
    doc = json.loads((root / "bank.json").read_text())
    edit(doc["cutouts"][0])
    (root / "bank.json").write_text(json.dumps(doc))
    with pytest.raises(InputError, match=field):
        read_bank(root)


def test_a_folder_without_bank_json_is_refused(tmp_path):
    with pytest.raises(InputError, match="no bank.json; expected a bank of cut-outs written by `synthua cutouts`"):
        read_bank(tmp_path)


def test_light_distance():
    sun = Light(0.0, 40.0, 0.0)
    assert sun.distance(sun) == pytest.approx(0.0)
    assert sun.distance(Light(0.0, 40.0, 180.0)) == pytest.approx(2 * (90 - 40) / 90)  # the sun behind, then ahead
    assert sun.distance(Light(1.0, 40.0, 180.0)) == pytest.approx(1.0)               # overcast: the sun no matter
