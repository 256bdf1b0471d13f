"""``synthua cutouts`` (issue 45): a bank of rendered aid users and pedestrians whose every label claim holds
against an independent computation: instance ids against an Embree ray cast of the studio's meshes, the shadow
layer against independent shadow rays to the sun, keypoints and ground points against the camera's projection,
the scale against the anchor's depth; the same bytes on one and two workers; ``synthua verify`` on a bank."""

from __future__ import annotations

import json
import math
import shutil

import numpy as np
import pytest

from hostile import assert_refused, run_synthua
from reference_raycast import meshes_hit, reference_labels
from synthua_usd.core.images import read_image
from synthua_usd.pipeline.bank_check import check_bank
from synthua_usd.pipeline.cutouts import BANK_FILE, CutoutJob, CutoutWorker, make_bank
from synthua_usd.randomisation.cutouts import CutoutsConfig

#: Small frames, few samples: labels and shadows do not depend on them.
TINY = {"count": 6, "views_per_group": 3, "seed": 5, "workers": 1,
        "frame": {"width": 96, "height": 128, "spp": 4, "denoise": False, "max_depth": 3},
        "people": {"aid_user_share": 1.0, "aids": {"manual_wheelchair": 1, "walker": 1}, "pushed_share": 1.0,
                   "accompanied_share": 1.0},
        "conditions": ["clear_day"]}


@pytest.fixture(scope="module")
def bank(tmp_path_factory):
    folder = tmp_path_factory.mktemp("bank")
    config = folder / "cutouts.json"
    config.write_text(json.dumps(TINY), encoding="utf-8")
    make_bank(config, folder / "bank")
    return folder / "bank", config


def entries(bank_folder):
    return json.loads((bank_folder / BANK_FILE).read_text(encoding="utf-8"))["cutouts"]


def test_a_bank_holds_every_cut_out_whole_and_verifies(bank, run_cli):
    folder, _ = bank
    cutouts = entries(folder)
    assert [c["id"] for c in cutouts] == [f"g{g:06d}v{v:02d}" for g in range(2) for v in range(3)]
    assert check_bank(folder).ok
    code, out, _ = run_cli("verify", folder)
    assert code == 0 and "6 cut-outs, 24 files checked: ok" in out
    for c in cutouts:
        roles = sorted(i["role"] for i in c["instances"])
        assert c["kind"] == "aid_user" and c["group"] in ("pushed", "accompanied")
        assert "user" in roles and "device" in roles and ({"pusher", "companion"} & set(roles))
        user = next(i for i in c["instances"] if i["role"] == "user")
        device = next(i for i in c["instances"] if i["role"] == "device")
        assert user["relations"] == {"uses": device["index"]}
        rgba = read_image(folder / c["files"]["rgba"])[0]
        h, w = rgba.shape[:2]
        assert [w, h] == c["size"] and rgba.shape[2] == 4
        # the crop holds the whole group: nothing covers its border
        assert not rgba[[0, -1], :, 3].any() and not rgba[:, [0, -1], 3].any()


def _in_crop(frame_array: np.ndarray, entry: dict) -> np.ndarray:
    """A frame-sized array cut to the entry's crop, zeros where the crop reaches beyond the frame (by its shadow)."""
    x0, y0 = entry["camera"]["crop_origin"]
    w, h = entry["size"]
    fh, fw = frame_array.shape[:2]
    out = np.zeros((h, w) + frame_array.shape[2:], frame_array.dtype)
    out[max(0, -y0):min(fh, y0 + h) - y0, max(0, -x0):min(fw, x0 + w) - x0] = \
        frame_array[max(0, y0):min(fh, y0 + h), max(0, x0):min(fw, x0 + w)]
    return out


def test_ids_are_those_of_an_independent_ray_cast(bank):
    """Rebuild a view's studio scene and cast its pixel-centre rays with Embree (trimesh): every pixel of the crop
    names the instance Embree hits first (the cut-out's index of it, by prim path)."""
    folder, config = bank
    from synthua_usd.model.taxonomy import ClassMap

    worker = CutoutWorker(CutoutJob(CutoutsConfig.load(config), ClassMap.default().document(), str(folder)))
    checked = 0
    for group in range(2):
        drawn, placements = worker.set_group(group)
        for view in range(3):
            _, _, snapshot, camera, _ = worker.set_view(drawn, placements, view)
            entry = next(c for c in entries(folder) if c["id"] == f"g{group:06d}v{view:02d}")
            frame = entry["camera"]["frame"]
            _, instance_ids = reference_labels(snapshot, camera, *frame)
            by_path = {i.prim_path: i.id for i in snapshot.instances}
            lut = np.zeros(int(instance_ids.max()) + 1, np.uint8)
            for inst in entry["instances"]:
                lut[by_path[inst["prim_path"]]] = inst["index"]
            expected = _in_crop(lut[instance_ids], entry)
            ids = read_image(folder / entry["files"]["ids"])[0][..., 0]
            assert np.mean(ids == expected) >= 0.999, entry["id"]  # float32 against float64 rays: edge pixels
            assert np.count_nonzero(expected) == np.count_nonzero(lut[instance_ids])  # nothing outside the crop
            checked += 1
    assert checked == 6


