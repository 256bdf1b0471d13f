"""How diverse a dataset's scenes are: the figures ``synthua stats`` reports beside the paper's statistics.

From the records alone (the choices scene randomisation recorded, :mod:`synthua_usd.pipeline.randomiser`):

* distinct scenes (seeds' casts), districts and view layers (every image whose layer differs is a scene of
  its own);
* over the people and devices each image shows: the age, build (body-mass index) and Monk skin tone of the
  body, the colour of the upper and lower garments, and the device's finish and frame colour;
* over the images: the sun's elevation and azimuth, and the camera's height above the ground beneath it.

And from the label maps: the mean per-pixel disagreement of the class maps of images that share camera and
time code (0: the same picture of classes; what randomisation changes between them), over at most
:data:`MAX_PAIRS` pairs, taken in image-id order.

Colour names are those of the colour's hue in sRGB (red, orange, yellow, green, cyan, blue, purple, pink), or
black, grey and white for colours with little saturation.
"""

from __future__ import annotations

import colorsys
from collections import Counter
from itertools import combinations

import numpy as np

from synthua_usd.analytics.dataset_index import DatasetIndex, ImageSummary
from synthua_usd.composition.scenario import CROWD_ROOT
from synthua_usd.model.materials import MONK_SKIN_TONES
from synthua_usd.model.srgb import from_linear

#: Most image pairs the class-map disagreement reads.
MAX_PAIRS = 200
AGE_EDGES = (0, 13, 18, 30, 45, 60, 75, 120)
#: WHO's body-mass-index classes: under 18.5 underweight, 25 overweight, 30 obese.
BMI_EDGES = (0.0, 18.5, 25.0, 30.0, 100.0)
ELEVATION_EDGES = tuple(range(-90, 91, 10))
COMPASS = ("N", "NE", "E", "SE", "S", "SW", "W", "NW")
HEIGHT_EDGES = (0.0, 1.0, 1.5, 2.0, 3.0, 5.0, 8.0, 15.0, 30.0, 60.0, 120.0, 1e9)
_HUES = ((15, "red"), (45, "orange"), (70, "yellow"), (160, "green"), (200, "cyan"), (260, "blue"),
         (300, "purple"), (345, "pink"), (361, "red"))


def colour_name(linear_rgb) -> str:
    """The name of a linear Rec.709 colour (see the module docstring)."""
    r, g, b = (float(v) for v in from_linear(np.clip(np.asarray(linear_rgb, float), 0.0, 1.0)))
    hue, saturation, value = colorsys.rgb_to_hsv(r, g, b)
    if value < 0.2:
        return "black"
    if saturation < 0.2:
        return "white" if value > 0.8 else "grey"
    degrees = hue * 360.0
    return next(name for edge, name in _HUES if degrees < edge)


def _histogram(values, edges) -> dict:
    counts, _ = np.histogram(np.asarray(values, float), bins=np.asarray(edges, float))
    return {"edges": [float(e) for e in edges], "counts": [int(c) for c in counts]}


def _counts(values) -> dict:
    return dict(sorted(Counter(values).items()))


def _people(images: list[ImageSummary]) -> tuple[dict, dict]:
    """(appearance histograms of the people shown, finish and colour counts of the devices shown)."""
    from synthua_usd.assets.bodies import load_bank

    bank = load_bank()
    ages, bmis, tones, upper, lower, finishes, frames = [], [], [], [], [], [], []
    for img in images:
        cast = img.randomisation["scene"]["cast"]
        shown = set(img.visible)
        for k, member in enumerate(cast):
            agent = f"{CROWD_ROOT}/Agent_{k:04d}"
            if f"{agent}/Person" in shown:
                body = int(member["body"])
                ages.append(float(bank.years[body]))
                bmis.append(float(bank.mass_kg[body] / bank.height_m[body] ** 2))
                tones.append(int(str(member["skin"]).removeprefix("Skin")) + 1)
                upper.append(colour_name(member["upper"]))
                lower.append(colour_name(member["lower"]))
            device = member.get("device")
            if device and any(p.startswith(agent + "/") and not p.endswith("/Person") for p in shown):
                finishes.append(device["frame"]["name"])
                frames.append(colour_name(device["frame"]["base_color"]))
    people = {"count": len(ages), "age_years": _histogram(ages, AGE_EDGES),
              "body_mass_index": _histogram(bmis, BMI_EDGES),
              "monk_skin_tone": {str(k): tones.count(k) for k in range(1, len(MONK_SKIN_TONES) + 1)},
              "upper_garment_colour": _counts(upper), "lower_garment_colour": _counts(lower)}
    devices = {"count": len(finishes), "finish": _counts(finishes), "frame_colour": _counts(frames)}
    return people, devices


