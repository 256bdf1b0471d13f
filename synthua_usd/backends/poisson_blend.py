"""Poisson blending (Pérez, Gangnet and Blake 2003, "seamless cloning") of one paste over a photo, in linear light.

Inside a domain Ω (the paste's pixels, widened a little) the result ``f`` has the gradients of the *source* ``s``
(the paste hard-composited over the photo) and, on Ω's edge, the photo's values ``t``: for every pixel p of Ω with
4-neighbours N(p),

    |N(p)| f_p - Σ_{q ∈ N(p) ∩ Ω} f_q = Σ_{q ∈ N(p)} (s_p - s_q) + Σ_{q ∈ N(p) \\ Ω} t_q.

Where ``regions`` is given, the source's gradient between p and q counts only where both lie in the same region
(the sum's term is 0 across a seam): with the paste's covered pixels one region and the photo's the other, the paste
imports its own gradients but not the jump at its silhouette, so it keeps its shading and texture while its overall
colour and brightness slide to meet the photo around it (Pérez et al.'s seamless cloning of an object without its
own background). Without ``regions`` the source's every gradient counts: a source that equals ``t`` on Ω's edge is
then returned as it is. The sparse system (one unknown per pixel of Ω) is factorised once by scipy's SuperLU
(:func:`scipy.sparse.linalg.splu`) and solved for the three channels.

Where Ω touches the border of the arrays, N(p) holds only the neighbours that exist: the border is open (no value
is imposed there; the gradient across it is free), as the frame's edge is where it cuts a paste, whose surroundings
lie beyond the photo. A caller that wants the photo's values on a border keeps Ω off it. An Ω with no neighbour
outside it (the whole array) has no value to meet: it is the source there.
"""

from __future__ import annotations

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import splu


def poisson_blend(target: np.ndarray, source: np.ndarray, domain: np.ndarray,
                  regions: np.ndarray | None = None) -> np.ndarray:
    """``target`` (h, w, 3) float with the Poisson solution on ``domain`` (h, w) bool (see the module docstring);
    ``source`` (h, w, 3) gives the gradients, within each of ``regions`` (h, w; bool or int labels) when given.
    Returns a new float64 array; outside ``domain`` it is ``target``."""
    h, w = domain.shape
    out = np.array(target, dtype=np.float64)
    flat = np.flatnonzero(domain.reshape(-1))
    if not flat.size:
        return out
    s = np.asarray(source, np.float64).reshape(-1, 3)
    region = None if regions is None else np.asarray(regions).reshape(-1)
    t = out.reshape(-1, 3)
    if flat.size == h * w:
        t[:] = s
        return out
    index = np.full(h * w, -1, np.int64)
    index[flat] = np.arange(flat.size)
    y, x = np.divmod(flat, w)
    degree = np.zeros(flat.size)
    rows, cols, values = [np.arange(flat.size)], [np.arange(flat.size)], [degree]
    rhs = np.zeros((flat.size, 3))
    for step, exists in ((-w, y > 0), (w, y < h - 1), (-1, x > 0), (1, x < w - 1)):  # the 4 neighbours
        at = np.flatnonzero(exists)             # the unknowns that have this neighbour (not beyond the border)
        neighbour = flat[at] + step
        degree[at] += 1.0
        guide = s[flat[at]] - s[neighbour]
        if region is not None:
            guide[region[flat[at]] != region[neighbour]] = 0.0     # no gradient across a seam
        rhs[at] += guide
        inner = index[neighbour]
        known = inner < 0
        rhs[at[known]] += t[neighbour[known]]
        rows.append(at[~known])
        cols.append(inner[~known])
        values.append(np.full(int((~known).sum()), -1.0))
    matrix = sparse.csc_matrix((np.concatenate(values), (np.concatenate(rows), np.concatenate(cols))),
                               shape=(flat.size, flat.size))
    # the matrix is symmetric: a minimum-degree order of A + A^T fills in least (measured 0.13 s against COLAMD's
    # 0.18 s for 43,500 unknowns)
    solution = splu(matrix, permc_spec="MMD_AT_PLUS_A").solve(rhs)
    t[flat] = solution
    return out
