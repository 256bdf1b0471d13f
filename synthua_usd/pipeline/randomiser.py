"""Scene randomisation applied to a loaded stage: what a dataset worker, the planner and ``synthua randomise``
hold to give each image its own scene.

A :class:`Randomiser` inserts three layers into its stage's session layer, never into the user's files (the
view layer, sublayering the scene layer, sublayering the prototypes layer: see
:mod:`synthua_usd.usd.randomisation_layer`). :meth:`Randomiser.apply` draws an image's randomisation
(:mod:`synthua_usd.randomisation`) and moves it into those layers: a new scene (another seed) replaces the
scene and prototypes layers, every image replaces the view layer. Layers are replaced through
``Sdf.Layer.TransferContent`` (:class:`synthua_usd.usd.session_layers.RandomisationLayers`), so USD notifies only
what differs: a :class:`StageReader` of the stage then
re-places the crowd and a :class:`RenderSession` updates vertices, sensor and sky in place, while a new scene
is read and loaded afresh.

What a draw needs of the scenario itself (the twin's walkable surfaces and materials, the cameras, the
conditions) is read from a second composition of the same root layer with an empty session layer, so it never
sees an earlier image's randomisation. With ``distractors`` on, a new scene also scatters its distractors
(:mod:`synthua_usd.randomisation.distractors`) into the scene layer (:mod:`synthua_usd.usd.distractor_layer`); the
crowd is then placed clear of them, and they hide what is behind them when aid users are placed in view. The
scenario a scene is in (the dataset's, a district's, a setting's: :mod:`synthua_usd.pipeline.scenes`) is the
caller's to open; the randomiser records it.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from synthua_usd.assets.postures import shared_body_parts
from synthua_usd.core.errors import StageError
from synthua_usd.model.taxonomy import ClassMap
from synthua_usd.pipeline.scenes import SceneKey, scene_of
from synthua_usd.randomisation.config import RandomisationConfig
from synthua_usd.randomisation.distractors import DistractorsDraw, SurfaceTops, draw_distractors
from synthua_usd.randomisation.framing import draw_framing
from synthua_usd.randomisation.light import LightDraw, draw_light
from synthua_usd.randomisation.scene import SceneDraw, draw_scene
from synthua_usd.randomisation.settings import CAMERA_CLEARANCE_M
from synthua_usd.randomisation.streams import stream
from synthua_usd.randomisation.view import CameraJitter, ViewDraw, WalkArea, draw_camera, place_cast
from synthua_usd.usd.agents_writer import AGENTS_ROOT
from synthua_usd.usd.cameras import camera_paths, camera_rig_type, read_camera
from synthua_usd.usd.distractor_layer import author_distractors
from synthua_usd.usd.conditions import read_condition
from synthua_usd.usd.randomisation_layer import (RANDOM_ROOT, camera_override, recolourable_objects, scene_layers,
                                                 view_layer)
from synthua_usd.usd.reader import StageReader
from synthua_usd.usd.session_layers import RandomisationLayers, recompose
from synthua_usd.usd.stage_io import stage_metadata

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class ImageRandomisation:
    """What one image drew: the randomisation seed, its scene, its view, its light (None without a condition),
    and the SHA-256 of its view layer as authored (the same draws author the same bytes); with the ``settings``
    part on, the scene's ``setting`` (None in the district; absent from the record with the part off), and with
    ``distractors`` on, the scene's ``distractors``."""

    seed: int
    scene: SceneDraw
    view: ViewDraw
    light: LightDraw | None
    view_layer_digest: str
    settings_on: bool = False
    setting: object = None
    distractors: DistractorsDraw | None = None

    def to_dict(self) -> dict:
        out = {"seed": self.seed, "scene_seed": self.scene.scene_seed, "district_seed": self.scene.district_seed,
               "view_layer_sha256": self.view_layer_digest, "scene": self.scene.to_dict(),
               "view": self.view.to_dict(), "light": None if self.light is None else self.light.to_dict()}
        # absent, not null, where the parts are off: records as before they existed
        if self.settings_on:
            out["setting"] = None if self.setting is None else self.setting.to_dict()
        if self.distractors is not None:
            out["distractors"] = self.distractors.to_dict()
        return out


