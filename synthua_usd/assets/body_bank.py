"""The body bank: people's bodies generated from the parametric body model ``anny`` (NAVER LABS, Apache-2.0,
built on MakeHuman's CC0 assets), decimated once, stored in the package (``assets/data/bodies.npz``).

Why a bank and not the model at run time: loading anny costs ~200 s the first time on a machine (it builds
~0.8 GB of model data) and ~10 s per process after that, and its full mesh has 27,420 triangles. The bank is
built by ``python tools/build_body_bank.py`` (this module; it is the only code that imports torch and anny)
and read by :mod:`synthua_usd.assets.bodies` without either. All bodies share one topology: the quadric
decimation is done once, on an average adult, keeping a subset of the template's vertices (no vertex is
moved), so every body's decimated mesh is the same subset of its own full mesh, and skin weights, garment
regions and keypoint weights are per topology, not per body.

Phenotypes are sampled per body from stated distributions (docs/bodies.md):

- age in years: the age pyramid of Brazil's 2022 census (IBGE: 0-14 years 19.8 %, 15-64 years 69.3 %,
  65+ 10.9 %), uniform inside each band, 65+ capped at 90;
- sex: 1:1;
- height, weight, muscle and proportions given age and sex: anny's ``SimpleShapeDistribution``, whose
  conditional Beta distributions are calibrated to the WHO child growth standards and reference data for
  height-for-age (its documentation); we take its draws as they are;
- an older stratum for users of mobility aids (their device use rises steeply with age: about two thirds of
  US mobility-device users are 65 or older, Kaye, Kang & LaPlante 2000): ages uniform in 50-90.
"""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np

from synthua_usd.model.keypoint_classes import PERSON_KEYPOINTS

log = logging.getLogger(__name__)

BANK_PATH = Path(__file__).parent / "data" / "bodies.npz"
#: Triangles of the decimated topology (the full anny mesh has 27,420).
TARGET_TRIANGLES = 3000
#: Census age bands (years, lower inclusive, upper exclusive) and their shares: Brazil 2022 (IBGE).
AGE_BANDS = ((0.0, 15.0, 0.198), (15.0, 65.0, 0.693), (65.0, 90.0, 0.109))
#: The older stratum for mobility-aid users, years.
AID_AGE_RANGE = (50.0, 90.0)
GENERAL_BODIES = 48
AID_BODIES = 24

#: The reduced rig: name, anny bones it absorbs (prefix match), the anny bone whose head is its joint.
REDUCED_BONES = (
    ("torso", ("root", "pelvis.", "spine", "clavicle.", "shoulder01."), "root"),
    ("head", ("neck", "head", "eye."), "neck01"),
    ("upperleg.L", ("upperleg01.L", "upperleg02.L"), "upperleg01.L"),
    ("upperleg.R", ("upperleg01.R", "upperleg02.R"), "upperleg01.R"),
    ("lowerleg.L", ("lowerleg01.L", "lowerleg02.L"), "lowerleg01.L"),
    ("lowerleg.R", ("lowerleg01.R", "lowerleg02.R"), "lowerleg01.R"),
    ("foot.L", ("foot.L", "toe"), "foot.L"),
    ("foot.R", ("foot.R",), "foot.R"),
    ("upperarm.L", ("upperarm01.L", "upperarm02.L"), "upperarm01.L"),
    ("upperarm.R", ("upperarm01.R", "upperarm02.R"), "upperarm01.R"),
    ("lowerarm.L", ("lowerarm01.L", "lowerarm02.L"), "lowerarm01.L"),
    ("lowerarm.R", ("lowerarm01.R", "lowerarm02.R"), "lowerarm01.R"),
    ("hand.L", ("wrist.L", "finger", "metacarpal"), "wrist.L"),
    ("hand.R", ("wrist.R",), "wrist.R"),
)
#: COCO's 17 person keypoints, in COCO's order (anny's regressor names them so too).
COCO_KEYPOINTS = PERSON_KEYPOINTS


def _reduced_index(labels: list[str], parents: list[int]) -> np.ndarray:
    """(104,) index into :data:`REDUCED_BONES` of every anny bone (toes and fingers follow their side)."""
    out = np.full(len(labels), -1, np.int64)
    for k, label in enumerate(labels):
        for r, (name, prefixes, _) in enumerate(REDUCED_BONES):
            side = name[-2:] if name[-2:] in (".L", ".R") else None
            if any(label.startswith(p) for p in prefixes) and (side is None or label.endswith(side)):
                out[k] = r
                break
    for k in range(len(labels)):  # anything unmatched follows its parent
        if out[k] < 0:
            out[k] = out[parents[k]]
    return out


def sample_phenotypes(rng: np.random.Generator, distribution, torch, count: int, aid: bool) -> list[dict]:
    """``count`` phenotypes: years, sex and anny's phenotype parameters (0..1)."""
    out = []
    for _ in range(count):
        if aid:
            years = float(rng.uniform(*AID_AGE_RANGE))
        else:
            band = AGE_BANDS[int(rng.choice(len(AGE_BANDS), p=[b[2] for b in AGE_BANDS]))]
            years = float(rng.uniform(band[0], band[1]))
        female = bool(rng.random() < 0.5)
        torch.manual_seed(int(rng.integers(2 ** 31)))
        age = distribution.morphological_age_mapping.morphological_to_anny_age(torch.tensor([years], dtype=torch.float64))
        gender = torch.tensor([1.0 if female else 0.0], dtype=torch.float64)
        table = "girls" if female else "boys"
        params = {"age": float(age[0]), "gender": float(gender[0])}
        for key in ("height", "weight", "muscle", "proportions"):
            dist = getattr(distribution, f"{table}_conditional_{key}_distribution").get_torch_distribution(age)
            params[key] = float(dist.sample()[0])
        out.append({"years": years, "female": female, "params": params})
    return out


