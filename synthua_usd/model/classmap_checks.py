"""Rules on class maps that a JSON Schema cannot express. Each returns findings, never raises."""

from __future__ import annotations

import itertools
import warnings

import numpy as np

from synthua_usd.core.findings import Finding, Severity
from synthua_usd.core.schemas import json_pointer, schema_errors

#: Smallest CIEDE2000 distance allowed between two class colours. 10 keeps Cityscapes' own car/motorcycle
#: pair (11.5) and is far above the ~2.3 "just noticeable difference".
MIN_CIEDE2000 = 10.0


def _entry(index: int, cls: dict) -> str:
    return f"classes[{index}] '{cls.get('name', '?')}'"


def check_unique_ids(classes: list[dict]) -> list[Finding]:
    seen: dict[int, int] = {}
    out = []
    for i, c in enumerate(classes):
        if c["id"] in seen:
            j = seen[c["id"]]
            out.append(Finding("unique-ids", _entry(i, c),
                               f"id {c['id']} is already used by {_entry(j, classes[j])}; give every class its own id"))
        seen.setdefault(c["id"], i)
    return out


def check_unique_names(classes: list[dict]) -> list[Finding]:
    """Names and aliases resolve case-insensitively, so they must be unique case-insensitively."""
    owner: dict[str, int] = {}
    out = []
    for i, c in enumerate(classes):
        for kind, word in [("name", c["name"])] + [("alias", a) for a in c["aliases"]]:
            key = word.casefold()
            if key in owner:
                j = owner[key]
                other = "its own name" if j == i else _entry(j, classes[j])
                out.append(Finding("unique-names", _entry(i, c),
                                   f"{kind} '{word}' is the same (ignoring case) as a name or alias of {other}; "
                                   f"every name and alias must resolve to one class"))
            else:
                owner[key] = i
    return out


def check_unique_colors(classes: list[dict]) -> list[Finding]:
    seen: dict[tuple, int] = {}
    out = []
    for i, c in enumerate(classes):
        rgb = tuple(c["color"])
        if rgb in seen:
            j = seen[rgb]
            out.append(Finding("unique-colors", _entry(i, c),
                               f"colour {list(rgb)} is already used by {_entry(j, classes[j])}; "
                               f"semantic PNGs could not be read back"))
        seen.setdefault(rgb, i)
    return out


def check_void_class(classes: list[dict]) -> list[Finding]:
    zero = [(i, c) for i, c in enumerate(classes) if c["id"] == 0]
    if not zero:
        return [Finding("void-class", "classes", "no class with id 0; id 0 is reserved for unlabelled pixels "
                                                 "(add {\"id\": 0, \"name\": \"unlabelled\", \"color\": [0, 0, 0], ...})")]
    out = []
    for i, c in zero:
        if c["name"] != "unlabelled":
            out.append(Finding("void-class", _entry(i, c), f"id 0 is named '{c['name']}'; id 0 is reserved for "
                                                           f"'unlabelled'"))
        if list(c["color"]) != [0, 0, 0]:
            out.append(Finding("void-class", _entry(i, c), f"id 0 has colour {c['color']}; unlabelled must be "
                                                           f"black [0, 0, 0]"))
        if c["isthing"]:
            out.append(Finding("void-class", _entry(i, c), "id 0 has isthing true; unlabelled has no instances"))
    return out


def ciede2000_matrix(colors: np.ndarray) -> np.ndarray:
    """(n, n) float64 CIEDE2000 distances between (n, 3) sRGB colours given as 0-255 integers."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # colour-science warns that matplotlib is absent; we plot nothing.
        import colour
    rgb = np.asarray(colors, np.float64) / 255.0
    lab = colour.XYZ_to_Lab(colour.sRGB_to_XYZ(rgb))
    n = len(lab)
    a = np.repeat(lab[:, None, :], n, axis=1)
    b = np.repeat(lab[None, :, :], n, axis=0)
    return np.asarray(colour.delta_E(a, b, method="CIE 2000"))


def check_color_distance(classes: list[dict], minimum: float = MIN_CIEDE2000) -> list[Finding]:
    if len(classes) < 2:
        return []
    dist = ciede2000_matrix(np.array([c["color"] for c in classes]))
    out = []
    for i, j in itertools.combinations(range(len(classes)), 2):
        if tuple(classes[i]["color"]) != tuple(classes[j]["color"]) and dist[i, j] < minimum:
            out.append(Finding("color-distance", _entry(j, classes[j]),
                               f"colour {classes[j]['color']} is {dist[i, j]:.1f} CIEDE2000 from {_entry(i, classes[i])} "
                               f"colour {classes[i]['color']}; expected at least {minimum:g} so they can be told apart",
                               Severity.WARNING))
    return out


#: The rules whose findings are errors (a class map that breaks one is refused wherever it is loaded) ...
REFUSING_RULES = (check_unique_ids, check_unique_names, check_unique_colors, check_void_class)
#: ... and every rule, the colour distance's warnings too (``synthua validate classes``): CIEDE2000 needs
#: colour-science, whose import and pairwise distances took ~2.7 s of every process that loaded a class map.
RULES = (*REFUSING_RULES, check_color_distance)


def check_classmap_rules(document: dict, rules=RULES) -> list[Finding]:
    """Findings of the non-schema ``rules`` on a document that already passed the schema."""
    classes = document["classes"]
    return [f for rule in rules for f in rule(classes)]


def check_classmap(document: object) -> list[Finding]:
    """Schema first (each violation a finding), then, when the schema holds, every rule."""
    errors = schema_errors(document, "classmap")
    if errors:
        return [Finding("schema", json_pointer(e), e.message) for e in errors]
    return check_classmap_rules(document)  # type: ignore[arg-type]
