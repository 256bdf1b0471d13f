"""Tables of per-shape and per-face values that a scene's BSDFs read by the registry id of the shape hit: what
lets every material of one kind share one BSDF, whatever its constants.

Why. In the JIT variants Dr.Jit records every BSDF of a scene into the path tracer's kernel and records it
again for every render (tracing), and a value that differs between materials makes their code differ. A
randomised district scene held 513 BSDFs (a wardrobe of garments, skin tones, hair, device finishes, the twin's
materials) over 4,223 shapes: about a second of tracing per render before any ray is traced, and a per-shape
``mesh_attribute`` inside each weathered BSDF made a snowy scene's kernel 358,602 operations long (25 s of LLVM
compilation). Here the constants of a material (base colour, roughness, metallic, clear coat, opacity, the tint of
a shared texture image, their wet versions) are rows of tables, one row per shape, and the materials of one kind
(the same textures, clear coat or not, the same weathering) are one BSDF. The values are the float32 numbers the
constants would have been, so images are the same, bit for bit (tested).

Two textures, registered for the JIT variants (``si.shape`` is a registry id there; scalar variants keep one BSDF
per material with its constants, :attr:`ShapeTables.enabled`):

- ``shape_value``: ``table[id]``, one value (1 or 3 channels) per shape;
- ``face_weight``: ``weights[first[id] + prim_index]``, one value per face of the shape (the weathering weights
  ``face_wet`` and ``face_snow``); on scalar variants Mitsuba's ``mesh_attribute`` reads the same numbers.

The tables are filled once the scene is loaded (:meth:`ShapeTables.fill`), when the shapes' registry ids are
known; rows of shapes that never ask are zeros.
"""

from __future__ import annotations

import numpy as np

from synthua_usd.backends.mitsuba import python_textures


def enabled(mi) -> bool:
    """Whether ``mi``'s active variant reads materials and face weights from tables (JIT variants) or holds them
    in each BSDF and mesh (scalar)."""
    return not mi.variant().startswith("scalar")


def register(mi) -> None:
    """Register ``shape_value`` and ``face_weight`` with the active variant of ``mi`` (once; JIT variants)."""
    if not enabled(mi):
        return
    import drjit as dr

    def shape_value(base: type) -> type:
        class ShapeValue(base):
            """``table[id]`` of the shape hit; ``channels`` 1 or 3."""

            def __init__(self, props) -> None:
                base.__init__(self, props)
                self.name = props["name"]
                self.channels = int(props["channels"])
                self.table = mi.Float(0.0)

            def set_table(self, rows: np.ndarray) -> None:
                # opaque: a table's values are never constants of the kernel (a new kernel per scene)
                self.table = mi.Float(np.ascontiguousarray(rows, np.float32).ravel())
                dr.make_opaque(self.table)

            def eval(self, si, active=True):
                row = dr.reinterpret_array(mi.UInt32, si.shape) * self.channels
                if self.channels == 1:
                    return mi.Color3f(dr.gather(mi.Float, self.table, row, active))
                return mi.Color3f(*(dr.gather(mi.Float, self.table, row + k, active) for k in range(3)))

            def eval_1(self, si, active=True):
                if self.channels == 1:
                    return dr.gather(mi.Float, self.table, dr.reinterpret_array(mi.UInt32, si.shape), active)
                return mi.luminance(self.eval(si, active))

            def mean(self):
                return float(dr.mean(self.table))

            def to_string(self) -> str:
                return f"ShapeValue[{self.name}]"

        return ShapeValue

    def face_weight(base: type) -> type:
        class FaceWeight(base):
            """``weights[first[id] + prim_index]`` of the shape and face hit."""

            def __init__(self, props) -> None:
                base.__init__(self, props)
                self.name = props["name"]
                self.first = mi.UInt32(0)
                self.weights = mi.Float(0.0)

            def set_table(self, first: np.ndarray, weights: np.ndarray) -> None:
                self.first = mi.UInt32(np.ascontiguousarray(first, np.uint32))
                self.weights = mi.Float(np.ascontiguousarray(weights, np.float32))
                dr.make_opaque(self.first, self.weights)

            def eval_1(self, si, active=True):
                start = dr.gather(mi.UInt32, self.first, dr.reinterpret_array(mi.UInt32, si.shape), active)
                return dr.gather(mi.Float, self.weights, start + si.prim_index, active)

            def eval(self, si, active=True):
                return mi.Color3f(self.eval_1(si, active))

            def mean(self):
                return float(dr.mean(self.weights))

            def to_string(self) -> str:
                return f"FaceWeight[{self.name}]"

        return FaceWeight

    python_textures.register(mi, "shape_value", shape_value)
    python_textures.register(mi, "face_weight", face_weight)


