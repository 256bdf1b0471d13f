"""``--camera auto`` for stages without a camera: a framing camera in the session layer, on Y-up and
centimetre stages too, checked with an independent ray cast."""

import numpy as np
import pytest

from reference_raycast import reference_labels
from synthua_usd.pipeline.frame import AUTO_CAMERA, FrameRequest, run_frames

#: A Y-up, centimetre stage without camera or lights: a 2 m tall, 1 m wide post (a labelled Cube scaled in Y)
#: standing on a 10 m slab, 30 m from the origin along X.
STAGE = """#usda 1.0
(
    defaultPrim = "World"
    metersPerUnit = 0.01
    upAxis = "Y"
    startTimeCode = 1
    endTimeCode = 1
)

def Xform "World"
{
    def Cube "Post" (prepend apiSchemas = ["SemanticsLabelsAPI:synthua"])
    {
        double size = 100
        token[] semantics:labels:synthua = ["light_pole"]
        double3 xformOp:translate = (3000, 100, 0)
        float3 xformOp:scale = (1, 2, 1)
        uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:scale"]
    }
    def Cube "Slab" (prepend apiSchemas = ["SemanticsLabelsAPI:synthua"])
    {
        double size = 100
        token[] semantics:labels:synthua = ["road"]
        double3 xformOp:translate = (3000, -5, 0)
        float3 xformOp:scale = (10, 0.1, 10)
        uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:scale"]
    }
}
"""


@pytest.mark.slow
def test_auto_camera_frames_a_y_up_centimetre_stage(tmp_path, class_map):
    path = tmp_path / "post.usda"
    path.write_text(STAGE)
    run = run_frames(FrameRequest(stage_path=path, out_dir=tmp_path / "out", camera_paths=(AUTO_CAMERA,),
                                  width=64, height=48, spp=1, keep_buffers=True))
    assert path.read_text() == STAGE  # authored in the session layer only
    frame = run.frames[0]
    cam = frame.camera
    _, up, forward = cam.axes()
    assert up[1] > 0.3 and forward[1] < -0.3  # image up is the stage's +Y; it looks down at the scene
    assert np.linalg.norm(cam.origin - [30.0, 0.5, 0.0]) < 40  # metres: near the 10 m slab, not 100x away
    classes, _ = reference_labels(frame.snapshot, cam, 64, 48)
    assert np.array_equal(classes, frame.rendered.class_ids)
    pole = classes == class_map.resolve("light_pole").id
    road = classes == class_map.resolve("road").id
    assert pole.sum() > 20 and road.mean() > 0.2
    # The whole slab is in view: no labelled pixel on the border.
    labelled = classes > 0
    assert not (labelled[0].any() or labelled[-1].any() or labelled[:, 0].any() or labelled[:, -1].any())
    # The post stands up in the image: it is taller than wide.
    rows, cols = np.nonzero(pole)
    assert np.ptp(rows) > np.ptp(cols)