def test_the_shadow_layer_is_where_independent_rays_to_the_sun_are_blocked(bank):
    """Ground pixels whose ray to the sun Embree finds blocked by the group are darker than the sky alone leaves
    them; ground pixels far from the group with the sun unblocked keep (nearly) all their light."""
    folder, config = bank
    from synthua_usd.backends.mitsuba.cutout_passes import SMOOTHING_PX
    from synthua_usd.model.taxonomy import ClassMap

    worker = CutoutWorker(CutoutJob(CutoutsConfig.load(config), ClassMap.default().document(), str(folder)))
    drawn, placements = worker.set_group(0)
    _, _, snapshot, camera, condition = worker.set_view(drawn, placements, 0)
    worker.session.render(snapshot, camera, rgb=False, condition=condition)  # the condition's sun, as rendered
    entry = entries(folder)[0]
    shadow = read_image(folder / entry["files"]["shadow"])[0][..., 0] / 255.0
    elevation = math.radians(entry["light"]["sun_elevation_deg"])
    assert elevation > 0
    x0, y0 = entry["camera"]["crop_origin"]
    w, h = entry["size"]
    frame_w, frame_h = entry["camera"]["frame"]
    # every pixel centre of the crop, inside the frame or beyond it
    px, py = np.meshgrid(np.arange(x0, x0 + w) + 0.5, np.arange(y0, y0 + h) + 0.5)
    origins, directions = camera.pixel_rays(px.ravel(), py.ravel(), frame_w, frame_h)
    ground = (directions[:, 2] < 0) & (meshes_hit(snapshot, origins, directions) < 0)
    t = -origins[ground, 2] / directions[ground, 2]
    points = origins[ground] + directions[ground] * t[:, None]
    sun = np.asarray(worker.session.lighting.sun_direction, float)
    assert math.isclose(math.degrees(math.asin(sun[2])), math.degrees(elevation), abs_tol=0.5)
    blocked = meshes_hit(snapshot, points + sun * 1e-3, np.broadcast_to(sun, points.shape).copy()) >= 0
    values = shadow.ravel()[ground]
    # away from the shadow's edge (the layer is smoothed by SMOOTHING_PX)
    assert blocked.sum() > 20 and (~blocked).sum() > 20
    assert np.median(values[blocked]) < np.median(values[~blocked]) - 0.2
    assert np.quantile(values[~blocked], 0.5) > 0.9
    assert SMOOTHING_PX < 2


def test_keypoints_ground_points_and_scale_follow_the_camera(bank):
    """Visible keypoints lie on their instance's pixels (within 3 px at this tiny size); ground points are the projections of the
    group's lowest points; the scale is the focal length over the anchor's depth along the view axis; the
    elevation is that of the camera seen from the anchor."""
    folder, _ = bank
    for entry in entries(folder):
        ids = read_image(folder / entry["files"]["ids"])[0][..., 0]
        for inst in entry["instances"]:
            for x, y, v in inst["keypoints"] or []:
                if v == 2:
                    ys, xs = np.nonzero(ids == inst["index"])
                    assert np.min(np.hypot(xs + 0.5 - x, ys + 0.5 - y)) <= 3.0, (entry["id"], inst["index"])
        cam = entry["camera"]
        assert math.isclose(cam["elevation_deg"], math.degrees(math.atan2(cam["height_m"], cam["distance_m"])),
                            abs_tol=1e-3)
        h, w = ids.shape
        x, y = entry["anchor"]
        assert 0 <= x <= w and 0 <= y <= h and entry["ground_points"]
        # below the group's middle: the anchor is the lowest of the ground points' rows, give or take the feet
        assert y >= min(p[1] for p in entry["ground_points"]) - 0.5 * h
        assert entry["scale_px_per_m"] > 0 and 0.5 < entry["subject_height_m"] < 2.5


def test_the_same_config_gives_the_same_bytes_on_two_workers(bank, tmp_path):
    folder, config = bank
    document = json.loads(config.read_text(encoding="utf-8"))
    document["workers"] = 2
    again = tmp_path / "cutouts.json"
    again.write_text(json.dumps(document), encoding="utf-8")
    make_bank(again, tmp_path / "bank")
    first = json.loads((folder / BANK_FILE).read_text(encoding="utf-8"))
    second = json.loads((tmp_path / "bank" / BANK_FILE).read_text(encoding="utf-8"))
    assert first["files"] == second["files"] and first["cutouts"] == second["cutouts"]
    assert first["config"] == {**second["config"], "workers": 1}