class ShapeTables:
    """The tables of one translation: a column per material value (:meth:`value`) and per face weight
    (:meth:`weight`), a row per mesh (:meth:`put`, :meth:`put_weights`), filled into the textures once the scene
    is loaded (:meth:`fill`). On scalar variants (``enabled`` False) it holds nothing: BSDFs carry constants."""

    def __init__(self, mi) -> None:
        self.mi = mi
        self.enabled = enabled(mi)
        self._values: dict[str, object] = {}
        self._weights: dict[str, object] = {}
        self._rows: dict[int, dict[str, object]] = {}
        self._face_rows: dict[int, dict[str, np.ndarray]] = {}
        register(mi)

    def value(self, name: str, channels: int):
        """The ``shape_value`` texture of the column ``name`` (shared by every BSDF that reads it)."""
        if name not in self._values:
            self._values[name] = self.mi.load_dict({"type": "shape_value", "name": name, "channels": channels})
        return self._values[name]

    def weight(self, name: str):
        """The texture (or texture dict) that gives a BSDF the face's ``name`` weight."""
        if not self.enabled:
            return {"type": "mesh_attribute", "name": name}
        if name not in self._weights:
            self._weights[name] = self.mi.load_dict({"type": "face_weight", "name": name})
        return self._weights[name]

    def put(self, mesh: int, values: dict[str, object]) -> None:
        """Mesh ``mesh``'s row of the value columns: name -> a number or an RGB triple."""
        if values:
            self._rows.setdefault(mesh, {}).update(values)

    def put_weights(self, mesh: int, weights: dict[str, np.ndarray]) -> None:
        """Mesh ``mesh``'s (m,) float32 per-face weights by name."""
        if weights:
            self._face_rows[mesh] = weights

    def fill(self, scene, shape_ids: tuple[str, ...]) -> None:
        """Fill every texture's table from the loaded ``scene``, whose shapes ``shape_ids`` are the meshes in
        order (mesh ``k`` is the shape of id ``shape_ids[k]``)."""
        if not self.enabled or not (self._values or self._weights):
            return
        import drjit as dr

        registry = np.asarray(dr.reinterpret_array(self.mi.UInt32, scene.shapes_dr()), np.int64)
        by_key = {shape.id(): int(r) for shape, r in zip(scene.shapes(), registry)}
        rows = np.array([by_key[key] for key in shape_ids], np.int64)
        size = int(registry.max()) + 1 if len(registry) else 1
        for name, texture in self._values.items():
            table = np.zeros((size, texture.channels), np.float32)
            for mesh, values in self._rows.items():
                if name in values:
                    table[rows[mesh]] = values[name]
            texture.set_table(table)
        for name, texture in self._weights.items():
            first = np.zeros(size, np.uint32)
            chunks, at = [np.zeros(1, np.float32)], 1  # entry 0: the zero of shapes without this weight
            for mesh in sorted(self._face_rows):
                values = self._face_rows[mesh].get(name)
                if values is not None:
                    first[rows[mesh]] = at
                    chunks.append(np.asarray(values, np.float32))
                    at += len(values)
            texture.set_table(first, np.concatenate(chunks))
