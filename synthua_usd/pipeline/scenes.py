"""Which scenario each randomised scene is in, and those scenarios written once into the dataset: the one
mechanism behind ``randomise.district`` and ``randomise.settings``.

A seed's scene is in the dataset's own scenario, or in a scenario the dataset holds in its ``scenes/`` folder
(:func:`scene_of`): a district of another seed (:mod:`synthua_usd.pipeline.districts`, ``scenes/district_<d>``) or a
procedural setting (:mod:`synthua_usd.pipeline.setting_scenes`, ``scenes/<kind>_<variant>``). Each is a complete,
self-contained scenario, written once before anything is planned (:func:`write_dataset_scenes`) and listed in the
manifest; workers, the planner, ``synthua replay`` and ``synthua randomise`` open the scenario of each seed's scene
by the same :class:`SceneKey`, and order their work by it so that each is loaded once.
"""

from __future__ import annotations

import shutil
from dataclasses import dataclass
from pathlib import Path

from synthua_usd.composition.scenario import ROOT_FILE
from synthua_usd.model.taxonomy import ClassMap
from synthua_usd.pipeline.districts import check_district_scenario, district_of, write_district_scene
from synthua_usd.randomisation.config import RandomisationConfig
from synthua_usd.randomisation.settings import SettingDraw, draw_setting
from synthua_usd.randomisation.streams import stream

#: Where a dataset keeps the scenarios of its scenes, relative to the dataset folder.
SCENES_FOLDER = "scenes"
DISTRICT = "district"


@dataclass(frozen=True, order=True)
class SceneKey:
    """A scenario a scene can be in: ``kind`` ``district`` (``number`` its district seed) or a setting kind of
    :data:`synthua_usd.randomisation.settings.SETTING_KINDS` (``number`` its variant)."""

    kind: str
    number: int

    @property
    def name(self) -> str:
        """``district_<d>``, ``<kind>_<variant>``: the scenario's folder in ``scenes/``."""
        return f"{self.kind}_{self.number}"

    @property
    def folder(self) -> str:
        """``scenes/<name>``, relative to the dataset folder."""
        return f"{SCENES_FOLDER}/{self.name}"

    @property
    def district_seed(self) -> int | None:
        return self.number if self.kind == DISTRICT else None

    @property
    def setting(self) -> SettingDraw | None:
        return None if self.kind == DISTRICT else SettingDraw(self.kind, self.number)


def setting_of(config: RandomisationConfig, seed: int) -> SettingDraw | None:
    """The procedural setting of the scene of ``seed`` (None: the district, or settings are off)."""
    if not config.settings.enabled:
        return None
    return draw_setting(stream(config.seed, seed, "setting"), config.settings)


def scene_of(config: RandomisationConfig | None, seed: int) -> SceneKey | None:
    """The scenario the scene of ``seed`` is in: None for the dataset's own scenario. A setting drawn for the seed
    wins; otherwise the district drawn for it (each from a stream of its own, so neither moves the other)."""
    if config is None:
        return None
    setting = setting_of(config, seed)
    if setting is not None:
        return SceneKey(setting.kind, setting.variant)
    district = district_of(config, seed)
    return None if district is None else SceneKey(DISTRICT, district)


def scene_order(key: SceneKey | None) -> tuple:
    """A sort key that puts the dataset's own scenario first, then the keys in order."""
    return (0,) if key is None else (1, key.kind, key.number)


def write_scene(scenario: Path, key: SceneKey, out_dir: Path, class_map: ClassMap, dataset_part: bool = False) -> Path:
    """Write the scenario of ``key`` for the dataset scenario ``scenario`` into ``out_dir`` (kept when it holds it
    already) and return its ``scenario.usda``."""
    if key.kind == DISTRICT:
        return write_district_scene(scenario, key.number, out_dir, class_map, dataset_part)
    from synthua_usd.pipeline.setting_scenes import write_setting_scene

    return write_setting_scene(scenario, key.kind, key.number, out_dir, class_map, dataset_part)


def write_dataset_scenes(scenario: Path, config: RandomisationConfig | None, seeds, class_map: ClassMap,
                         dataset: Path) -> dict[SceneKey, Path]:
    """Every scenario the ``seeds`` draw, written into ``dataset``'s ``scenes/`` (kept from an earlier run of the
    job); key -> its ``scenario.usda``. Empty when every scene is in the dataset's own scenario."""
    keys = sorted({scene_of(config, s) for s in seeds} - {None})
    if config is not None and config.district.enabled:
        check_district_scenario(scenario)
    if not keys:
        return {}
    clear_partial_scenes(dataset)
    return {k: write_scene(scenario, k, Path(dataset) / k.folder, class_map, dataset_part=True) for k in keys}


def scene_paths(config: RandomisationConfig | None, seeds, dataset: Path) -> dict[SceneKey, str]:
    """key -> the absolute path of its ``scenario.usda`` in ``dataset``, for every scene the ``seeds`` draw."""
    keys = sorted({scene_of(config, s) for s in seeds} - {None})
    return {k: str((Path(dataset) / k.folder / ROOT_FILE).resolve()) for k in keys}


def clear_partial_scenes(dataset: Path) -> None:
    """Remove the staging folders a killed run left in ``scenes/`` (their scenarios are written again)."""
    folder = Path(dataset) / SCENES_FOLDER
    if folder.is_dir():
        for path in folder.iterdir():
            if path.name.startswith(".") and path.is_dir():
                shutil.rmtree(path, ignore_errors=True)
