"""``face_weight``: a Mitsuba texture whose value is a per-face weight of the shape hit, read from one table that
holds the weights of every mesh of the scene (the weathering weights ``face_wet`` and ``face_snow``).

Why not Mitsuba's ``mesh_attribute``: it asks the shape hit for its attribute, a virtual call over every shape
of the scene, and inside a BSDF that call is recorded anew in each BSDF's code. Dr.Jit then cannot merge the
BSDFs that are otherwise alike, and a snowy district's path-tracing kernel grew to 358,602 operations (25 s of
LLVM compilation for every new scene, against 8,508 operations dry). Here the weight is two gathers: the shape's
first face in the table, by the shape's registry id (``si.shape`` as an integer), then the face's weight
(``si.prim_index``). Every weathered BSDF holds the same texture object, so their code is the same and is merged;
the weights are the same float32 numbers ``mesh_attribute`` would read, so images are too.

The JIT variants only (``si.shape`` is a registry id there); scalar variants keep ``mesh_attribute``
(:func:`weight_node`). The table is filled after the scene is loaded (:func:`fill`), when the shapes' registry ids
are known; it is written in Python, which the JIT variants trace into their kernels like Mitsuba's own plugins.
"""

from __future__ import annotations

import numpy as np

from synthua_usd.backends.mitsuba import python_textures


def uses_table(mi) -> bool:
    """Whether ``mi``'s active variant reads face weights from a table (JIT variants) or mesh attributes (scalar)."""
    return not mi.variant().startswith("scalar")


def register(mi) -> None:
    """Register ``face_weight`` with the active variant of ``mi`` (once; JIT variants only)."""
    if not uses_table(mi):
        return
    import drjit as dr

    def make(base: type) -> type:
        class FaceWeight(base):
            """The weight of the face hit: ``weights[first[shape id] + prim_index]``; ``name`` says which."""

            def __init__(self, props) -> None:
                base.__init__(self, props)
                self.name = props["name"]
                self.first = mi.UInt32(0)
                self.weights = mi.Float(0.0)

            def set_table(self, first: np.ndarray, weights: np.ndarray) -> None:
                # opaque: the table's values must never become constants of the kernel (a new kernel per scene)
                self.first = mi.UInt32(np.ascontiguousarray(first, np.uint32))
                self.weights = mi.Float(np.ascontiguousarray(weights, np.float32))
                dr.make_opaque(self.first, self.weights)

            def eval_1(self, si, active=True):
                shape = dr.reinterpret_array(mi.UInt32, si.shape)
                start = dr.gather(mi.UInt32, self.first, shape, active)
                return dr.gather(mi.Float, self.weights, start + si.prim_index, active)

            def eval(self, si, active=True):
                return mi.Color3f(self.eval_1(si, active))

            def mean(self):
                return float(dr.mean(self.weights))

            def to_string(self) -> str:
                return f"FaceWeight[{self.name}]"

        return FaceWeight

    python_textures.register(mi, "face_weight", make)


class WeightNodes:
    """The weight textures of one translation: one ``face_weight`` object per weight name (JIT variants), shared
    by every BSDF weathered by it; ``mesh_attribute`` dicts on scalar variants."""

    def __init__(self, mi) -> None:
        self.mi = mi
        self.table = uses_table(mi)
        self.nodes: dict[str, object] = {}
        register(mi)

    def node(self, name: str):
        """The texture (or texture dict) that gives the BSDF the face's ``name`` weight."""
        if not self.table:
            return {"type": "mesh_attribute", "name": name}
        if name not in self.nodes:
            self.nodes[name] = self.mi.load_dict({"type": "face_weight", "name": name})
        return self.nodes[name]

    def fill(self, scene, shape_ids: tuple[str, ...], weights: list[dict[str, np.ndarray]]) -> None:
        """Fill every weight texture's table from the loaded ``scene``: ``shape_ids`` the Mitsuba ids of the
        meshes, ``weights`` their (m,) float32 per-face weights by name (:func:`weather_scene.mesh_face_weights`)
        in the same order. A shape without a weight points at a zero (its BSDF never asks)."""
        if not self.table or not self.nodes:
            return
        import drjit as dr

        registry = np.asarray(dr.reinterpret_array(self.mi.UInt32, scene.shapes_dr()), np.int64)
        by_key = {shape.id(): int(r) for shape, r in zip(scene.shapes(), registry)}
        size = int(registry.max()) + 1 if len(registry) else 1
        for name, texture in self.nodes.items():
            first = np.zeros(size, np.uint32)
            chunks, at = [np.zeros(1, np.float32)], 1  # entry 0: the zero of shapes without this weight
            for key, faces in zip(shape_ids, weights):
                values = faces.get(name)
                if values is not None:
                    first[by_key[key]] = at
                    chunks.append(np.asarray(values, np.float32))
                    at += len(values)
            texture.set_table(first, np.concatenate(chunks))
