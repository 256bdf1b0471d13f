"""Whether a generated file matches its committed copy in stages/, across machines.

The committed stages are compared with what the generator writes now. On the machine that wrote them the bytes are
the same; on another CPU some floating-point numbers differ in their last bits, because NumPy picks its SIMD and
BLAS kernels by the processor (AVX2 or AVX-512, fused multiply-adds or not: a dot product may round differently).
Measured: `synthua agents populate` of the district on an AVX-512 EPYC differs from the committed agents.usdc in
13,627 of its 2,327,005 numbers, by at most 7.3e-15. So a USD layer matches when it is the same bytes, or else
when its text (``Sdf.Layer.ExportToString``, binary crate files included) is the same apart from numbers that
agree within :data:`ABS_TOL` + :data:`REL_TOL` x |committed|: a stale layer (a moved prim, a new attribute, a
changed value) still fails. Every other file (texture images, JSON) must be the same bytes.
"""

from __future__ import annotations

import filecmp
import re
from pathlib import Path

import numpy as np

#: Allowed difference of a number, absolute (metres, for positions) and relative to the committed value.
ABS_TOL = 1e-9
REL_TOL = 1e-9
USD_SUFFIXES = (".usda", ".usdc", ".usd")
_NUMBER = re.compile(r"-?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|-?\binf\b|\bnan\b")


def _text(path: Path) -> str:
    from pxr import Sdf

    layer = Sdf.Layer.OpenAsAnonymous(str(path))
    assert layer is not None, f"{path}: USD cannot open it"
    return layer.ExportToString()


def mismatch(generated: Path, committed: Path) -> str | None:
    """None when ``generated`` matches ``committed``, else what differs first."""
    if filecmp.cmp(generated, committed, shallow=False):
        return None
    if generated.suffix not in USD_SUFFIXES:
        return f"{committed.name}: the bytes differ"
    ours, theirs = _text(generated), _text(committed)
    words_ours, words_theirs = _NUMBER.split(ours), _NUMBER.split(theirs)
    if words_ours != words_theirs:
        at = next(i for i, (a, b) in enumerate(zip(words_ours, words_theirs)) if a != b) \
            if any(a != b for a, b in zip(words_ours, words_theirs)) else min(len(words_ours), len(words_theirs))
        shown = (words_ours[at:at + 1] or ["<end>"])[0][:200], (words_theirs[at:at + 1] or ["<end>"])[0][:200]
        return f"{committed.name}: the layer's text differs: {shown[0]!r} where the committed one has {shown[1]!r}"
    a = np.array([float(x) for x in _NUMBER.findall(ours)])
    b = np.array([float(x) for x in _NUMBER.findall(theirs)])
    off = ~np.isclose(a, b, rtol=REL_TOL, atol=ABS_TOL, equal_nan=True)
    if off.any():
        i = int(np.argmax(off))
        return (f"{committed.name}: {int(off.sum())} numbers differ beyond the tolerance, the first "
                f"{a[i]!r} where the committed layer has {b[i]!r}")
    return None
