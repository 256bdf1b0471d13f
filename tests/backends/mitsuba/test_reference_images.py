"""RGB renders of a tiny scene against reference images, compared statistically (see reference_images.py
for the reasoning). The references are regenerated only by `make refs`."""

import dataclasses

import numpy as np
import pytest

from reference_images import HEIGHT, WIDTH, compare, reference_path, render_passes, tiny_scene
from synthua_usd.core.images import read_image


@pytest.fixture(scope="module")
def scene(class_map):
    return tiny_scene(class_map)


def reference(variant: str) -> np.ndarray:
    path = reference_path(variant)
    if not path.exists():
        pytest.fail(f"{path} is missing; run `make refs` and commit it")
    pixels, _ = read_image(path)
    assert pixels.shape == (HEIGHT, WIDTH, 3), f"{path} is {pixels.shape}; run `make refs` after changing its size"
    return pixels


def test_render_matches_the_reference(scene, variant):
    passes, instance_ids = render_passes(*scene, variant)
    result = compare(reference(variant), passes, instance_ids)
    assert result.ok, result.problems
    assert len(result.region_t) == 4  # sky, ground, box and ball each compared


def _box_less_red(snapshot):
    key = next(m.material_key for m in snapshot.meshes if m.prim_path == "/World/Box")
    red = snapshot.materials[key]
    color = (0.9 * red.base_color[0],) + red.base_color[1:]
    return dataclasses.replace(snapshot, materials={**snapshot.materials,
                                                    key: dataclasses.replace(red, base_color=color)})


def _weaker_sun(snapshot):
    lights = tuple(dataclasses.replace(l, irradiance=0.9 * l.irradiance) if l.kind == "distant" else l
                   for l in snapshot.lights)
    return dataclasses.replace(snapshot, lights=lights)


@pytest.mark.parametrize("change,region", [(_box_less_red, "/World/Box"), (_weaker_sun, "/World/Ground")],
                         ids=["box 10% less red", "sun 10% weaker"])
def test_a_real_change_fails_the_comparison(scene, variant, change, region):
    """A test of the test: changes of 10 % put the changed region's mean far beyond its threshold."""
    snapshot, camera = scene
    passes, instance_ids = render_passes(change(snapshot), camera, variant)
    result = compare(reference(variant), passes, instance_ids)
    changed = next(i.id for i in snapshot.instances if i.prim_path == region)
    assert any(p.startswith(f"instance {changed}:") for p in result.problems), result.problems
