"""Third-party UsdLux lights: strength is intensity x 2^exposure; a strength beyond our renderer units is read
in the convention it follows (UsdLux's sun-disk radiance, lux, nits), so a stage lit the way other tools
light it renders within a brightness band instead of pure white; a stage without lights gets a default sky."""

import math

import numpy as np
import pytest

from synthua_usd.backends.mitsuba.session import RenderSession
from synthua_usd.model.photometry import CD_PER_M2_PER_UNIT, distant_irradiance, dome_radiance, luminance
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.usd.cameras import read_camera
from synthua_usd.usd.reader import read_snapshot
from synthua_usd.usd.stage_io import open_stage

ALBEDO = 0.5

STAGE = """#usda 1.0
(
    defaultPrim = "World"
    metersPerUnit = 1
    upAxis = "Z"
    startTimeCode = 1
    endTimeCode = 1
)

def Xform "World"
{{
    def Mesh "Ground" (prepend apiSchemas = ["MaterialBindingAPI"])
    {{
        float3[] extent = [(-50, -50, 0), (50, 50, 0)]
        int[] faceVertexCounts = [4]
        int[] faceVertexIndices = [0, 1, 2, 3]
        point3f[] points = [(-50, -50, 0), (50, -50, 0), (50, 50, 0), (-50, 50, 0)]
        rel material:binding = </World/Looks/Grey>
    }}
    def Scope "Looks"
    {{
        def Material "Grey"
        {{
            token outputs:surface.connect = </World/Looks/Grey/Surface.outputs:surface>
            def Shader "Surface"
            {{
                uniform token info:id = "UsdPreviewSurface"
                color3f inputs:diffuseColor = ({a}, {a}, {a})
                float inputs:roughness = 1
                float inputs:specular = 0
                token outputs:surface
            }}
        }}
    }}
    def Camera "Cam"
    {{
        float focalLength = 0.5
        float horizontalAperture = 0.36
        float verticalAperture = 0.24
        float2 clippingRange = (0.1, 100)
        matrix4d xformOp:transform = ( (1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 0, 5, 1) )
        uniform token[] xformOpOrder = ["xformOp:transform"]
    }}
{lights}
}}
"""


def _stage(tmp_path, lights: str, name: str):
    path = tmp_path / f"{name}.usda"
    path.write_text(STAGE.format(a=ALBEDO, lights=lights))
    return open_stage(path)


def _sun(intensity: float, exposure: float = 0.0, extra: str = "") -> str:
    return (f'    def DistantLight "Sun"\n    {{\n        float inputs:intensity = {intensity}\n'
            f'        float inputs:exposure = {exposure}\n{extra}    }}\n')


def _render(stage, class_map):
    snap = read_snapshot(stage, 1.0, class_map)
    cam = read_camera(stage, "/World/Cam", 1.0)
    frame = RenderSession(RenderConfig(width=24, height=16, spp=4, variant="scalar_rgb", denoise=False)).render(
        snap, cam)
    return snap, frame


def test_conventions_against_independent_numbers():
    disk = 2 * math.pi * (1 - math.cos(math.radians(0.53 / 2)))  # 6.72e-5 sr
    assert distant_irradiance(1.2, 0.53, False) == (1.2, "renderer units")  # our own sun
    e, rule = distant_irradiance(50_000, 0.53, False)  # UsdLux's default DistantLight
    assert e == pytest.approx(50_000 * disk) and "disk" in rule
    assert e * CD_PER_M2_PER_UNIT == pytest.approx(245_000, rel=0.01)  # lux: ~2.3 clear-noon suns
    e, rule = distant_irradiance(100_000, 0.53, True)  # normalised: illuminance in lux
    assert (e, rule) == (pytest.approx(100_000 / CD_PER_M2_PER_UNIT), "lux")
    assert dome_radiance(0.08) == (0.08, "renderer units")
    assert dome_radiance(5000.0) == (pytest.approx(5000.0 / CD_PER_M2_PER_UNIT), "nits (cd/m²)")


@pytest.mark.parametrize("intensity,exposure", [(50_000.0, 0.0), (3125.0, 4.0)])
def test_exposure_scaled_sun_renders_within_a_brightness_band(tmp_path, class_map, intensity, exposure):
    """A sun authored as other tools do (UsdLux's default 50,000, or 3,125 at exposure 4: the same strength)
    lights a 0.5-albedo Lambertian ground with 245 klx: scene-linear luminance rho * E / pi, and an exposed
    image in the mid-tones (before: 50,000 units of irradiance, exposure clamped at EV 21, pure white)."""
    stage = _stage(tmp_path, _sun(intensity, exposure), "sun")
    snap, frame = _render(stage, class_map)
    (sun,) = snap.lights
    assert sun.irradiance == pytest.approx(50_000 * 2 * math.pi * (1 - math.cos(math.radians(0.53 / 2))), rel=1e-4)
    lum_cd = luminance(frame.rgb).mean() * CD_PER_M2_PER_UNIT
    assert lum_cd == pytest.approx(ALBEDO * 245_000 / math.pi, rel=0.05)
    display = np.clip(luminance(frame.rgb) * frame.exposure.scale, 0, 1)
    assert not frame.exposure.clamped and 0.1 < display.mean() < 0.5


def test_stage_without_lights_gets_a_default_sky(tmp_path, class_map, caplog):
    stage = _stage(tmp_path, "", "dark")
    with caplog.at_level("WARNING"):
        snap, frame = _render(stage, class_map)
    assert "no UsdLux lights; lit by a default uniform sky" in caplog.text
    (sky,) = snap.lights
    assert sky.kind == "dome"
    # A uniform sky of radiance L over a Lambertian plane: rho * L (the whole hemisphere sees the sky); 10 %:
    # the principled BSDF is not Lambertian at grazing angles (Disney diffuse, Mitsuba's default specular).
    expected = ALBEDO * float(np.dot(sky.color, [0.2126, 0.7152, 0.0722])) * sky.radiance
    assert luminance(frame.rgb).mean() == pytest.approx(expected, rel=0.10)
