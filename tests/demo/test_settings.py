"""The procedural settings as plain data: each kind builds the same twin for the same variant and another for
another, with classes of the class map (floors walkable ``sidewalk``, nothing a person or a mobility aid), rooms lit
by ceiling lamps on under every condition, room for the crowd to stand and sit, and a camera for every rig type
placed inside the room or above the ground, aimed at where people stand."""

from __future__ import annotations

import numpy as np
import pytest

from synthua_usd.composition.rigs import RIG_TYPES
from synthua_usd.demo.settings import BUILDERS, build_setting
from synthua_usd.demo.settings.layout import room_layout, setting_cameras
from synthua_usd.model.cameras import CameraSpec
from synthua_usd.model.conditions import indoors, shipped
from synthua_usd.model.lamps import KINDS, is_on
from synthua_usd.randomisation.settings import INDOOR_KINDS, SETTING_KINDS
from synthua_usd.randomisation.view import WalkArea

PEOPLE_AND_AIDS = {"person", "manual_wheelchair", "electric_wheelchair", "walker", "crutch", "smart_cane",
                   "wooden_cane", "orthopedic_cane", "tripod_cane"}


def _arrays(setting):
    return [(o.path, o.label, p.name, p.material, p.points.tobytes(), p.triangles.tobytes())
            for o in setting.twin.objects for p in o.parts]


def test_every_kind_has_a_builder():
    assert tuple(BUILDERS) == SETTING_KINDS


@pytest.mark.parametrize("kind", SETTING_KINDS)
def test_a_setting_is_its_variant_and_honestly_labelled(kind, class_map):
    setting = build_setting(kind, 3, textures=False)
    assert _arrays(setting) == _arrays(build_setting(kind, 3, textures=False))
    assert _arrays(setting) != _arrays(build_setting(kind, 4, textures=False))
    labels = set(setting.twin.label_counts())
    assert all(class_map.resolve(label) for label in labels)
    assert not labels & PEOPLE_AND_AIDS and "sidewalk" in labels
    assert setting.indoor == (kind in INDOOR_KINDS)
    vertices, faces, face_labels = setting.twin.labelled_triangles()
    area = WalkArea.build(vertices, faces, np.array([class_map.resolve(x).name for x in face_labels], object))
    assert area.area_m2() > 40.0 and len(area.nodes) > 100  # room for a crowd
    if setting.indoor:
        lamps = [p for o in setting.twin.objects if o.label == "luminaire" for p in o.parts if p.attributes.get("lamp")]
        assert lamps and {p.attributes["lamp"] for p in lamps} == {"ceiling"}
        lo, hi = vertices.min(axis=0), vertices.max(axis=0)
        for x, y, z in setting.layout.high_spots + setting.layout.eye_spots:  # cameras stand inside the room
            assert lo[0] < x < hi[0] and lo[1] < y < hi[1] and z < setting.layout.ceiling_z


def test_shelves_and_seats_give_seats_only_to_seats(class_map):
    """The crowd's sitters find the rows of seats of a clinic, and no shelf board at a seat's height."""
    for kind, least in (("clinic", 6), ("shop", 0)):
        setting = build_setting(kind, 0, textures=False)
        vertices, faces, labels = setting.twin.labelled_triangles()
        area = WalkArea.build(vertices, faces, np.array([class_map.resolve(x).name for x in labels], object))
        assert len(area.seats) >= least if least else len(area.seats) == 0, (kind, len(area.seats))


def test_room_lights_shine_under_every_condition_and_rooms_have_no_weather():
    ceiling = KINDS["ceiling"]
    for name in ("clear_day", "clear_night", "night_rain_fog", "snow"):
        outdoor = shipped(name)
        inside = indoors(outdoor)
        assert is_on(ceiling, inside, "/World/Twin/Lighting/CeilingLight_000")
        assert inside.name == outdoor.name and not inside.sun_up and inside.night_sky_luminance_cd_m2 == 0.0
        assert (inside.fog_visibility_m, inside.rain_rate_mm_per_h, inside.ground_wetness, inside.snow_cover,
                inside.lit_window_fraction) == (np.inf, 0.0, 0.0, 0.0, 0.0)
    assert not is_on(KINDS["street"], shipped("clear_day"), "/a")  # street lamps still follow the condition


def test_every_rig_type_gets_a_camera_aimed_at_the_focus():
    layout = room_layout(-10.0, -1.5, 10.0, 1.5, 3.0)
    wanted = [CameraSpec(name, (0, 0, 0), (1, 0, 0), 4.0, 4.8, 3.6, "", rig_type=rig)
              for name, rig in (("A", "cctv"), ("B", "cctv"), ("C", "pedestrian_eye"), ("D", "wheelchair_eye"),
                                ("E", "uav_nadir"), ("F", "uav_oblique"), ("G", "dashcam"), ("H", None))]
    placed = setting_cameras(layout, wanted)
    assert [c.name for c in placed] == list("ABCDEFGH")
    assert [c.rig_type for c in placed] == [c.rig_type for c in wanted]
    by = {c.name: c for c in placed}
    assert by["A"].eye != by["B"].eye and by["C"].eye[:2] != by["D"].eye[:2]  # other corners, other ends
    assert by["C"].eye[2] == pytest.approx(1.6) and by["D"].eye[2] == pytest.approx(1.2)
    for cam, asked in zip(placed, wanted):
        # the rig type's widest focal length (a room is smaller than the street a rig was zoomed for), else its own
        assert cam.focal_length_mm == (RIG_TYPES[asked.rig_type].lens.default_focal_mm if asked.rig_type else 4.0)
        assert cam.eye[2] < 3.0 and cam.horizontal_aperture_mm == 4.8
        forward = np.subtract(cam.target, cam.eye)
        to_focus = np.subtract(layout.focus, cam.eye)
        cos = forward @ to_focus / np.linalg.norm(forward) / np.linalg.norm(to_focus)
        assert cos > 0.9, cam.name  # looking at where people stand
