"""Metadata table read back by pyarrow and csv; one-hot .npz read by np.load and byte-deterministic;
instance previews."""

from __future__ import annotations

import csv
import hashlib
import zipfile

import numpy as np
import pyarrow.parquet as pq
import pytest

from label_scenes import crowded_scene, record, scene
from synthua_usd.backends.previews import instance_colors, instance_preview
from synthua_usd.core.errors import InputError
from synthua_usd.dataset.formats.onehot import onehot, write_onehot_npz
from synthua_usd.dataset.formats.tables import metadata_rows, write_tables


def test_metadata_table_reads_back_by_pyarrow_and_csv(tmp_path, class_map):
    records = [record(2, "val", class_map, verdict="rejected")[0], record(1, "train", class_map)[0]]
    rows = metadata_rows(records, class_map)
    write_tables(rows, tmp_path / "metadata.csv", tmp_path / "metadata.parquet")
    table = pq.read_table(tmp_path / "metadata.parquet").to_pylist()
    with open(tmp_path / "metadata.csv", newline="") as f:
        text_rows = list(csv.DictReader(f))
    assert [r["image_id"] for r in table] == [1, 2] and [r["image_id"] for r in text_rows] == ["1", "2"]
    first, rec = table[0], records[1]
    assert (first["fx"], first["cy"], first["camera_path"], first["rig_type"]) == (50.0, 20.0, "/World/Cameras/C1", "cctv")
    assert table[1]["rig_type"] is None and text_rows[1]["rig_type"] == ""
    assert first["world_to_camera_opencv_11"] == -1.0 and first["camera_to_world_33"] == 1.0
    assert first["condition"] == "clear-day" and first["condition.sun_elevation_deg"] == 41.0
    assert first["condition.fog"] is False and text_rows[1]["condition.fog"] == "true"
    persons = sum(1 for i in rec["instances"] if i["category_id"] == 18)
    assert first["instances.person"] == persons == 3 and first["instances.walker"] == 0
    cls = scene()[0]
    assert first["pixels.person"] == np.sum(cls == 18) and int(text_rows[0]["pixels.road"]) == np.sum(cls == 1)
    assert table[1]["qa_verdict"] == "rejected" and table[1]["qa_reasons"] == "blur: 3.1 < 5"
    assert first["qa.laplacian_var"] == 11.0
    assert list(text_rows[0]) == list(rows[0])


def test_onehot_npz_is_loadable_and_byte_identical(tmp_path):
    cls = scene()[0]
    tensor = onehot(cls, 37)
    assert tensor.shape == (37,) + cls.shape and tensor.dtype == bool
    assert np.array_equal(tensor.argmax(0), cls) and np.all(tensor.sum(0) == 1)
    a, b = tmp_path / "a.npz", tmp_path / "b.npz"
    write_onehot_npz(a, tensor)
    write_onehot_npz(b, tensor)
    assert hashlib.sha256(a.read_bytes()).digest() == hashlib.sha256(b.read_bytes()).digest()
    assert zipfile.ZipFile(a).infolist()[0].date_time == (1980, 1, 1, 0, 0, 0)
    with np.load(a) as data:
        assert np.array_equal(data["onehot"], tensor)
    with pytest.raises(InputError, match="class id 29 present"):
        onehot(cls, 29)


def test_instance_preview_is_deterministic_black_on_zero_and_distinct():
    ins = scene()[1]
    preview = instance_preview(ins)
    assert preview.shape == ins.shape + (3,) and preview.dtype == np.uint8
    assert np.all(preview[ins == 0] == 0)
    colours = {int(i): tuple(preview[ins == i][0]) for i in np.unique(ins) if i}
    assert len(set(colours.values())) == len(colours) and (0, 0, 0) not in colours.values()
    for i, c in colours.items():
        assert np.all(preview[ins == i] == c)
    assert np.array_equal(instance_preview(ins[:, ::-1]), preview[:, ::-1])  # colour depends on the id only
    ids = np.arange(1, 2001)
    strip = instance_preview(ids.reshape(1, -1).astype(np.uint16))[0].astype(int)
    assert np.abs(np.diff(strip, axis=0)).sum(1).min() > 30  # consecutive ids are far apart


def test_instance_preview_equals_each_pixels_own_colour():
    ins = crowded_scene(1)[1]
    assert np.array_equal(instance_preview(ins), instance_colors(ins.reshape(-1)).reshape(ins.shape + (3,)))
