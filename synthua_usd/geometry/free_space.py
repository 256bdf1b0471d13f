"""Whether a camera's eye stands in free space outdoors: rays cast from the eye into its surroundings.

An automatic camera must not stand inside a building, a tree or a wall (its image would be a noisy interior
that still counts as labelled pixels). :func:`check_eyes` casts from each eye (world metres, Z up):

* straight up: outdoors nothing is above the eye (``open_sky``);
* :data:`UPPER_DIRECTIONS`, spread over the sky above 10 degrees of elevation, each counting every surface
  it crosses: from inside a closed shell a ray crosses it an odd number of times, from outside an even
  number (zero included). ``inside_share`` is the share of odd counts; a majority means the eye is inside
  geometry, even where a shell has gaps. Inside two nested shells (a part inside a building) the counts are
  even again, but no ray reaches the sky: ``sky_share``, the share that meets nothing, is 0. The generated
  ground is never crossed from above it: only rays above the horizon count;
* :data:`SPHERE_DIRECTIONS` all round: the distance to the nearest surface (``clearance_m``, sampled);
* along the view direction: the free line of sight (``free_view_m``, inf when nothing is hit).

An eye is free (:attr:`EyeCheck.ok`) with open sky (when asked for), a minority inside, at least
:data:`MIN_CLEARANCE_M` to every surface and at least :data:`MIN_FREE_VIEW_M` of free view.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Least free line of sight towards what a camera looks at (metres).
MIN_FREE_VIEW_M = 5.0
#: Least distance from the eye to any surface (metres): a lens is not pressed against a wall.
MIN_CLEARANCE_M = 0.3
#: A majority of odd crossing counts means inside a closed shell.
MAX_INSIDE_SHARE = 0.5


def _fibonacci(n: int) -> np.ndarray:
    """(n, 3) float64 unit vectors spread evenly over the sphere (golden-angle spiral)."""
    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    r = np.sqrt(1.0 - z * z)
    phi = k * np.pi * (3.0 - np.sqrt(5.0))
    return np.column_stack([r * np.cos(phi), r * np.sin(phi), z])


#: (70, 3) directions all round the eye: 64 spread evenly and the six axes (walls and floors are often
#: axis-aligned).
SPHERE_DIRECTIONS = np.concatenate([_fibonacci(64), np.eye(3), -np.eye(3)])
#: (m, 3) directions of a 128-ray sphere more than 10 degrees above the horizon (terrain rising beside a street
#: does not cross them).
UPPER_DIRECTIONS = _fibonacci(128)[_fibonacci(128)[:, 2] > np.sin(np.radians(10.0))]


@dataclass(frozen=True)
class EyeCheck:
    """What the rays from one eye found (see the module docstring); distances in metres."""

    open_sky: bool
    inside_share: float
    sky_share: float
    clearance_m: float
    free_view_m: float
    need_sky: bool = True

    @property
    def reason(self) -> str | None:
        """Why the eye is not free, in words, or None when it is."""
        if self.inside_share > MAX_INSIDE_SHARE:
            return (f"it stands inside a closed surface ({self.inside_share:.0%} of the rays to the sky cross "
                    f"geometry an odd number of times)")
        if self.sky_share == 0:
            return "it stands inside geometry (no ray above the horizon reaches the sky)"
        if self.need_sky and not self.open_sky:
            return "it stands under a roof, a tree or a bridge (the ray straight up meets a surface)"
        if self.clearance_m < MIN_CLEARANCE_M:
            return f"a surface is {self.clearance_m:.2f} m from it; expected at least {MIN_CLEARANCE_M:g} m"
        if self.free_view_m < MIN_FREE_VIEW_M:
            return (f"its view is blocked {self.free_view_m:.1f} m ahead; expected a free view of at least "
                    f"{MIN_FREE_VIEW_M:g} m towards what it looks at")
        return None

    @property
    def ok(self) -> bool:
        return self.reason is None

    def rank(self) -> tuple:
        """Sorts eyes that are not free from the least to the most enclosed: inside, then less sky, then less
        free view."""
        return (self.inside_share > MAX_INSIDE_SHARE, -self.sky_share, not self.open_sky, -min(self.free_view_m, 1e6))

    def as_report(self) -> dict:
        return {"free_space": self.ok, **({"reason": self.reason} if not self.ok else {}),
                "open_sky": self.open_sky, "inside_share": self.inside_share, "sky_share": self.sky_share,
                "clearance_m": self.clearance_m,
                "free_view_m": min(self.free_view_m, 1e6)}


def _crossings(mesh, origins: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """(n,) number of surfaces each ray crosses."""
    counts = np.zeros(len(origins), np.int64)
    if len(origins):
        _, ray_idx, _ = mesh.ray.intersects_location(origins, directions, multiple_hits=True)
        np.add.at(counts, ray_idx, 1)
    return counts


def first_hits(mesh, origins: np.ndarray, directions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(n,) distance to the first surface along each ray (inf for none) and (n,) its face index (-1 for
    none); ``origins`` and ``directions`` (n, 3), directions unit length, world metres."""
    dist = np.full(len(origins), np.inf)
    face = np.full(len(origins), -1)
    if not len(origins):
        return dist, face
    locations, ray_idx, tri_idx = mesh.ray.intersects_location(origins, directions, multiple_hits=False)
    dist[ray_idx] = np.linalg.norm(locations - origins[ray_idx], axis=1)
    face[ray_idx] = tri_idx
    return dist, face


def check_eyes(mesh, eyes: np.ndarray, views: np.ndarray, need_sky: bool = True) -> list[EyeCheck]:
    """One :class:`EyeCheck` per eye of ``eyes`` (n, 3) looking along ``views`` (n, 3) (any length) in the
    trimesh ``mesh`` (world metres); ``need_sky``: whether an eye must have open sky above it."""
    eyes = np.asarray(eyes, float).reshape(-1, 3)
    views = np.asarray(views, float).reshape(-1, 3)
    views = views / np.linalg.norm(views, axis=1, keepdims=True)
    n, up, sphere = len(eyes), len(UPPER_DIRECTIONS), len(SPHERE_DIRECTIONS)
    crossings = _crossings(mesh, np.repeat(eyes, up, axis=0), np.tile(UPPER_DIRECTIONS, (n, 1)))
    inside = (crossings.reshape(n, up) % 2 == 1).mean(axis=1)
    sky_share = (crossings.reshape(n, up) == 0).mean(axis=1)
    near, _ = first_hits(mesh, np.repeat(eyes, sphere, axis=0), np.tile(SPHERE_DIRECTIONS, (n, 1)))
    clearance = near.reshape(n, sphere).min(axis=1)
    sky, _ = first_hits(mesh, eyes, np.tile([0.0, 0.0, 1.0], (n, 1)))
    free, _ = first_hits(mesh, eyes, views)
    return [EyeCheck(bool(np.isinf(sky[i])), float(inside[i]), float(sky_share[i]), float(clearance[i]),
                     float(free[i]), need_sky)
            for i in range(n)]