def test_verify_finds_a_tampered_bank(bank, tmp_path):
    folder, _ = bank
    copy = tmp_path / "bank"
    shutil.copytree(folder, copy)
    a, b = entries(copy)[:2]
    # the ids of two cut-outs swapped, the manifest's checksums rewritten to match: the masks disagree
    pa, pb = copy / a["files"]["ids"], copy / b["files"]["ids"]
    data_a, data_b = pa.read_bytes(), pb.read_bytes()
    pa.write_bytes(data_b)
    pb.write_bytes(data_a)
    from synthua_usd.dataset.manifest import file_entry

    document = json.loads((copy / BANK_FILE).read_text(encoding="utf-8"))
    document["files"] = [file_entry(copy, f["path"]) for f in document["files"]]
    (copy / BANK_FILE).write_text(json.dumps(document), encoding="utf-8")
    problems = check_bank(copy).problems
    assert any(a["id"] in p for p in problems) and any(b["id"] in p for p in problems)
    # another version's bank is refused in one line
    document["format"] = "synthua-cutouts/0"
    (copy / BANK_FILE).write_text(json.dumps(document), encoding="utf-8")
    assert_refused(run_synthua("verify", str(copy)), "format: 'synthua-cutouts/0'")


@pytest.mark.parametrize("change, says", [
    ({"frame": {"spp": 5}}, "frame.spp: 5"),
    ({"people": {"aids": {"rocket": 1}}}, "people.aids"),
    ({"conditions": ["clear_night"]}, "conditions"),
    ({"camera": {"height_m": [3, 1]}}, "camera.height_m"),
    ({"count": 0}, "count"),
])
def test_a_bad_config_is_one_line(tmp_path, change, says):
    config = tmp_path / "bad.json"
    config.write_text(json.dumps({**TINY, **change}), encoding="utf-8")
    assert_refused(run_synthua("cutouts", "--config", str(config), "--out", str(tmp_path / "bank")), says)
    assert not (tmp_path / "bank").exists()


def test_an_existing_folder_is_not_written_into(tmp_path):
    config = tmp_path / "c.json"
    config.write_text(json.dumps(TINY), encoding="utf-8")
    (tmp_path / "bank").mkdir()
    (tmp_path / "bank" / "keep.txt").write_text("mine", encoding="utf-8")
    assert_refused(run_synthua("cutouts", "--config", str(config), "--out", str(tmp_path / "bank")), "not an empty")
    assert [p.name for p in (tmp_path / "bank").iterdir()] == ["keep.txt"]


def test_no_shadow_ends_at_its_crops_border(bank):
    """The shadow layer covers the ground around the frame (a low sun's shadow goes on beyond it) and fades a longer
    one out: no cut-out's shadow is cut off in a straight line at its crop's border (where it would be pasted)."""
    from synthua_usd.pipeline.cutouts import SHADOWED

    folder, _ = bank
    beyond = 0
    for entry in entries(folder):
        shadow = read_image(folder / entry["files"]["shadow"])[0][..., 0] / 255.0
        border = np.concatenate([shadow[0], shadow[-1], shadow[:, 0], shadow[:, -1]])
        assert border.min() >= SHADOWED - 1 / 255, entry["id"]
        x0, y0 = entry["camera"]["crop_origin"]
        (w, h), (frame_w, frame_h) = entry["size"], entry["camera"]["frame"]
        beyond += x0 < 0 or y0 < 0 or x0 + w > frame_w or y0 + h > frame_h
    assert beyond, "some shadow of the bank reaches beyond its frame"


def test_the_shadow_traced_where_it_can_fall_is_the_shadow_traced_everywhere(bank):
    """The shadow layer traces only the pixels where the group's box can shadow the ground (or the sky's occlusion
    is measured) and only the sun rays that meet the box: the same layer, to the bit, as every pixel of the frame
    and its pad traced, for every view of a group (the sun from several sides, one close camera)."""
    from synthua_usd.backends.mitsuba.cutout_passes import ground_light, ground_shadow
    from synthua_usd.model.taxonomy import ClassMap
    from synthua_usd.pipeline.cutouts import _bounds, shadow_pad

    folder, config = bank
    worker = CutoutWorker(CutoutJob(CutoutsConfig.load(config), ClassMap.default().document(), str(folder)))
    drawn, placements = worker.set_group(1)
    shadowed = 0
    for view in range(3):
        _, _, snapshot, camera, condition = worker.set_view(drawn, placements, view)
        worker.session.render(snapshot, camera, rgb=False, condition=condition)
        light, bounds = ground_light(worker.session), _bounds(snapshot)
        near = (*((bounds[0, :2] + bounds[1, :2]) / 2), float(np.hypot(*(bounds[1, :2] - bounds[0, :2])) / 2 + 1.5
                                                            * bounds[1, 2]))
        pad = shadow_pad(TINY["frame"]["width"], TINY["frame"]["height"])
        everywhere = ground_shadow(worker.session, camera, light, near, pad)
        np.testing.assert_array_equal(ground_shadow(worker.session, camera, light, near, pad, bounds), everywhere)
        shadowed += everywhere.min() < 0.9
    assert shadowed, "a shadow was cast"