def build_bank(seed: int = 0, path: Path = BANK_PATH) -> dict:
    """Build the bank from anny and write it to ``path`` (npz); returns what was written."""
    import anny
    import pymeshlab
    import torch
    from anny.shape_distribution import SimpleShapeDistribution

    torch.set_grad_enabled(False)
    model = anny.Anny()
    faces = model.faces.numpy().astype(np.int64)
    labels = list(model.bone_labels)
    reduced = _reduced_index(labels, list(model.bone_parents))
    regressor = anny.KeypointsRegressor.coco(model, labels=list(COCO_KEYPOINTS))

    # One topology: decimate an average adult, keeping original vertices (no optimal placement).
    ref = model(phenotype_kwargs={"age": 2 / 3, "gender": 0.5})["rest_vertices"][0].numpy()
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(ref, faces))
    ms.meshing_decimation_quadric_edge_collapse(targetfacenum=TARGET_TRIANGLES, optimalplacement=False,
                                                preservenormal=True, preservetopology=True, qualitythr=0.5)
    small = ms.current_mesh()
    from scipy.spatial import cKDTree
    dist, keep = cKDTree(ref).query(small.vertex_matrix())
    if dist.max() > 1e-6:
        raise RuntimeError(f"decimation moved a vertex by {dist.max():g} m; expected a subset of the template")
    tris = small.face_matrix().astype(np.int32)

    # Skin weights on the reduced rig, 4 influences per vertex.
    idx = model.vertex_bone_indices.numpy()[keep]
    w = model.vertex_bone_weights.numpy()[keep]
    dense = np.zeros((len(keep), len(REDUCED_BONES)))
    np.add.at(dense, (np.repeat(np.arange(len(keep)), idx.shape[1]), reduced[idx].ravel()), w.ravel())
    top = np.argsort(-dense, axis=1)[:, :4]
    top_w = np.take_along_axis(dense, top, axis=1)
    top_w /= top_w.sum(axis=1, keepdims=True)
    # Keypoints follow the bones of the vertices they are regressed from.
    full_dense = np.zeros((len(ref), len(REDUCED_BONES)))
    fi, fw = model.vertex_bone_indices.numpy(), model.vertex_bone_weights.numpy()
    np.add.at(full_dense, (np.repeat(np.arange(len(ref)), fi.shape[1]), reduced[fi].ravel()), fw.ravel())
    keypoint_bones = regressor.regression_weights.numpy() @ full_dense  # (17, bones)

    distribution = SimpleShapeDistribution(model)
    rng = np.random.default_rng(seed)
    phenotypes = sample_phenotypes(rng, distribution, torch, GENERAL_BODIES, aid=False)
    phenotypes += sample_phenotypes(rng, distribution, torch, AID_BODIES, aid=True)
    joint_bones = [labels.index(j) for _, _, j in REDUCED_BONES]
    points, joints, keypoints, heights = [], [], [], []
    measure = anny.Anthropometry(model)
    masses = []
    for ph in phenotypes:
        out = model(phenotype_kwargs={k: torch.tensor([v], dtype=torch.float64) for k, v in ph["params"].items()},
                    return_bone_ends=False)
        rest = out["rest_vertices"]
        v = rest[0].numpy()
        ground = v[:, 2].min()
        shift = np.array([0.0, 0.0, -ground])
        points.append((v[keep] + shift).astype(np.float32))
        joints.append((out["rest_bone_poses"][0].numpy()[joint_bones, :3, 3] + shift).astype(np.float32))
        keypoints.append((regressor({"vertices": rest})[0].numpy() + shift).astype(np.float32))
        m = measure(rest)
        heights.append(float(m["height"][0]))
        masses.append(float(m["mass"][0]))
    bank = {
        "points": np.stack(points), "triangles": tris, "joints": np.stack(joints), "keypoints": np.stack(keypoints),
        "skin_bones": top.astype(np.int8), "skin_weights": top_w.astype(np.float32),
        "keypoint_bones": keypoint_bones.astype(np.float32), "years": np.array([p["years"] for p in phenotypes]),
        "female": np.array([p["female"] for p in phenotypes]), "aid_stratum": np.arange(len(phenotypes)) >= GENERAL_BODIES,
        "height_m": np.array(heights), "mass_kg": np.array(masses),
        "params": np.array([[p["params"][k] for k in ("age", "gender", "height", "weight", "muscle", "proportions")]
                            for p in phenotypes]),
        "seed": np.array(seed),
    }
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp.npz")
    np.savez_compressed(tmp, **bank)
    tmp.replace(path)
    log.info("body bank: %d bodies, %d vertices, %d triangles -> %s", len(points), len(keep), len(tris), path)
    return bank
