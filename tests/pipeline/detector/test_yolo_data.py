"""A detection set written in Ultralytics' box layout reads back, through our reader and supervision's, as the
boxes it holds (ignored boxes and untrained classes left out); and the runner's refusal when there is no
detector."""

from __future__ import annotations


import numpy as np
import pytest
from PIL import Image

from synthua_usd.analytics.detection_sets import Box, DetectionSet, SetImage, read_yolo
from synthua_usd.pipeline.detector.runner import DetectorUnavailable, find_detector_python
from synthua_usd.pipeline.detector.yolo_data import write_yolo_boxes


def test_written_boxes_read_back(tmp_path):
    import supervision as sv

    path = tmp_path / "src" / "a.png"
    path.parent.mkdir()
    Image.fromarray(np.zeros((30, 50, 3), np.uint8)).save(path)
    boxes = (Box("person", 2.5, 3, 10, 20), Box("manual_wheelchair", 20, 5, 25, 25),
             Box("person", 40, 1, 2, 2, ignore=True), Box("walker", 0, 0, 5, 5))
    image = SetImage(1, path, 50, 30, boxes)
    data = DetectionSet(("person", "manual_wheelchair", "walker"), (image,), "synthua", "x", "train")
    data_yaml = write_yolo_boxes(tmp_path / "out", {"train": data, "val": data}, ("person", "manual_wheelchair"))
    assert (tmp_path / "out" / "images" / "train" / "000001.png").resolve() == path.resolve()
    back = read_yolo(data_yaml, "train")
    assert back.names == ("person", "manual_wheelchair")
    got = [(b.label, *np.round([b.x, b.y, b.w, b.h], 4)) for b in back.images[0].boxes]
    assert got == [("person", 2.5, 3, 10, 20), ("manual_wheelchair", 20, 5, 25, 25)]
    theirs = sv.DetectionDataset.from_yolo(str(tmp_path / "out" / "images" / "val"),
                                           str(tmp_path / "out" / "labels" / "val"), str(data_yaml))
    (_, _, det), = list(theirs)
    assert np.allclose(det.xyxy, [[2.5, 3, 12.5, 23], [20, 5, 45, 30]], atol=1e-3)


def test_no_detector_interpreter_is_one_line(tmp_path):
    with pytest.raises(DetectorUnavailable) as info:
        find_detector_python(tmp_path / "bin" / "python")
    assert "setup_train.sh" in str(info.value) and "\n" not in str(info.value)
    fake = tmp_path / "python"
    fake.write_text("#!/bin/sh\necho 'No module named ultralytics' >&2\nexit 1\n")
    fake.chmod(0o755)
    with pytest.raises(DetectorUnavailable, match="No module named ultralytics"):
        find_detector_python(fake)
