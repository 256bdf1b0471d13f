"""Hand-made label maps for the dataset-format tests: overlapping, multi-part, holed, border-touching and
diagonal-only instances plus stuff and void, and records built from them by the code under test.

Class ids are the project's class map's (``schemas/classmap.json``): 1 road, 3 sidewalk, 16 grass (stuff);
6 building, 12 light_pole, 18 person, 19 car, 22 bicycle, 29 manual_wheelchair (things).
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from synthua_usd.dataset.annotations import annotate, mark_ignored, panoptic
from synthua_usd.model.scene import Instance

H, W = 40, 48

INSTANCES = (
    Instance(1, "/World/Road", 1, "road", False),
    Instance(2, "/World/Building", 6, "building", True),
    Instance(3, "/World/Agents/P1", 18, "person", True, (("uses", "/World/Agents/W1"),)),
    Instance(5, "/World/Agents/W1", 29, "manual_wheelchair", True),
    Instance(7, "/World/Car", 19, "car", True),
    Instance(8, "/World/Pole", 12, "light_pole", True),
    Instance(9, "/World/Agents/P2", 18, "person", True, (("pushes", "/World/Agents/W1"),)),
    Instance(11, "/World/Agents/P3", 18, "person", True, (("accompanies", "/World/Agents/P1"),)),
    Instance(12, "/World/Agents/Hidden", 18, "person", True, (("uses", "/World/Agents/W1"),)),
    Instance(13, "/World/Bike", 22, "bicycle", True),
)


def scene() -> tuple[np.ndarray, np.ndarray, dict[int, np.ndarray], dict[int, float]]:
    """(class ids (H, W) uint8, instance ids (H, W) uint16, amodal flat indices, truncation)."""
    cls = np.zeros((H, W), np.uint8)
    ins = np.zeros((H, W), np.uint16)

    def put(rows, cols, c, i):
        cls[rows, cols] = c
        ins[rows, cols] = i

    put(slice(0, 10), slice(0, 40), 6, 2)          # building on the top border; cols 40.. stay void
    put(slice(10, 40), slice(0, 48), 1, 1)         # road: a stuff class with an instance
    put(slice(30, 40), slice(0, 21), 3, 0)         # sidewalk: stuff without instance
    put(slice(30, 40), slice(21, 31), 16, 0)       # grass
    car = np.zeros((H, W), bool)
    car[14:23, 5:21] = True
    cls[car], ins[car] = 19, 7
    put(slice(8, 29), slice(11, 13), 12, 8)        # pole cuts the car in two parts
    person = np.zeros((H, W), bool)
    person[12:29, 26:32] = True
    cls[person], ins[person] = 18, 3
    put(slice(18, 20), slice(28, 30), 1, 1)        # a hole in the person, road seen through it
    put(slice(22, 28), slice(24, 34), 29, 5)       # wheelchair in front of the person
    put(slice(32, 40), slice(44, 48), 18, 9)       # person on the bottom-right corner ...
    put(31, 43, 18, 9)                             # ... with a pixel joined only diagonally
    put(0, 47, 18, 11)                             # one pixel in the top-right corner (void around)
    bike = np.zeros((H, W), bool)                  # a ring with a pinch, and a second diagonal part
    bike[11:16, 36:41] = True
    bike[12:15, 37:40] = False
    bike[12, 37] = True
    bike[13, 38] = True
    bike[17, 42] = True
    bike[18, 43] = True
    cls[bike], ins[bike] = 22, 13
    amodal = {
        7: np.flatnonzero(car),                    # the car behind the pole
        3: np.flatnonzero(person),                 # the person behind the wheelchair (hole included)
        12: np.array([W * 20 + 20]),               # hidden entirely: no visible pixel, no entry
        9: np.array([W * 39 + 47]),                # already visible: union changes nothing
    }
    truncation = {9: 0.25, 2: 0.5, 11: 0.0}
    return cls, ins, amodal, truncation


def record(image_id: int, split: str, class_map, flip: bool = False, verdict: str = "accepted") -> tuple[dict, tuple]:
    """A record as the pipeline will write it (fields the formats read), and its label maps."""
    cls, ins, amodal, truncation = scene()
    if flip:
        cls, ins = np.ascontiguousarray(cls[:, ::-1]), np.ascontiguousarray(ins[:, ::-1])
        amodal = {k: np.sort((v // W) * W + (W - 1 - v % W)) for k, v in amodal.items()}
    instances = annotate(cls, ins, INSTANCES, amodal, truncation)
    mark_ignored(instances, 0)  # every written entry has ``ignore`` (the schema requires it)
    _, segments = panoptic(cls, ins, INSTANCES, class_map)
    name = f"{image_id:06d}_cam-{image_id % 2}_t0024_clear-day_s{image_id}"
    rec = {
        "id": image_id, "name": name, "split": split, "width": W, "height": H,
        "camera": {"prim_path": f"/World/Cameras/C{image_id % 2}", "name": f"C{image_id % 2}",
                   "rig_type": "cctv" if image_id % 2 else None,
                   "K": [[50.0, 0, 24.0], [0, 50.0, 20.0], [0, 0, 1]],
                   "camera_to_world": np.eye(4).tolist(), "world_to_camera_opencv": np.diag([1.0, -1, -1, 1]).tolist(),
                   "focal_length_mm": 35.0, "horizontal_aperture_mm": 36.0, "vertical_aperture_mm": 30.0,
                   "distortion": None},
        "time_code": 24.0, "seed": image_id,
        "condition": {"name": "clear-day", "sun_elevation_deg": 40.0 + image_id, "fog": image_id % 2 == 0},
        "files": {},
        "class_pixel_counts": {class_map.by_id(int(c)).name: int(n) for c, n in zip(*np.unique(cls, return_counts=True))},
        "instances": instances, "panoptic_segments": segments,
        "qa": {"verdict": verdict, "reasons": [] if verdict == "accepted" else ["blur: 3.1 < 5"],
               "measures": {"laplacian_var": 10.0 + image_id}},
    }
    return rec, (cls, ins, amodal)


def crowded_scene(seed: int, height: int = 61, width: int = 83) -> tuple:
    """A random scene of many overlapping instances, for comparisons with per-instance computations:
    blobs and boxes (things and stuff) painted over each other, parts cut apart and pinched, instances on
    every border (column-major runs that cross from one column's bottom to the next column's top), single
    pixels, instances hidden entirely; random amodal pixel sets (some outside the visible mask, some empty)
    and truncations. Returns (class ids, instance ids, instances, amodal, truncation)."""
    rng = np.random.default_rng(seed)
    cls = np.zeros((height, width), np.uint8)
    ins = np.zeros((height, width), np.uint16)
    kinds = [(1, "road", False), (3, "sidewalk", False), (6, "building", True), (18, "person", True),
             (19, "car", True), (22, "bicycle", True), (29, "manual_wheelchair", True)]
    instances = []
    for k in range(60):
        inst_id = 65535 - k if k % 7 == 0 else 100 + 3 * k  # ids up to the uint16 limit too
        class_id, name, isthing = kinds[int(rng.integers(len(kinds)))]
        instances.append(Instance(inst_id, f"/World/I{k}", class_id, name, isthing))
        y0, x0 = int(rng.integers(-5, height)), int(rng.integers(-5, width))
        y1, x1 = y0 + int(rng.integers(1, 25)), x0 + int(rng.integers(1, 25))
        region = (slice(max(0, y0), max(0, y1)), slice(max(0, x0), max(0, x1)))
        if k % 3 == 0:
            painted = rng.random((height, width)) < 0.5  # a speckled blob: pinches, holes, many parts
            keep = np.zeros((height, width), bool)
            keep[region] = True
            painted &= keep
        else:
            painted = np.zeros((height, width), bool)
            painted[region] = True
        if k == 5:  # a full column: runs that continue from one column into the next
            painted[:, width // 2:width // 2 + 3] = True
        if k == 6:  # one pixel on the last row
            painted = np.zeros((height, width), bool)
            painted[-1, -1] = True
        cls[painted], ins[painted] = class_id, inst_id
    stuff_only = rng.random((height, width)) < 0.05  # stuff and void pixels without instance
    cls[stuff_only], ins[stuff_only] = 3, 0
    hidden = Instance(7, "/World/Hidden", 18, "person", True)
    instances.append(hidden)
    visible = {int(i) for i in np.unique(ins) if i}
    amodal, truncation = {}, {}
    for inst in instances:
        choice = int(rng.integers(4))
        if choice == 0:
            amodal[inst.id] = np.sort(rng.choice(height * width, int(rng.integers(1, 200)), replace=False))
        elif choice == 1 and inst.id in visible:  # the visible pixels and a few more around them
            around = np.flatnonzero(ndimage.binary_dilation(ins == inst.id))
            amodal[inst.id] = around
        elif choice == 2:
            amodal[inst.id] = np.zeros(0, np.int64)
        truncation[inst.id] = float(rng.random())
    return cls, ins, tuple(instances), amodal, truncation
