"""Hair made from the body mesh: a closed shell over the scalp of a posed bank body (no assets downloaded).

The scalp is the part of the head (the triangles whose dominant bone is ``head``) above a hairline that runs
around the head in its rest frame: a little above the eyes at the front, above the ears at the sides, down to
the nape at the back (lower for long hair). Its vertices, posed, are pushed outward along the body's vertex
normals by the style's thickness (thinner towards the hairline, fuller at the back for long hair); that outer
surface, an inner one just off the scalp (1 mm out, so no hair vertex lies in the head) and a wall along the
hairline close the shell, wound outward. It lives in the frame of the segment that holds the head
(``Torso``), so it moves with the head as the body's own triangles do.
"""

from __future__ import annotations

import numpy as np

from synthua_usd.assets.bodies import BONES, Bank
from synthua_usd.model import meshes as geo

#: Hair styles: none (bald), short, medium, long.
HAIR_STYLES = ("none", "short", "medium", "long")
#: Per style: thickness at the crown (m), how far the hairline drops below the ears at the back (m).
STYLE_SHAPES = {"short": (0.010, 0.01), "medium": (0.025, 0.03), "long": (0.035, 0.06)}
#: The inner surface's distance off the scalp, metres.
INNER_OFFSET_M = 0.001
#: At the hairline the thickness is this share of the crown's, growing to all of it over :data:`TAPER_M`.
HAIRLINE_SHARE = 0.3
TAPER_M = 0.03

# COCO keypoints (bank.keypoints' order): eyes and ears
_EYES, _EARS = (1, 2), (3, 4)


def _hairline_drop(bank: Bank, body: int, style: str) -> tuple[np.ndarray, np.ndarray]:
    """(V,) height of each rest vertex above the hairline of ``style`` (negative below), and (V,) the cosine
    of its azimuth about the head's vertical axis from the face's direction (+X)."""
    rest = bank.points[body]
    keys = bank.keypoints[body]
    eye_z = float(keys[list(_EYES), 2].mean())
    ears = keys[list(_EARS)]
    ear_z = float(ears[:, 2].mean())
    head = np.unique(bank.triangles[bank.face_bone == BONES.index("head")])
    top = float(rest[head, 2].max())
    centre = np.array([float(ears[:, 0].mean()), float(ears[:, 1].mean())])
    d = rest[:, :2] - centre
    cos = d[:, 0] / np.maximum(np.linalg.norm(d, axis=1), 1e-9)
    front = eye_z + 0.45 * (top - eye_z)
    side = ear_z + 0.035
    back = ear_z - STYLE_SHAPES[style][1]
    line = np.where(cos >= 0, side + cos * (front - side), side - cos * (back - side))
    return rest[:, 2] - line, cos


def hair_mesh(bank: Bank, body: int, posed: np.ndarray, style: str) -> tuple[np.ndarray, np.ndarray] | None:
    """(points (n, 3), triangles (m, 3)) of ``body``'s hair in ``style`` over its ``posed`` vertices (V, 3),
    in their frame; None for ``"none"``."""
    if style == "none":
        return None
    if style not in STYLE_SHAPES:
        raise ValueError(f"hair style {style!r}; expected one of {', '.join(HAIR_STYLES)}")
    above, cos = _hairline_drop(bank, body, style)
    head_faces = bank.triangles[bank.face_bone == BONES.index("head")]
    scalp = head_faces[(above[head_faces] > 0).all(axis=1)]
    scalp = _largest_component(scalp)
    used, local = np.unique(scalp, return_inverse=True)
    local = local.reshape(-1, 3)
    normals = geo.vertex_normals(posed, bank.triangles)[used]
    thickness, _ = STYLE_SHAPES[style]
    share = HAIRLINE_SHARE + (1 - HAIRLINE_SHARE) * np.clip(above[used] / TAPER_M, 0.0, 1.0)
    if style == "long":  # fuller at the back
        share = share * (1.0 + 0.4 * np.clip(-cos[used], 0.0, 1.0))
    outer = posed[used] + normals * (thickness * share)[:, None]
    inner = posed[used] + normals * INNER_OFFSET_M
    n = len(used)
    edges = np.concatenate([local[:, [0, 1]], local[:, [1, 2]], local[:, [2, 0]]])
    key = np.sort(edges, axis=1)
    _, index, counts = np.unique(key, axis=0, return_index=True, return_counts=True)
    rim = edges[index[counts == 1]]  # boundary edges a -> b as the scalp's faces run them
    a, b = rim[:, 0], rim[:, 1]
    walls = np.concatenate([np.stack([b, a, a + n], axis=1), np.stack([b, a + n, b + n], axis=1)])
    triangles = np.concatenate([local, local[:, ::-1] + n, walls])
    return np.concatenate([outer, inner]), triangles.astype(np.int64)


def _largest_component(faces: np.ndarray) -> np.ndarray:
    """The faces of the largest edge-connected component of ``faces`` (F, 3)."""
    parent = np.arange(len(faces))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    owner: dict[tuple[int, int], int] = {}
    for f, tri in enumerate(faces.tolist()):
        for u, v in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])):
            e = (min(u, v), max(u, v))
            if e in owner:
                parent[find(f)] = find(owner[e])
            else:
                owner[e] = f
    roots = np.array([find(f) for f in range(len(faces))])
    values, counts = np.unique(roots, return_counts=True)
    return faces[roots == values[counts.argmax()]]