def class_map_disagreement(index: DatasetIndex, max_pairs: int = MAX_PAIRS) -> dict:
    """Mean and spread of the per-pixel class disagreement of image pairs sharing camera and time code."""
    from synthua_usd.core.images import read_image

    groups: dict[tuple, list[ImageSummary]] = {}
    for img in index.images:
        groups.setdefault((img.camera_path, img.time_code), []).append(img)
    pairs = [pair for key in sorted(groups) for pair in combinations(groups[key], 2)][:max_pairs]
    maps: dict[int, np.ndarray] = {}

    def class_map(img: ImageSummary) -> np.ndarray:
        if img.id not in maps:
            maps[img.id] = read_image(index.root / img.class_png)[0]
        return maps[img.id]

    values, other_seed = [], []
    for a, b in pairs:
        ca, cb = class_map(a), class_map(b)
        if ca.shape != cb.shape:
            continue
        values.append(float(np.mean(ca != cb)))
        other_seed.append(a.seed != b.seed)
    v = np.asarray(values)
    seeds = v[np.asarray(other_seed, bool)] if len(v) else v
    return {"pairs": len(values), "mean": float(v.mean()) if len(v) else None,
            "median": float(np.median(v)) if len(v) else None,
            "pairs_other_seed": int(len(seeds)), "mean_other_seed": float(seeds.mean()) if len(seeds) else None}


def diversity(index: DatasetIndex) -> dict:
    """The diversity figures of the dataset at ``index`` (see the module docstring)."""
    images = list(index.images)
    randomised = [i for i in images if i.randomisation]
    out: dict = {"images": len(images), "randomised_images": len(randomised),
                 "distinct_scenes": len({i.randomisation["scene_seed"] for i in randomised}),
                 "distinct_districts": len({i.randomisation["district_seed"] for i in randomised
                                            if i.randomisation.get("district_seed") is not None}),
                 "distinct_view_layers": len({i.randomisation["view_layer_sha256"] for i in randomised}),
                 "class_map_disagreement": class_map_disagreement(index)}
    if not randomised:
        out["note"] = "no image of this dataset was randomised: appearance, sun and camera figures need the records' draws"
        return out
    out["people"], out["devices"] = _people(randomised)
    lights = [i.randomisation["light"] for i in randomised if i.randomisation.get("light")]
    elevations = [light["sun_elevation_deg"] for light in lights]
    azimuths = [COMPASS[int(((light["sun_azimuth_deg"] + 22.5) % 360) // 45)] for light in lights
                if light["sun_elevation_deg"] > 0]
    out["sun"] = {"images": len(lights), "elevation_deg": _histogram(elevations, ELEVATION_EDGES),
                  "azimuth": {c: azimuths.count(c) for c in COMPASS},
                  "exposure_ev": _histogram([light["exposure_ev"] for light in lights], np.linspace(-4, 4, 17))}
    heights = [i.randomisation["view"]["camera"]["height_m"] for i in randomised
               if (i.randomisation["view"].get("camera") or {}).get("height_m") is not None]
    out["camera_height_m"] = _histogram(heights, HEIGHT_EDGES)
    return out
