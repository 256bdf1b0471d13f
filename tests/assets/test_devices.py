"""Every model of every mobility aid keeps the contract of the fit and of the agents layer: standing on z = 0
with its footprint about the origin, facing +X, its seat top and width or its grips where the fitted posture
puts the body and hands, tips at the origin, closed outward-wound parts with the palette keys the standard
models use, wheels of the modelled radii on the ground, and a bounded triangle count."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from synthua_usd.assets.devices import DEVICE_MODELS, DEVICES, MAX_TRIANGLES
from synthua_usd.assets.postures import AID_OFFSETS, GRIP_DX, REAR_WHEEL_X, RIM_RADIUS_M, SEATED, STEPPING_AIDS, DeviceFit
from synthua_usd.model import meshes as geo
from synthua_usd.model.materials import PALETTE

MODELS = [(name, model) for name in sorted(DEVICE_MODELS) for model in sorted(DEVICE_MODELS[name])]
FITS = [DeviceFit(grip_height_m=0.78, seat_height_m=0.42, seat_width_m=0.42),
        DeviceFit(grip_height_m=0.95, seat_height_m=0.55, seat_width_m=0.52)]
#: Parts that are wheels: each of their pieces is a tyre touching the ground.
WHEELS = ("RearWheels", "Casters", "Wheels")


def _parts(name: str, model: str, fit: DeviceFit):
    return DEVICE_MODELS[name][model](fit)


def _mesh(parts) -> trimesh.Trimesh:
    return trimesh.Trimesh(*geo.merge(*[p.mesh for p in parts]), process=False)


def _pieces(part) -> list[trimesh.Trimesh]:
    return trimesh.Trimesh(part.points, part.triangles, process=False).split(only_watertight=False)


def test_every_class_has_its_standard_and_a_detailed_model():
    assert set(DEVICE_MODELS) == set(DEVICES)
    for name, models in DEVICE_MODELS.items():
        assert models["standard"] is DEVICES[name] and len(models) == 2 and "detailed" in models, name


@pytest.mark.parametrize("fit", FITS, ids=["small", "large"])
@pytest.mark.parametrize("name,model", MODELS)
def test_stands_on_the_ground_about_the_origin(name, model, fit):
    points = np.concatenate([p.points for p in _parts(name, model, fit)])
    assert abs(points[:, 2].min()) < 1e-9
    lo, hi = points[:, :2].min(axis=0), points[:, :2].max(axis=0)
    assert np.all(np.abs((lo + hi) / 2) < [0.06, 0.01]), (lo + hi) / 2
    if name in STEPPING_AIDS:  # the tip (its lowest points, within 5 mm) at the origin: where the posture plants it
        tip = points[points[:, 2] < 0.005]
        assert np.linalg.norm(tip[:, :2].mean(axis=0)) < 0.005


@pytest.mark.parametrize("name,model", MODELS)
def test_parts_are_closed_outward_wound_and_within_the_triangle_budget(name, model):
    parts = _parts(name, model, DeviceFit())
    for part in parts:
        mesh = trimesh.Trimesh(part.points, part.triangles, process=False)
        assert mesh.is_watertight and mesh.is_winding_consistent, part.name
        assert all(piece.volume > 0 for piece in _pieces(part)), part.name  # every closed piece wound outward
    assert sum(len(p.triangles) for p in parts) < MAX_TRIANGLES


@pytest.mark.parametrize("name,model", MODELS)
def test_materials_are_the_keys_the_standard_models_use(name, model):
    standard = set().union(*({p.material for p in build()} for build in DEVICES.values()))
    keys = {p.material for p in _parts(name, model, DeviceFit())}
    assert keys <= standard and keys <= set(PALETTE)
    assert keys & {"Frame", "Wood"}  # a frame the randomised finishes recolour
    assert "Seat" in keys or name not in SEATED  # a seat the randomised fabrics recolour


def _hands(name: str, fit: DeviceFit) -> list[np.ndarray]:
    """Where the fitted posture puts the hands on the device, device frame (postures.pose)."""
    h, half, g = fit.seat_height_m, fit.seat_width_m / 2, fit.grip_height_m
    if name == "manual_wheelchair":  # on the push rims through the push (20 +- 35 degrees from the top)
        r = RIM_RADIUS_M + 0.02
        return [np.array([REAR_WHEEL_X + r * np.sin(np.radians(a)), s * (half + 0.07), 0.3 + r * np.cos(np.radians(a))])
                for a in (-15.0, 20.0, 55.0) for s in (-1, 1)]
    if name == "electric_wheelchair":  # the left hand over the joystick
        return [np.array([0.22, half + 0.03, h + 0.3])]
    if name == "walker":
        return [np.array([0.3 - AID_OFFSETS["walker"][0][0], s * 0.27, g]) for s in (-1, 1)]
    return [np.array([GRIP_DX[name], 0.0, g])]


#: How near the device's surface each hand is, m (a hand's wrist above the joystick's knob).
HAND_REACH_M = {"manual_wheelchair": 0.03, "electric_wheelchair": 0.07}


@pytest.mark.parametrize("fit", FITS, ids=["small", "large"])
@pytest.mark.parametrize("name,model", MODELS)
def test_grips_are_where_the_fitted_posture_puts_the_hands(name, model, fit):
    _, distance, _ = trimesh.proximity.closest_point(_mesh(_parts(name, model, fit)), np.array(_hands(name, fit)))
    assert distance.max() < HAND_REACH_M.get(name, 0.02), distance


@pytest.mark.parametrize("fit", FITS, ids=["small", "large"])
@pytest.mark.parametrize("name,model", [(n, m) for n, m in MODELS if n in SEATED])
def test_seat_top_and_width_are_the_fitted_ones_and_the_backrest_behind(name, model, fit):
    seat = next(p for p in _parts(name, model, fit) if p.name == "Seat")
    pieces = _pieces(seat)
    cushion = max(pieces, key=lambda m: np.prod(np.ptp(m.vertices[:, :2], axis=0)))  # as test_bodies finds it
    assert abs(cushion.vertices[:, 2].max() - fit.seat_height_m) < 1e-9
    assert abs(np.ptp(cushion.vertices[:, 1]) - fit.seat_width_m) < 1e-9
    lo, hi = cushion.vertices[:, :2].min(axis=0), cushion.vertices[:, :2].max(axis=0)
    assert np.all(lo < 0) and np.all(hi > 0)
    top = seat.points[np.argmax(seat.points[:, 2])]
    assert top[0] < -0.18 and top[2] > fit.seat_height_m + 0.3  # the backrest rises behind the user's back


@pytest.mark.parametrize("name,model", MODELS)
def test_wheels_touch_the_ground_and_rear_wheels_have_the_modelled_radius(name, model):
    for part in _parts(name, model, FITS[1]):
        if part.name not in WHEELS:
            continue
        lowest = [piece.vertices[:, 2].min() for piece in _pieces(part)]
        assert abs(min(lowest)) < 1e-9, part.name
        if model != "standard":  # every wheel on the ground (the standard power chair's casters float 6 cm up)
            assert np.abs(lowest).max() < 1e-9, part.name
        if part.name == "RearWheels":  # the push rims' wheels: 0.6 m about REAR_WHEEL_X, axle 0.3 m up
            for piece in _pieces(part):
                lo, hi = piece.vertices.min(axis=0), piece.vertices.max(axis=0)
                assert np.allclose([hi[0] - lo[0], hi[2] - lo[2], (lo[0] + hi[0]) / 2], [0.6, 0.6, REAR_WHEEL_X], atol=1e-6)


def test_the_detailed_manual_wheelchair_has_spoked_wheels_with_push_rims_of_the_postures_radius():
    fit = FITS[0]
    rims = next(p for p in _parts("manual_wheelchair", "detailed", fit) if p.name == "Rims")
    pieces = _pieces(rims)
    axle = np.array([REAR_WHEEL_X, 0.3])
    push = [m for m in pieces if np.abs(m.vertices[:, 1]).min() > fit.seat_width_m / 2 + 0.08]
    rings = [m for m in push if np.ptp(m.vertices[:, 0]) > 0.5]
    assert len(rings) == 2
    for ring in rings:
        radius = np.linalg.norm(ring.vertices[:, [0, 2]] - axle, axis=1)
        assert abs((radius.min() + radius.max()) / 2 - RIM_RADIUS_M) < 1e-3
    spokes = [m for m in pieces if len(m.faces) == 16 and np.ptp(m.vertices[:, [0, 2]], axis=0).max() > 0.1]
    assert len(spokes) == 48  # 24 a wheel


@pytest.mark.parametrize("fit", FITS, ids=["small", "large"])
def test_the_detailed_manual_wheelchair_has_armrests_and_clothing_guards_between_seat_and_wheels(fit):
    """Padded armrests 0.2-0.24 m over the seat, and guards under them from the seat up, both beside the seat
    (not over the user's thighs) and inside the push rims (where the hands push)."""
    h, w = fit.seat_height_m, fit.seat_width_m / 2
    seat = next(p for p in _parts("manual_wheelchair", "detailed", fit) if p.name == "Seat")
    one_side = [m for m in _pieces(seat) if np.ptp(np.sign(m.vertices[:, 1])) == 0]
    beside = [m for m in one_side if np.abs(m.vertices[:, 1]).min() >= w - 1e-9]
    pads = [m for m in beside if m.vertices[:, 2].min() > h + 0.1]
    guards = [m for m in beside if m.vertices[:, 2].min() < h]
    assert len(pads) == len(guards) == 2
    for pad in pads:
        assert np.allclose([pad.vertices[:, 2].min(), pad.vertices[:, 2].max()], [h + 0.2, h + 0.24])
        assert np.ptp(pad.vertices[:, 0]) > 0.3  # long enough to rest a forearm on
    for piece in pads + guards:
        assert np.abs(piece.vertices[:, 1]).max() < w + 0.095 - 0.02  # clear of the push rims
    for guard in guards:
        assert guard.vertices[:, 2].min() < h and guard.vertices[:, 2].max() >= h + 0.2 - 1e-9


def test_tube_and_torus_are_closed_and_outward_wound():
    tube = trimesh.Trimesh(*geo.tube([(0, 0, 0), (0, 0, 1), (0.5, 0, 1.5), (1, 0.2, 1.5)], 0.05, 8), process=False)
    assert tube.is_watertight and tube.volume > 0 and len(tube.faces) == 2 * 8 * 3 + 2 * 8
    radius = np.linalg.norm(tube.vertices[:8] - [0, 0, 0], axis=1)
    assert np.allclose(radius, 0.05)
    for axis in "xyz":
        ring = trimesh.Trimesh(*geo.torus((1.0, 2.0, 3.0), 0.3, 0.05, axis=axis, major_sections=16, minor_sections=8),
                               process=False)
        assert ring.is_watertight and ring.volume > 0 and len(ring.faces) == 2 * 16 * 8
        assert np.isclose(ring.volume, 2 * np.pi ** 2 * 0.3 * 0.05 ** 2, rtol=0.2)
        k = "xyz".index(axis)
        assert np.allclose(np.ptp(ring.vertices, axis=0), [0.1 if j == k else 0.7 for j in range(3)])
    with pytest.raises(ValueError, match="tube"):
        geo.tube([(0, 0, 0), (0, 0, 0)], 0.05)
