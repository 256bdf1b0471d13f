"""The random streams of scene randomisation: one ``numpy.random.Generator`` per scope, seeded by the config's
randomisation seed, the image's seed and the scope's keys, so that a draw depends on nothing else (not on
which worker renders the image, nor on what it rendered before) and one scope's draws never shift another's.

- ``district``: (seed) which district seed a scene's twin is;
- ``scene``: (seed) the crowd's cast and looks, the devices, the twin's material variants;
- ``view``: (seed, camera, time code) the camera's jitter, then where each person stands;
- ``light``: (seed, camera, time code, condition) the sun, sky and exposure;
- ``effects``: (seed, camera, time code, condition) the camera effects applied after rendering (a composite's:
  (its number, background path));
- ``framing``: (seed, camera, time code) the photographer's view of an aid user;
- ``composite``: (its number, background path) a composite's camera model and pastes (``synthua composite``);
- ``setting``: (seed) whether the scene is in the district or a procedural setting, and which;
- ``distractors``: (seed) the objects scattered in the scene, their looks and places.
"""

from __future__ import annotations

import zlib

import numpy as np

#: Each scope's number, never reused.
_SCOPES = {"district": 1, "scene": 2, "view": 3, "light": 4, "effects": 5, "cutout_group": 6, "cutout_view": 7,
           "framing": 8, "composite": 9, "setting": 10, "distractors": 11}


def _key(value) -> int:
    """A 32-bit key of a string (CRC-32 of its UTF-8) or a time code (thousandths)."""
    if isinstance(value, str):
        return zlib.crc32(value.encode("utf-8", "surrogatepass"))
    return int(round(float(value) * 1000)) & 0xFFFFFFFF


def stream(config_seed: int, seed: int, scope: str, *keys) -> np.random.Generator:
    """The generator of ``scope`` for the image seed ``seed`` under the randomisation seed ``config_seed``;
    ``keys`` (strings or time codes) narrow it (the view's camera path and time code, the condition's name)."""
    return np.random.default_rng([int(config_seed), int(seed), _SCOPES[scope], *(_key(k) for k in keys)])
