"""Rig requests as plain data: parsing, defaults per type, and refusals that name the value and the range."""

import pytest

from synthua_usd.composition.rigs import RIG_TYPES, RigSpec, describe_types
from synthua_usd.core.errors import InputError


def test_parse_fills_the_types_defaults():
    spec = RigSpec.parse("cctv")
    assert (spec.type, spec.height_m, spec.aim, spec.count, spec.apertures_mm) == ("cctv", 6.0, "aid_user", 1, (4.8, 3.6))
    assert spec.distortion.is_zero and not spec.moving
    spec = RigSpec.parse("wheelchair_eye: ride=auto, aim=crossing, k1=-0.1, height_m=1.15, name=WC")
    assert (spec.height_m, spec.aim, spec.ride, spec.name, spec.distortion.k1) == (1.15, "crossing", "auto", "WC", -0.1)
    assert spec.moving and RigSpec.parse("dashcam").moving and RigSpec.parse("dashcam").aim == "none"


def test_every_type_documents_its_heights_and_lens():
    table = describe_types()
    for name, kind in RIG_TYPES.items():
        assert name in table and kind.lens.doc in table
        lo, hi = kind.height_range_m
        assert lo <= kind.default_height_m <= hi
        assert kind.lens.focal_range_mm[0] <= kind.lens.default_focal_mm <= kind.lens.focal_range_mm[1]


@pytest.mark.parametrize("text, message", [
    ("tripod", "rig type 'tripod' is unknown; expected one of cctv, dashcam"),
    ("cctv:height_m=12", "height_m = 12.0; expected 3-8 m"),
    ("dashcam:height_m=2", "height_m = 2.0; expected 1.2-1.5 m"),
    ("uav_nadir:height_m=150", "height_m = 150.0; expected 20-120 m"),
    ("pedestrian_eye:height_m=nan", "height_m = nan; expected 1.45-1.75 m"),
    ("cctv:speed_kmh=30", "speed_kmh do(es) not apply to a cctv rig"),
    ("cctv:zoom=2", "zoom do(es) not apply to a cctv rig"),
    ("cctv:height_m", "'height_m' is not key=value"),
    ("cctv:height_m=high", "height_m = 'high'; expected a number"),
    ("cctv:count=0", "count = 0; expected an integer 1-20"),
    ("cctv:aim=bicycle", "aim = 'bicycle'; expected aid_user, crossing, curb_ramp, none, a mobility-aid class"),
    ("cctv:mount=roof", "mount = 'roof'; expected one of any, pole, facade"),
    ("uav_oblique:tilt_deg=89", "tilt_deg = 89.0; expected 15-75"),
    ("wheelchair_eye:ride=yes", "ride = 'yes'; expected 'auto' or an agent's prim path"),
    ("cctv:k1=inf", "distortion k1: inf; expected a finite number"),
    ("cctv:name=my camera", "name = 'my camera'; expected a USD prim name"),
    ("cctv:aim=/World/Agents/Agent_0001,count=2", "count = 2 with one target prim"),
])
def test_bad_rigs_are_refused_naming_the_value(text, message):
    with pytest.raises(InputError) as err:
        RigSpec.parse(text)
    assert message in str(err.value)


def test_distortion_without_an_inverse_over_the_image_is_refused():
    with pytest.raises(InputError, match="rig 1 \\(cctv\\): Brown-Conrady distortion .* has no inverse"):
        RigSpec.parse("cctv:k1=-0.5").check_lens(1280, 960, "rig 1 (cctv)")
    RigSpec.parse("cctv:k1=-0.05").check_lens(1280, 960, "rig 1 (cctv)")  # a mild barrel lens is fine