class Randomiser:
    """Randomises ``stage`` (an opened ``Usd.Stage``) image by image under ``config``, in :attr:`layers` (a
    :class:`~synthua_usd.usd.session_layers.RandomisationLayers` over the stage): ``size`` (width, height) is the
    render size (where a person counts as seen), ``time_code`` the one the twin is read at (it does not move)."""

    def __init__(self, stage, config: RandomisationConfig, class_map: ClassMap, size: tuple[int, int],
                 time_code: float | None = None) -> None:
        self.stage, self.config, self.class_map, self.size = stage, config, class_map, tuple(size)
        if config.crowd.enabled and stage_metadata(stage).up_axis != "Z":
            raise StageError(f"{stage.GetRootLayer().identifier}: is Y-up; crowd randomisation places people on "
                             f"Z-up stages (as synthua agents populate); expected upAxis Z, or randomise.crowd off")
        # what a draw reads of the scenario, never an earlier image's randomisation (the layers go over
        # ``stage``); the layers are rooted at /World whatever the stage's default prim
        self.base = recompose(stage, "base-session.usda")
        self.meta = replace(stage_metadata(self.base), default_prim="World")
        t = self.meta.start_time_code if time_code is None else time_code
        # the twin alone (walkable surfaces, recolourable objects, their materials): the district's crowd is three
        # quarters of its gprims (a snapshot 2.1 -> 0.5 s)
        snapshot = StageReader(recompose(stage, "twin-session.usda", inactive=(AGENTS_ROOT,)),
                               class_map).snapshot(float(t))
        twin = [m for m in snapshot.meshes if not m.prim_path.startswith((AGENTS_ROOT + "/", RANDOM_ROOT + "/"))]
        self.area = self.tops = None
        if config.crowd.enabled or config.camera.enabled or config.distractors.enabled:
            vertices, faces, owner = snapshot.world_triangles(twin)
            names = np.array([class_map.by_id(m.class_id).name for m in twin], object)
            face_class = names[owner] if len(owner) else np.zeros(0, object)
            self.area = WalkArea.build(vertices, faces, face_class)
            if config.distractors.enabled:
                self.tops = SurfaceTops.find(vertices, faces, face_class, self.area)
                self.cameras_xy = np.array([read_camera(self.base, p, float(t)).origin[:2] for p in camera_paths(self.base)])
        self.materials = snapshot.materials
        self.objects, self.bound = ([], {})
        if config.materials.enabled:
            self.objects, self.bound = recolourable_objects(self.base, snapshot, config.materials.classes)
        self.has_agents = bool(self.base.GetPrimAtPath(AGENTS_ROOT))
        self.bodies = shared_body_parts()
        self.layers = RandomisationLayers(stage)
        self._scene: SceneDraw | None = None
        self._cast = None  # the scene's CastPrims
        self._distractors: DistractorsDraw | None = None
        self._area = self.area  # the scene's: the twin's, with the distractors among the occluders

    def close(self) -> None:
        """Take the layers out of the stage's session layer again (the stage as composed before)."""
        self.layers.close()

    def scene(self, seed: int, key: SceneKey | None = None) -> SceneDraw:
        """Make the scene of ``seed`` the stage's (drawn and authored once per seed in a row); ``key`` the scenario
        the stage is (:func:`synthua_usd.pipeline.scenes.scene_of`; None: the dataset's own), recorded."""
        if self._scene is not None and self._scene.scene_seed == seed:
            return self._scene
        rng = stream(self.config.seed, seed, "scene")
        draw = draw_scene(rng, self.config, seed, walkable_area_m2=self.area.area_m2() if self.area else 0.0,
                          seats=list(self.area.seats) if self.area else [], objects=self.objects,
                          district_seed=None if key is None else key.district_seed)
        prototypes, scene, cast = scene_layers(draw, self.meta, self.class_map.taxonomy, self.bodies, self.materials,
                                               self.bound, deactivate_agents=self.has_agents and self.config.crowd.enabled)
        self._distractors, self._area = None, self.area
        if self.config.distractors.enabled:
            self._distractors = draw_distractors(stream(self.config.seed, seed, "distractors"), self.config.distractors,
                                                 self.area, self.tops, self.cameras_xy)
            author_distractors(scene, self._distractors, self.class_map.taxonomy)
            self._area = self.area.with_occluders((points, triangles) for item in self._distractors.items
                                                  for _, points, triangles, _, _ in item.parts())
        self.layers.set_scene(prototypes, scene)
        self._scene, self._cast = draw, cast
        return draw

    def apply(self, seed: int, camera_path: str, time_code: float, condition: str | None,
              key: SceneKey | None = None) -> ImageRandomisation:
        """Give the stage the randomisation of the image (``seed``, ``camera_path``, ``time_code``, ``condition``
        name or None for the stage's own lights; ``key`` the scenario the stage is, recorded) and return what it
        drew."""
        scene = self.scene(seed, key)
        cast = self._cast
        base_camera = read_camera(self.base, camera_path, time_code)
        rng = stream(self.config.seed, seed, "view", camera_path, time_code)
        jitter: CameraJitter | None = None
        camera = base_camera
        if self.config.camera.enabled:
            below = self.area.height_below(base_camera.origin) if self.area is not None else None
            jitter = draw_camera(rng, base_camera, camera_rig_type(self.base, camera_path), below, self.config.camera)
            camera = jitter.camera(base_camera)
        placements = ()
        if self.config.crowd.enabled and scene.cast:
            blocked = self._distractors.discs() if self._distractors is not None else ()
            if key is not None and key.setting is not None:  # nobody at the lens (a setting's cameras stand on its floors)
                blocked += ((float(camera.origin[0]), float(camera.origin[1]), CAMERA_CLEARANCE_M),)
            placements = place_cast(rng, scene.cast, self._area, camera, self.size, self.config.crowd, blocked)
        framing = None
        if (self.config.framing.enabled and placements and self.area is not None
                and camera_rig_type(self.base, camera_path) in self.config.framing.rig_types):
            framing = draw_framing(stream(self.config.seed, seed, "framing", camera_path, time_code),
                                   self.config.framing, scene.cast, placements, self._area, camera, self.size,
                                   self.bodies.bank)
            if framing is not None:
                camera = framing.camera(base_camera)
        light = randomised = None
        if condition is not None:
            base_condition = read_condition(self.base, condition)
            light = draw_light(stream(self.config.seed, seed, "light", camera_path, time_code, condition),
                               base_condition, self.config.light)
            randomised = light.condition(base_condition)
        override = None
        if jitter is not None or framing is not None or (light is not None and light.exposure_ev):
            override = camera_override(self.base, camera_path, time_code, camera.camera_to_world,
                                       camera.focal_length_mm, base_camera.focal_length_mm,
                                       light.exposure_ev if light is not None else 0.0)
        fresh = view_layer(cast, placements, self.bodies, self.meta, override, randomised,
                           doc=f"synthua randomisation: scene {seed}, {camera_path} at time code {time_code:g}"
                               + (f", {condition}" if condition else ""))
        digest = self.layers.set_view(fresh)
        return ImageRandomisation(self.config.seed, scene, ViewDraw(jitter, placements, framing), light, digest,
                                  self.config.settings.enabled, None if key is None else key.setting,
                                  self._distractors)

    def export(self, out: Path, anchor: Path | None = None) -> tuple[Path, Path, Path]:
        """Write the current image's layers: ``out`` (the view layer), ``<stem>.scene.usda`` and
        ``<stem>.prototypes.usdc`` beside it (:func:`synthua_usd.usd.randomisation_layer.export_layers`; asset
        paths relative to ``anchor``, the folder the files will be in, default ``out``'s)."""
        return self.layers.export(Path(out), anchor)


