"""Distractors (issue 40: the ``distractors`` part of the randomise block): what they may be and how they are
labelled (never a person; only empty wheelchairs a mobility aid), drawn per scene from a stream of their own (the
same seed the same draw; the scene's other draws unmoved), standing free on the ground and on table tops away from
the cameras, the crowd kept clear of them, the aid users placed in view still seen, labels exact against an
independent Embree ray cast, and impossible values refused in one line."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from conftest import SCENARIO
from reference_raycast import reference_labels
from synthua_usd.agents.profiles import PROFILES
from synthua_usd.assets.distractor_objects import CATALOGUE
from synthua_usd.backends.mitsuba.session import RenderSession
from synthua_usd.core.errors import InputError
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.randomisation.config import RandomisationConfig
from synthua_usd.randomisation.distractors import DistractorRandomisation
from synthua_usd.usd.cameras import read_camera
from synthua_usd.usd.distractor_layer import DISTRACTORS_ROOT
from synthua_usd.usd.randomisation_layer import CROWD_ROOT
from synthua_usd.usd.reader import StageReader
from synthua_usd.usd.stage_io import open_stage

W, H = 96, 72
CCTV, EYE = "/World/Cameras/CCTV", "/World/Cameras/PedestrianEye"
AIDS = {"manual_wheelchair", "electric_wheelchair", "walker", "crutch", "smart_cane", "wooden_cane", "orthopedic_cane",
        "tripod_cane"}
ON = {"seed": 2, "crowd": {"density_per_m2": [0.05, 0.08]},
      "distractors": {"enabled": True, "ground_per_100m2": [8.0, 10.0], "on_surfaces": [4, 6]}}


def test_the_catalogue_labels_honestly(class_map):
    for name, entry in CATALOGUE.items():
        assert class_map.resolve(entry.label) is not None
        assert entry.label != "person", name
        assert (entry.label in AIDS) == name.startswith("empty_"), name  # only an empty wheelchair is an aid
    assert {n for n, e in CATALOGUE.items() if e.group == "hard_negative"} == {
        "stroller", "shopping_trolley", "empty_manual_wheelchair", "empty_electric_wheelchair"}


@pytest.fixture(scope="module")
def scattered(class_map):
    from synthua_usd.pipeline.randomiser import Randomiser

    stage = open_stage(SCENARIO)
    randomiser = Randomiser(stage, RandomisationConfig.from_document(ON), class_map, (W, H))
    reader = StageReader(stage, class_map)
    views = []
    for seed in range(3):
        for camera in (CCTV, EYE):
            drawn = randomiser.apply(seed, camera, 24.0, None)
            views.append((seed, camera, drawn, reader.snapshot(24.0), read_camera(stage, camera, 24.0)))
    yield randomiser, views
    randomiser.close()


def test_distractors_stand_free_and_away_from_cameras(scattered):
    randomiser, views = scattered
    config = randomiser.config.distractors
    for seed, camera, drawn, _, _ in views:
        ground = [d for d in drawn.distractors.items if d.on == "ground"]
        assert len(ground) >= 3, seed
        for k, a in enumerate(ground):
            assert np.min(np.hypot(*(randomiser.cameras_xy - a.position[:2]).T)) >= config.camera_clearance_m + a.radius_m
            for b in ground[k + 1:]:
                assert math.dist(a.position[:2], b.position[:2]) >= a.radius_m + b.radius_m
            # on the walkable ground: the ground under its centre is where it stands
            assert randomiser.area.height_below(np.array([*a.position[:2], a.position[2] + 0.01])) == \
                pytest.approx(a.position[2], abs=0.03)


def test_small_distractors_stand_on_tops_in_a_room_and_render_exact_labels(class_map, tmp_path):
    """In a clinic (tables and a reception counter), small primitives stand on the tops, 0.6-1.9 m above the
    floor, and the room with its distractors and crowd renders exact labels."""
    from synthua_usd.pipeline.randomiser import Randomiser
    from synthua_usd.pipeline.setting_scenes import write_setting_scene

    stage = open_stage(write_setting_scene(SCENARIO, "clinic", 0, tmp_path / "clinic", class_map))
    randomiser = Randomiser(stage, RandomisationConfig.from_document(ON), class_map, (W, H))
    reader = StageReader(stage, class_map)
    session = RenderSession(RenderConfig(width=W, height=H, spp=1))
    tops = 0
    for seed in range(2):
        drawn = randomiser.apply(seed, EYE, 24.0, None)
        for d in drawn.distractors.items:
            if d.on == "surface":
                tops += 1
                assert CATALOGUE[d.object].group == "primitive" and d.height_m <= 0.3
                below = randomiser.area.height_below(np.array(d.position) - [0.0, 0.0, 0.02])
                assert 0.6 <= d.position[2] - below <= 1.9
        snapshot, cam = reader.snapshot(24.0), read_camera(stage, EYE, 24.0)
        frame = session.render(snapshot, cam, rgb=False)
        ref_class, ref_inst = reference_labels(snapshot, cam, W, H)
        assert np.array_equal(ref_class, frame.class_ids) and np.array_equal(ref_inst, frame.instance_ids)
    assert tops >= 4
    randomiser.close()


def test_the_crowd_keeps_clear_and_aid_users_placed_in_view_are_seen(scattered):
    randomiser, views = scattered
    session = RenderSession(RenderConfig(width=320, height=240, spp=1))
    placed = seen = 0
    for seed, camera, drawn, snapshot, cam in views:
        discs = drawn.distractors.discs()
        for member, place in zip(drawn.scene.cast, drawn.view.placements):
            if member.seat is None and place.in_view:  # placed free: clear of every distractor's disc
                r = PROFILES[member.profile].radius_m
                assert all(math.hypot(place.position[0] - x, place.position[1] - y) >= r + rr for x, y, rr in discs)
        ids = set(np.unique(session.render(snapshot, cam, rgb=False).instance_ids).tolist())
        by_path = {i.prim_path: i.id for i in snapshot.instances}
        for k, place in enumerate(drawn.view.placements):
            if place.in_view:
                placed += 1
                seen += by_path[f"{CROWD_ROOT}/Agent_{k:04d}/Person"] in ids
    assert placed >= 6 and seen >= 0.75 * placed, (placed, seen)


def test_labels_are_exact_and_no_distractor_is_a_person(scattered, class_map):
    _, views = scattered
    session = RenderSession(RenderConfig(width=W, height=H, spp=1))
    distractor_pixels = 0
    for seed, camera, drawn, snapshot, cam in views:
        frame = session.render(snapshot, cam, rgb=False)
        ref_class, ref_inst = reference_labels(snapshot, cam, W, H)
        assert np.array_equal(ref_class, frame.class_ids) and np.array_equal(ref_inst, frame.instance_ids)
        mine = {i.id: i for i in snapshot.instances if i.prim_path.startswith(DISTRACTORS_ROOT + "/")}
        assert len(mine) == len(drawn.distractors.items)
        for item, inst in zip(drawn.distractors.items, sorted(mine.values(), key=lambda i: i.prim_path)):
            assert inst.class_name == class_map.resolve(item.label).name != "person"
        distractor_pixels += int(np.isin(frame.instance_ids, list(mine)).sum())
    assert distractor_pixels > 50  # they are in the pictures


def test_the_same_seed_draws_the_same_distractors_and_moves_no_other_draw(scattered, class_map):
    from synthua_usd.pipeline.randomiser import Randomiser

    randomiser, views = scattered
    fresh = Randomiser(open_stage(SCENARIO), randomiser.config, class_map, (W, H))
    seed, camera, drawn, _, _ = views[3]
    again = fresh.apply(seed, camera, 24.0, None)
    assert again.distractors == drawn.distractors and again.to_dict() == drawn.to_dict()
    fresh.close()
    off = Randomiser(open_stage(SCENARIO), replace(randomiser.config, distractors=DistractorRandomisation()),
                     class_map, (W, H))
    plain = off.apply(seed, camera, 24.0, None)
    assert plain.distractors is None and "distractors" not in plain.to_dict()
    assert plain.scene == drawn.scene and plain.view.camera == drawn.view.camera  # the scene's draws as without them
    off.close()


@pytest.mark.parametrize("values, mentions", [
    ({"on_surfaces": [0.5, 2]}, "distractors.on_surfaces: [0.5, 2.0]; expected two whole numbers"),
    ({"objects": ["piano"]}, "distractors.objects: piano; expected one or more distinct of box"),
    ({"ground_per_100m2": [5, 1]}, "distractors.ground_per_100m2: [5, 1]"),
    ({"textured_share": 2.0}, "distractors.textured_share: 2.0; expected a number in [0, 1]"),
    ({"max_ground": -1}, "distractors.max_ground: -1"),
])
def test_impossible_values_are_refused_in_one_line(values, mentions):
    with pytest.raises(InputError) as err:
        RandomisationConfig.from_document({"distractors": values})
    assert mentions in str(err.value) and "\n" not in str(err.value)


def test_an_empty_wheelchair_is_boxed_alone_under_every_convention():
    """A wheelchair without a user (an empty-wheelchair distractor) is boxed as a wheelchair, its box its own frame's
    under both named conventions, while a used chair's box covers its user (with_user); no person box comes of it."""
    from synthua_usd.analytics.detection_targets import image_boxes, targets_for

    used = {"class_name": "manual_wheelchair", "prim_path": "/World/Randomisation/Crowd/Agent_0000/ManualWheelchair",
            "area": 50, "bbox": [10, 20, 10, 10], "relations": {}}
    user = {"class_name": "person", "prim_path": "/World/Randomisation/Crowd/Agent_0000/Person", "area": 80,
            "bbox": [11, 5, 8, 20], "relations": {"uses": used["prim_path"], "uses_class": "manual_wheelchair"}}
    empty = {"class_name": "manual_wheelchair", "prim_path": "/World/Randomisation/Distractors/D000_EmptyManualWheelchair",
             "area": 40, "bbox": [40, 20, 10, 10], "relations": {}}
    for convention, people in (("synthua", 1), ("wheelchair-sets", 0)):
        boxes = image_boxes([used, user, empty], targets_for(convention))
        chairs = [(b.x, b.y, b.w, b.h) for b in boxes if b.label == "manual_wheelchair"]
        assert chairs == [(10, 5, 10, 25), (40, 20, 10, 10)], convention
        assert sum(b.label == "person" for b in boxes) == people
