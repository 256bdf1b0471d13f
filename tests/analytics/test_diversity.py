"""Diversity figures of a randomised dataset, each against a count made independently from the records and
the label maps."""

from __future__ import annotations

import json
from itertools import combinations

import numpy as np
import pytest

from synthua_usd.analytics.dataset_index import load_index
from synthua_usd.analytics.diversity import colour_name, diversity
from synthua_usd.assets.bodies import load_bank
from synthua_usd.core.images import read_image


@pytest.mark.parametrize("rgb, name", [((0.0, 0.0, 0.0), "black"), ((1.0, 1.0, 1.0), "white"),
                                       ((0.2, 0.2, 0.2), "grey"), ((0.8, 0.02, 0.02), "red"),
                                       ((0.02, 0.05, 0.6), "blue"), ((0.1, 0.5, 0.1), "green"),
                                       ((0.8, 0.6, 0.02), "yellow")])
def test_colour_names(rgb, name):
    assert colour_name(rgb) == name


def test_diversity_of_a_randomised_dataset(generated_random):
    figures = diversity(load_index(generated_random))
    records = [json.loads(p.read_text()) for p in sorted((generated_random / "records").glob("*.json"))]
    assert figures["randomised_images"] == len(records)
    assert figures["distinct_scenes"] == len({r["seed"] for r in records})
    assert figures["distinct_view_layers"] == len(records)
    bank = load_bank()
    shown, ages = 0, []
    for r in records:
        paths = {i["prim_path"] for i in r["instances"] if i["area"] > 0}
        for k, member in enumerate(r["randomisation"]["scene"]["cast"]):
            if f"/World/Randomisation/Crowd/Agent_{k:04d}/Person" in paths:
                shown += 1
                ages.append(bank.years[member["body"]])
    people = figures["people"]
    assert people["count"] == shown > 0
    assert sum(people["age_years"]["counts"]) == shown and sum(people["monk_skin_tone"].values()) == shown
    assert people["age_years"]["counts"] == np.histogram(ages, bins=people["age_years"]["edges"])[0].tolist()
    assert sum(people["upper_garment_colour"].values()) == shown
    assert figures["sun"]["images"] == len(records)
    assert sum(figures["camera_height_m"]["counts"]) == len(records)
    # the class maps of images sharing camera and time code, compared here pixel by pixel
    groups = {}
    for r in records:
        groups.setdefault((r["camera"]["prim_path"], r["time_code"]), []).append(r)
    values = []
    for group in groups.values():
        for a, b in combinations(sorted(group, key=lambda r: r["id"]), 2):
            ca = read_image(generated_random / a["files"]["class"])[0]
            cb = read_image(generated_random / b["files"]["class"])[0]
            values.append(np.mean(ca != cb))
    disagreement = figures["class_map_disagreement"]
    assert disagreement["pairs"] == len(values) > 0
    assert disagreement["mean"] == pytest.approx(float(np.mean(values)))


def test_a_dataset_without_randomisation_says_so(generated):
    figures = diversity(load_index(generated))
    assert figures["randomised_images"] == 0 and "people" not in figures and "no image" in figures["note"]
    assert figures["class_map_disagreement"]["pairs"] >= 1  # the same camera and time code at other seeds