# --- synthua randomise: the layers of one image, written out ----------------------------------------------

@dataclass(frozen=True)
class RandomiseRequest:
    """One image's randomisation to write: of ``config_path``'s ``randomise`` block with ``seed``, ``camera``,
    ``time_code`` and ``condition`` (None: the stage's own lights), at the config's render size (else the
    stage's); or, with ``record_path``, of that record of a dataset (its generate.json gives the config; a record
    fixes the seed, camera, time code and condition, so none of those, nor ``config_path``, may come with it). When
    the seed's scene is in another scenario (a district, a setting: :mod:`synthua_usd.pipeline.scenes`), the layers
    go over that scenario: the dataset's copy, or one written beside ``out`` (``<stem>.district_<d>/``,
    ``<stem>.<kind>_<variant>/``); the render command printed names it."""

    scenario: Path
    out: Path
    config_path: Path | None = None
    record_path: Path | None = None
    seed: int | None = None
    camera: str | None = None
    time_code: float | None = None
    condition: str | None = None
    class_map_path: Path | None = None
    allow_external_assets: bool = False

    def __post_init__(self) -> None:
        from synthua_usd.core.errors import InputError, echo

        if self.record_path is None:
            return
        given = [option for option, value in (("--config", self.config_path), ("--seed", self.seed),
                                              ("--camera", self.camera), ("--time-code", self.time_code),
                                              ("--condition", self.condition)) if value is not None]
        if given:
            raise InputError(f"{given[0]}: given with --record {echo(self.record_path)}; expected one or the other (the "
                             f"record fixes its image's seed, camera, time code and condition, and its dataset's "
                             f"config)")


@dataclass(frozen=True)
class RandomiseResult:
    """The layer files written, what the image drew, and the ``synthua render`` arguments that render it."""

    files: tuple[Path, ...]
    randomisation: ImageRandomisation
    render_args: tuple[str, ...]


def _from_record(path: Path) -> tuple:
    """(config document, seed, camera path, time code, condition name, render dict) of a dataset record."""
    import json

    from synthua_usd.core.errors import InputError
    from synthua_usd.core.schemas import read_json
    from synthua_usd.dataset.layout import Layout
    from synthua_usd.dataset.record import IMAGE, read_record

    record = read_record(path, IMAGE)
    job_path = Path(path).resolve().parent.parent / Layout.CONFIG
    job = read_json(job_path, "the generate.json of the record's dataset")
    try:
        config = job["job_key"]["config"]
    except (KeyError, TypeError) as exc:
        raise InputError(f"{job_path}: job_key.config: {json.dumps(str(exc))[1:-1]} missing or malformed; expected "
                         f"the generate.json of the dataset synthua generate wrote") from None
    condition = record["condition"]["name"] if record["condition"] else None
    return (config, record["seed"], record["camera"]["prim_path"], float(record["time_code"]), condition,
            dict(record["render"]))


