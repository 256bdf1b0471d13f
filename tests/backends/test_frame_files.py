"""Writing one frame: the files of the chosen outputs, and frame.json last, validated before anything."""

import pytest

from conftest import DATA
from synthua_usd.backends.frame_files import write_frame
from synthua_usd.core.errors import SchemaError
from synthua_usd.core.outputs import FRAME_DOCUMENT, select_outputs
from synthua_usd.pipeline.frame import FrameRequest, run_frames


@pytest.fixture(scope="module")
def frame(tmp_path_factory):
    """A rendered frame of the tiny scene: its buffers and its (valid) frame.json document."""
    run = run_frames(FrameRequest(stage_path=DATA / "valid" / "tiny_scene.usda", out_dir=tmp_path_factory.mktemp("f"),
                                  camera_paths=("/World/Cam",), width=16, height=12, spp=1))
    return run.frames[0]


def write(out_dir, frame, outputs, document, palette):
    r = frame.rendered
    return write_frame(out_dir, outputs, rgb=r.rgb, class_ids=r.class_ids, instance_ids=r.instance_ids,
                       z_depth=r.hits.z_m, palette=palette, frame_doc=document)


def test_writes_the_files_of_the_outputs_and_frame_json_last(tmp_path, frame, class_map):
    written = write(tmp_path / "out", frame, select_outputs(["instance_id", "depth"]), frame.document,
                    class_map.palette())
    assert [p.name for p in written] == ["instance.png", "instance_preview.png", "depth.exr", FRAME_DOCUMENT]
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == sorted(p.name for p in written)


def test_an_invalid_document_writes_nothing(tmp_path, frame, class_map):
    document = {k: v for k, v in frame.document.items() if k != "image"}
    with pytest.raises(SchemaError, match="'image' is a required property"):
        write(tmp_path / "out", frame, select_outputs([]), document, class_map.palette())
    assert not (tmp_path / "out").exists()
