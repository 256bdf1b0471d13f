"""Scene randomisation applied to a loaded stage: an image is the same whatever the stage showed before, its
labels agree with an independent ray cast, the scenario's crowd gives way to the scene's, people placed for the
camera are seen, and the layers written out compose to the same scene."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from pxr import Sdf

from conftest import SCENARIO
from reference_raycast import meshes_hit, reference_labels
from snapshot_checks import assert_same_snapshot
from synthua_usd.backends.mitsuba.session import RenderSession
from synthua_usd.model.conditions import Condition
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.pipeline.randomiser import Randomiser
from synthua_usd.randomisation.config import HairRandomisation, RandomisationConfig
from synthua_usd.usd.agents_writer import AGENTS_ROOT
from synthua_usd.usd.cameras import read_camera
from synthua_usd.usd.conditions import read_condition
from synthua_usd.usd.randomisation_layer import CROWD_ROOT, HAIR_SEGMENT, LOOKS_ROOT, scene_layers
from synthua_usd.usd.reader import StageReader, read_snapshot
from synthua_usd.usd.stage_io import open_stage

W, H = 96, 72
CCTV, EYE = "/World/Cameras/CCTV", "/World/Cameras/PedestrianEye"
CONFIG = RandomisationConfig(seed=3)


def randomised(class_map):
    stage = open_stage(SCENARIO)
    return stage, StageReader(stage, class_map), Randomiser(stage, CONFIG, class_map, (W, H))


def test_an_image_is_the_same_whatever_came_before(class_map, variant):
    """The stage, its reader and a render session carried through other scenes and views give the image what a
    fresh stage, reader and session give it: the same snapshot (points bit for bit) and the same bytes of labels
    and RGB (the session updated in place, not reloaded)."""
    stage, reader, randomiser = randomised(class_map)
    session = RenderSession(RenderConfig(width=W, height=H, spp=2, variant=variant, denoise=False))
    for seed, camera, condition in ((0, CCTV, "clear_day"), (1, EYE, "sunset"), (1, CCTV, "clear_day"),
                                    (0, EYE, "clear_day")):
        drawn = randomiser.apply(seed, camera, 24.0, condition)
        session.render(reader.snapshot(24.0), read_camera(stage, camera, 24.0), condition=read_condition(stage, condition),
                       seed=seed)
    loads = session.loads
    drawn = randomiser.apply(1, EYE, 24.0, "clear_day")
    carried = session.render(reader.snapshot(24.0), read_camera(stage, EYE, 24.0),
                             condition=read_condition(stage, "clear_day"), seed=1)
    assert session.loads == loads + 1  # seed 1 after seed 0: a new scene, loaded once

    fresh_stage, fresh_reader, fresh_randomiser = randomised(class_map)
    again = fresh_randomiser.apply(1, EYE, 24.0, "clear_day")
    assert again == drawn
    assert_same_snapshot(reader.snapshot(24.0), fresh_reader.snapshot(24.0))
    fresh = RenderSession(RenderConfig(width=W, height=H, spp=2, variant=variant, denoise=False)).render(
        fresh_reader.snapshot(24.0), read_camera(fresh_stage, EYE, 24.0),
        condition=read_condition(fresh_stage, "clear_day"), seed=1)
    assert np.array_equal(carried.instance_ids, fresh.instance_ids) and np.array_equal(carried.class_ids,
                                                                                        fresh.class_ids)
    assert np.array_equal(carried.rgb, fresh.rgb)
    # a view of the same scene only moves things: updated in place
    randomiser.apply(1, CCTV, 24.0, "clear_day")
    session.render(reader.snapshot(24.0), read_camera(stage, CCTV, 24.0), condition=read_condition(stage, "clear_day"),
                   seed=1)
    assert session.loads == loads + 1


def test_randomised_labels_agree_with_an_independent_ray_cast(class_map):
    """Labels agree with Embree's first hits, the hair meshes' pixels too: the hair's pixels carry the class
    person and the instance id of the person whose hair it is."""
    stage, reader, randomiser = randomised(class_map)
    session = RenderSession(RenderConfig(width=160, height=120, spp=1))
    hair_pixels = agree = 0
    for seed, camera in ((0, CCTV), (2, EYE), (2, CCTV)):
        randomiser.apply(seed, camera, 24.0, None)
        snapshot, cam = reader.snapshot(24.0), read_camera(stage, camera, 24.0)
        frame = session.render(snapshot, cam, rgb=False)
        ref_class, ref_inst = reference_labels(snapshot, cam, 160, 120)
        assert np.mean(ref_class == frame.class_ids) >= 0.9999 and np.mean(ref_inst == frame.instance_ids) >= 0.9999
        people = {i.id for i in snapshot.instances if i.prim_path.startswith(CROWD_ROOT) and i.class_name == "person"}
        assert people & set(np.unique(frame.instance_ids).tolist())  # the new crowd is in the picture
        hit = meshes_hit(snapshot, *cam.pixel_center_rays(160, 120)).reshape(120, 160)
        by_path = {i.prim_path: i for i in snapshot.instances}
        person_class = class_map.resolve("person").id
        for k, mesh in enumerate(snapshot.meshes):
            if f"/{HAIR_SEGMENT}/Hair/" not in mesh.prim_path:
                continue
            owner = by_path[mesh.prim_path.split(f"/{HAIR_SEGMENT}/")[0]]
            assert (mesh.class_id, mesh.instance_id) == (person_class, owner.id) and owner.class_name == "person"
            pixels = hit == k
            hair_pixels += int(pixels.sum())
            agree += int(((frame.instance_ids[pixels] == owner.id) & (frame.class_ids[pixels] == person_class)).sum())
    assert hair_pixels >= 10 and agree >= 0.95 * hair_pixels, (hair_pixels, agree)  # hair in the pictures, the person's


def test_the_scenes_crowd_replaces_the_scenarios(class_map):
    """The scenario's agents are gone; every cast member is a labelled person, an aid user's device is its own
    instance of its class linked by synthua:uses and carrying its contact points; clothes are the cast's; the
    recoloured twin objects render with their variants."""
    stage, reader, randomiser = randomised(class_map)
    drawn = randomiser.apply(4, CCTV, 24.0, None)
    snapshot = reader.snapshot(24.0)
    assert not any(i.prim_path.startswith(AGENTS_ROOT + "/") for i in snapshot.instances)
    by_path = {i.prim_path: i for i in snapshot.instances}
    cast = drawn.scene.cast
    persons = [p for p in by_path if p.startswith(CROWD_ROOT) and p.endswith("/Person")]
    assert len(persons) == len(cast)
    for k, member in enumerate(cast):
        person = by_path[f"{CROWD_ROOT}/Agent_{k:04d}/Person"]
        assert person.class_name == "person" and person.id in snapshot.keypoints
        relations = dict(person.relations)
        if member.aid is None:
            assert "uses" not in relations
            continue
        device = by_path[relations["uses"]]
        assert device.class_name == member.aid and device.id in snapshot.keypoints
        frame = snapshot.materials[f"{LOOKS_ROOT}/Agent_{k:04d}_Frame"]
        assert frame.base_color == pytest.approx(member.device.frame.base_color, abs=1e-6)
    for k, member in enumerate(cast[:3]):  # dressed from the scene's wardrobe, its garments' materials shared
        upper = snapshot.materials[f"{LOOKS_ROOT}/Upper_{member.wear.upper:02d}"]
        assert upper.base_color == pytest.approx(member.upper, abs=1e-6)
        assert member.upper == drawn.scene.wardrobe.uppers[member.wear.upper].colour
        shirt = [m for m in snapshot.meshes if m.prim_path.startswith(f"{CROWD_ROOT}/Agent_{k:04d}/Person/Torso/Upper")]
        assert shirt and all(m.material_key == upper.key for m in shirt)
    recoloured = {m.prim_path: m.material_key for m in snapshot.meshes if m.material_key.startswith(LOOKS_ROOT + "/Twin_")}
    assert len(set(recoloured.values())) == len(drawn.scene.recolours) > 0
    for k, recolour in enumerate(drawn.scene.recolours):
        material = snapshot.materials[f"{LOOKS_ROOT}/Twin_{k:04d}"]
        if recolour.base_color is not None:
            assert material.base_color == pytest.approx(recolour.base_color, abs=1e-6)


def test_aid_users_placed_for_the_camera_are_seen(class_map):
    stage, reader, randomiser = randomised(class_map)
    session = RenderSession(RenderConfig(width=320, height=240, spp=1))
    placed = seen = 0
    for seed in range(4):
        drawn = randomiser.apply(seed, CCTV, 24.0, None)
        snapshot = reader.snapshot(24.0)
        ids = set(np.unique(session.render(snapshot, read_camera(stage, CCTV, 24.0), rgb=False).instance_ids).tolist())
        by_path = {i.prim_path: i.id for i in snapshot.instances}
        for k, place in enumerate(drawn.view.placements):
            if place.in_view:
                placed += 1
                seen += by_path[f"{CROWD_ROOT}/Agent_{k:04d}/Person"] in ids
    assert placed >= 4 and seen >= 0.75 * placed, (placed, seen)  # another person may stand in front


def test_exported_layers_compose_the_same_scene(class_map, tmp_path):
    stage, reader, randomiser = randomised(class_map)
    randomiser.apply(5, EYE, 24.0, "sunset")
    files = randomiser.export(tmp_path / "layer.usda")
    assert [p.name for p in files] == ["layer.usda", "layer.scene.usda", "layer.prototypes.usdc"]
    over = open_stage(SCENARIO, layers=[tmp_path / "layer.usda"])
    assert_same_snapshot(reader.snapshot(24.0), read_snapshot(over, 24.0, class_map))
    camera, again = read_camera(stage, EYE, 24.0), read_camera(over, EYE, 24.0)
    assert np.allclose(camera.camera_to_world, again.camera_to_world) and camera.exposure_ev == again.exposure_ev
    assert read_condition(over, None) == read_condition(stage, "sunset")
    assert isinstance(read_condition(over, None), Condition)
    randomiser.close()  # the stage as composed before: the scenario's crowd is back
    assert any(i.prim_path.startswith(AGENTS_ROOT + "/") for i in reader.snapshot(24.0).instances)


def test_randomise_refuses_a_malformed_record_with_one_line_naming_its_field(tmp_path):
    """``synthua randomise --record`` validates the record against schemas/record.schema.json first."""
    import json

    from synthua_usd.core.errors import InputError
    from synthua_usd.pipeline.randomiser import RandomiseRequest, randomise_image

    record = tmp_path / "dataset" / "records" / "000001_x.json"
    record.parent.mkdir(parents=True)
    record.write_text(json.dumps({"id": 1, "seed": "zero"}))
    with pytest.raises(InputError, match=r"000001_x\.json: not an image record: \(document\): 'camera' is a "
                                         r"required property; expected a document matching \$defs/image of "
                                         r"record\.schema\.json"):
        randomise_image(RandomiseRequest(scenario=SCENARIO, out=tmp_path / "layer.usda", record_path=record))


def test_hair_off_authors_the_layers_of_a_bald_crowd(class_map):
    """With hair off the scene's layers are those of the same cast drawn with hair and then made bald (the
    hair draws nothing else); with hair on, each haired person's head segment holds a Hair part bound to its
    own Hair material."""
    stage, reader, randomiser = randomised(class_map)
    off = Randomiser(open_stage(SCENARIO), dataclasses.replace(CONFIG, hair=HairRandomisation(enabled=False)),
                     class_map, (W, H))
    drawn, bald = randomiser.scene(4), off.scene(4)
    assert [dataclasses.replace(m, hair=None) for m in drawn.cast] == list(bald.cast)
    assert {m.hair.style for m in drawn.cast} - {"none"}
    prototypes, scene, _ = scene_layers(dataclasses.replace(drawn, cast=bald.cast), off.meta, class_map.taxonomy,
                                        off.bodies, off.materials, off.bound, deactivate_agents=off.has_agents)
    assert prototypes.ExportToString() == off.layers.prototypes.ExportToString()
    assert _without_sublayers(scene) == _without_sublayers(off.layers.scene)
    snapshot = reader.snapshot(24.0)
    hair = [m for m in snapshot.meshes if f"/{HAIR_SEGMENT}/Hair/" in m.prim_path]
    haired = [k for k, m in enumerate(drawn.cast) if m.hair.style != "none"]
    assert sorted({m.prim_path.split("/Person/")[0] for m in hair}) == [f"{CROWD_ROOT}/Agent_{k:04d}" for k in haired]
    for m in hair:
        k = int(m.prim_path.split("Agent_")[1][:4])
        assert m.material_key == f"{LOOKS_ROOT}/Agent_{k:04d}_Hair"
        material = snapshot.materials[m.material_key]
        assert material.base_color == pytest.approx(drawn.cast[k].hair.base_color, abs=1e-6)
        assert 0.4 <= material.roughness <= 0.6 + 1e-6


def _without_sublayers(layer):
    copy = Sdf.Layer.CreateAnonymous("copy.usda")
    copy.TransferContent(layer)
    copy.subLayerPaths.clear()
    return copy.ExportToString()


def test_companions_are_linked_to_their_aid_user_and_hold_the_chair(class_map):
    """A pusher's person prim names the chair it pushes (synthua:pushes), an accompanying companion's the aid user
    it walks beside (synthua:accompanies); a record's relations give their classes; and in the composed scene
    the pusher's wrists (its COCO keypoints) are at the chair's push handles (postures.push_handles, placed by the
    chair's own world transform), within the hand's length."""
    from pxr import UsdGeom

    from synthua_usd.assets.postures import push_handles
    from synthua_usd.dataset.annotations import relation_entries
    from synthua_usd.model.keypoint_classes import PERSON_KEYPOINTS
    from synthua_usd.randomisation.config import CrowdRandomisation

    crowd = CrowdRandomisation(density_per_m2=(0.1, 0.1), aid_share=(0.6, 0.6), pushed_share=(1.0, 1.0),
                               accompanied_share=(1.0, 1.0), aids=("manual_wheelchair", "walker"))
    stage = open_stage(SCENARIO)
    reader = StageReader(stage, class_map)
    randomiser = Randomiser(stage, dataclasses.replace(CONFIG, crowd=crowd), class_map, (W, H))
    pushers = companions = 0
    for seed in range(3):
        drawn = randomiser.apply(seed, CCTV, 24.0, None)
        snapshot = reader.snapshot(24.0)
        by_path = {i.prim_path: i for i in snapshot.instances}
        class_of = {p: i.class_name for p, i in by_path.items()}
        wrists = [PERSON_KEYPOINTS.index(n) for n in ("left_wrist", "right_wrist")]
        for k, member in enumerate(drawn.scene.cast):
            person = by_path[f"{CROWD_ROOT}/Agent_{k:04d}/Person"]
            relations = relation_entries(person.relations, class_of)
            if member.pushes is not None:
                pushers += 1
                chair = f"{CROWD_ROOT}/Agent_{member.pushes:04d}/ManualWheelchair"
                assert relations["pushes"] == chair and relations["pushes_class"] == "manual_wheelchair"
                user = dict(by_path[f"{CROWD_ROOT}/Agent_{member.pushes:04d}/Person"].relations)
                assert user["uses"] == chair
                m = np.array(UsdGeom.Xformable(stage.GetPrimAtPath(chair)).ComputeLocalToWorldTransform(24.0))
                handles = push_handles(member.pushing) @ m[:3, :3] + m[3, :3]
                hands = snapshot.keypoints[person.id].points[wrists]
                assert np.linalg.norm(hands - handles, axis=1).max() < 0.15, (hands, handles)
            elif member.accompanies is not None:
                companions += 1
                assert relations["accompanies"] == f"{CROWD_ROOT}/Agent_{member.accompanies:04d}/Person"
                assert relations["accompanies_class"] == "person"
            else:
                assert not {"pushes", "accompanies"} & set(relations)
    assert pushers >= 2 and companions >= 2, (pushers, companions)


def _looked_up_albedo(snapshot, camera, W: int, H: int):
    """Independently of the translator: at the first hit (Embree) of every pixel-centre ray on a mesh whose material
    has a base-colour texture, the texture's value there: the reader's st interpolated barycentrically, the image
    read by OpenImageIO (raw, 8-bit), bilinear with its wrap mode, times its scale plus its bias, clipped to [0, 1].
    Returns (H*W, 3) values and the (H*W,) mask of the pixels looked up."""
    from synthua_usd.core.images import read_image
    from trimesh.ray.ray_pyembree import RayMeshIntersector
    import trimesh

    origins, dirs = camera.pixel_center_rays(W, H)
    verts, faces, owner = snapshot.world_triangles()
    uvs = np.concatenate([m.uvs if m.uvs is not None else np.zeros((len(m.points), 2), np.float32)
                          for m in snapshot.meshes])
    tri, ray, where = RayMeshIntersector(trimesh.Trimesh(verts, faces, process=False, validate=False)).intersects_id(
        origins, dirs, multiple_hits=False, return_locations=True)
    bary = trimesh.triangles.points_to_barycentric(verts[faces[tri]], where)
    st = np.einsum("kc,kcd->kd", bary, uvs[faces[tri]].astype(np.float64))
    out, looked = np.zeros((W * H, 3)), np.zeros(W * H, bool)
    images = {}
    for k, (t, r) in enumerate(zip(tri, ray)):
        mesh = snapshot.meshes[owner[t]]
        texture = snapshot.materials[mesh.material_key].base_color_texture
        if texture is None or mesh.uvs is None:
            continue
        if texture.path not in images:
            images[texture.path] = read_image(texture.path)[0].astype(np.float64) / 255.0
        image = images[texture.path]
        h, w = image.shape[:2]
        x, y = st[k, 0] * w - 0.5, (1.0 - st[k, 1]) * h - 0.5
        x0, y0 = int(np.floor(x)), int(np.floor(y))
        fx, fy = x - x0, y - y0

        def at(yy, xx):
            if texture.wrap_s == "clamp":
                return image[min(max(yy, 0), h - 1), min(max(xx, 0), w - 1), :3]
            return image[yy % h, xx % w, :3]

        value = ((1 - fx) * (1 - fy) * at(y0, x0) + fx * (1 - fy) * at(y0, x0 + 1) + (1 - fx) * fy * at(y0 + 1, x0)
                 + fx * fy * at(y0 + 1, x0 + 1))
        out[r] = np.clip(value * np.array(texture.scale[:3]) + np.array(texture.bias[:3]), 0.0, 1.0)
        looked[r] = True
    return out, looked


def test_looks_render_their_images_and_change_no_label(class_map):
    """With looks on, every pixel whose first hit is a person's skin, garment or shoe shows the albedo of its
    image where the independent lookup above puts it (Mitsuba's BSDF albedo at the same pixel-centre rays;
    bilinear filtering, within 0.02 on 97 % of them over three views at 320 x 240); faces, fabrics and
    shoes are all among them. And the labels are those of the same scene with looks off, byte for byte: the looks
    split points at texture seams and add normals, never move a triangle."""
    from texture_checks import mitsuba_albedo

    from synthua_usd.backends.mitsuba import variants
    from synthua_usd.randomisation.config import LooksRandomisation

    stage, reader, randomiser = randomised(class_map)
    off_stage = open_stage(SCENARIO)
    off_reader = StageReader(off_stage, class_map)
    off = Randomiser(off_stage, dataclasses.replace(CONFIG, looks=LooksRandomisation(enabled=False)), class_map, (W, H))
    session = RenderSession(RenderConfig(width=320, height=240, spp=1))
    mi = variants.activate("llvm_ad_rgb")
    kinds, close = set(), []
    for seed, camera in ((0, EYE), (2, EYE), (2, CCTV)):
        drawn = randomiser.apply(seed, camera, 24.0, None)
        plain = off.apply(seed, camera, 24.0, None).scene.cast  # the same people, in their own flat colours
        assert [dataclasses.replace(m, wear=None, upper=p.upper, lower=p.lower, shoes=p.shoes)
                for m, p in zip(drawn.scene.cast, plain)] == list(plain)
        snapshot, cam = reader.snapshot(24.0), read_camera(stage, camera, 24.0)
        on_labels = session.render(snapshot, cam, rgb=False)
        off_labels = session.render(off_reader.snapshot(24.0), read_camera(off_stage, camera, 24.0), rgb=False)
        assert np.array_equal(on_labels.class_ids, off_labels.class_ids)
        assert np.array_equal(on_labels.instance_ids, off_labels.instance_ids)
        expected, looked = _looked_up_albedo(snapshot, cam, 320, 240)
        got, hit = mitsuba_albedo(mi, snapshot, cam, 320, 240)
        assert hit[looked].all()
        close += (np.abs(got[looked] - expected[looked]).max(axis=1) < 0.02).tolist()
        kinds |= {snapshot.materials[m.material_key].base_color_texture.path.rsplit("/", 1)[1].split("_")[0]
                  for m in snapshot.meshes if m.uvs is not None}
    assert len(close) > 500 and np.mean(close) > 0.97, (len(close), np.mean(close))
    assert {"face.png", "fabric", "shoe"} <= kinds