def randomise_image(request: RandomiseRequest) -> RandomiseResult:
    """Draw one image's randomisation over ``request.scenario`` and write its three layers as one output set."""
    import shlex

    from synthua_usd.core.atomic import output_set
    from synthua_usd.core.errors import InputError
    from synthua_usd.core.input_guard import check_not_inputs
    from synthua_usd.dataset.config import GenerationConfig
    from synthua_usd.model.render_config import resolve_render
    from synthua_usd.usd.render_settings import render_defaults
    from synthua_usd.usd.stage_io import USD_SUFFIXES, check_time_code, open_stage

    out = Path(request.out)
    if out.suffix.lower() not in USD_SUFFIXES[:3]:
        raise InputError(f"{out}: --out needs a USD layer name (.usda, .usdc or .usd); expected e.g. layer.usda")
    inputs = {"SCENARIO": request.scenario, "--config": request.config_path, "--record": request.record_path,
              "--class-map": request.class_map_path}
    check_not_inputs([out], inputs)  # before anything is drawn; the layers beside it are checked with the set
    render: dict = {}
    if request.record_path is not None:
        document, seed, camera, time_code, condition, render = _from_record(Path(request.record_path))
        config = GenerationConfig.from_document(document, source=str(request.record_path))
    else:
        if request.config_path is None:
            raise InputError("randomise: neither --config nor --record given; expected a generation config with a "
                             "randomise block, or an image record of a randomised dataset")
        config = GenerationConfig.load(request.config_path)
        seed, camera, time_code, condition = request.seed or 0, request.camera, request.time_code, request.condition
    source = request.record_path or request.config_path
    if config.randomise is None:
        raise InputError(f"{source}: has no randomise block; expected a config that randomises scenes (see "
                         f"schemas/generate.schema.json, randomise)")
    class_map = ClassMap.load_or_bundled(request.class_map_path)
    scenario, key = Path(request.scenario), scene_of(config.randomise, seed)
    if key is not None:
        # the seed's scene lies in another scenario: the dataset's copy of it, or one written beside --out
        from synthua_usd.pipeline.scenes import write_scene

        if config.randomise.district.enabled:
            from synthua_usd.pipeline.districts import check_district_scenario

            check_district_scenario(scenario)
        dataset = Path(request.record_path).resolve().parent.parent if request.record_path is not None else None
        if dataset is not None and (dataset / key.folder / "scenario.usda").is_file():
            scenario = dataset / key.folder / "scenario.usda"
        else:
            scenario = write_scene(scenario, key, out.parent / f"{out.stem}.{key.name}", class_map)
    stage = open_stage(scenario, request.allow_external_assets or key is not None)
    defaults = render_defaults(stage)
    if camera is None:
        camera = defaults.camera_path
        if not camera:
            raise StageError(f"{request.scenario}: no --camera given and no UsdRender settings name one; expected "
                             f"--camera PATH")
    time_code = float(stage.GetStartTimeCode()) if time_code is None else float(time_code)
    check_time_code(stage, time_code)
    read_camera(stage, camera, time_code)  # a missing camera is one line, before anything is drawn
    # a record's render block is what its image was rendered with: it stands where command-line options do
    settings = resolve_render(stage=defaults.render_values(), config=config.render.render_values(),
                              options={key: render.get(key) for key in ("width", "height", "spp", "max_depth")}
                              | ({"denoise": render["denoise"] is not None} if "denoise" in render else {}))
    width, height = settings.width, settings.height
    randomiser = Randomiser(stage, config.randomise, class_map, (width, height))
    drawn = randomiser.apply(seed, camera, time_code, condition, key)
    with output_set(out.parent, inputs=inputs) as staging:
        randomiser.export(staging / out.name, anchor=out.parent)
        files = tuple(out.parent / p.name for p in sorted(staging.iterdir()))
    args = ("synthua", "render", str(scenario), "--layer", str(out), "--camera", camera,
            "--time-code", f"{time_code:g}", *(("--condition", condition) if condition else ()), "--seed", str(seed),
            "--width", str(width), "--height", str(height), "--spp", str(settings.spp),
            "--max-depth", str(settings.max_depth), "--denoise" if settings.denoise else "--no-denoise", "--out", "OUT")
    log.info("render with: %s", " ".join(shlex.quote(a) for a in args))
    return RandomiseResult(files, drawn, args)
