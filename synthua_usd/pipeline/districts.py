"""Randomised scenes over several procedural districts: the scenario of each district seed a dataset draws.

A dataset whose config sets ``randomise.district`` renders each seed's scene in the Largo da Ordem district
of one of its district seeds (:func:`district_of`, drawn from the seed's ``district`` stream; which scenario a
scene is in is :func:`synthua_usd.pipeline.scenes.scene_of`'s to say). Each district is
written once into the dataset as a complete, self-contained scenario, ``scenes/district_<d>/``: the district's
twin and semantics layers with their textures (``synthua create district --seed d`` would write the same bytes),
copies of the scenario's own thin layers (render settings, environment, cameras, rigs), and a
``scenario.usda`` composing them in the scenario's order. The scenario's own crowd is left out: the
randomised crowd replaces it anyway. A worker keeps one district loaded while its shard's images need it.
"""

from __future__ import annotations

import shutil
from pathlib import Path

from synthua_usd.composition.scenario import LAYER_FILE, ROOT_FILE
from synthua_usd.core.atomic import output_set
from synthua_usd.core.errors import InputError
from synthua_usd.model.taxonomy import ClassMap
from synthua_usd.randomisation.config import RandomisationConfig
from synthua_usd.randomisation.streams import stream
from synthua_usd.usd.stage_io import open_layer

#: What the demo district's twin layer says it is (``customLayerData`` ``synthua:source``).
DISTRICT_SOURCE = "largo-da-ordem demo district"


def district_of(config: RandomisationConfig, seed: int) -> int | None:
    """The district seed of the scene of ``seed`` (None when districts are not randomised)."""
    if not config.district.enabled:
        return None
    seeds = config.district.seeds
    return int(seeds[int(stream(config.seed, seed, "district").integers(len(seeds)))])


def check_district_scenario(scenario: Path) -> list[str]:
    """The sublayer paths of ``scenario``'s root (strongest first), after checking that it composes the demo
    district's twin and semantics layers by their file names; an :class:`InputError` says what is expected."""
    root = open_layer(scenario)
    sublayers = list(root.subLayerPaths)
    names = [Path(p).name for p in sublayers]
    twin_name = LAYER_FILE["twin"]
    if twin_name not in names or LAYER_FILE["semantics"] not in names:
        raise InputError(f"{scenario}: randomise.district needs a scenario that composes {twin_name} and "
                         f"{LAYER_FILE['semantics']} (as synthua create district writes); it composes "
                         f"{', '.join(names) or 'no layers'}")
    twin = open_layer(Path(scenario).parent / sublayers[names.index(twin_name)])
    source = str(twin.customLayerData.get("synthua:source", ""))
    if not source.startswith(DISTRICT_SOURCE):
        raise InputError(f"{scenario}: randomise.district varies the demo district's seed, but its twin is "
                         f"'{source or 'unknown'}'; expected a scenario written by synthua create district")
    return sublayers


def write_district_scene(scenario: Path, seed: int, out_dir: Path, class_map: ClassMap,
                         dataset_part: bool = False) -> Path:
    """Write the district of ``seed`` as a scenario in ``out_dir`` (one output set; kept when ``out_dir`` holds
    it already) and return its ``scenario.usda``; ``dataset_part``: ``out_dir`` is the scenes folder of the
    dataset being generated (the one writer allowed into a dataset)."""
    from synthua_usd.core.texture_images import write_texture_images
    from synthua_usd.demo.district import META, build_district
    from synthua_usd.usd.authoring import save_layer_atomic
    from synthua_usd.usd.compose import compose_layers
    from synthua_usd.usd.twin_writer import author_twin

    out_dir = Path(out_dir)
    if (out_dir / ROOT_FILE).is_file():
        return out_dir / ROOT_FILE
    sublayers = check_district_scenario(scenario)
    base = Path(scenario).parent
    model = build_district(seed)
    twin, semantics = author_twin(model, class_map, META)
    own = {LAYER_FILE["twin"]: twin, LAYER_FILE["semantics"]: semantics}
    with output_set(out_dir, dataset_part=dataset_part) as staging:
        order = []
        for path in sublayers:
            name = Path(path).name
            if name == LAYER_FILE["agents"]:
                continue  # the randomised crowd replaces the scenario's
            if name in own:
                save_layer_atomic(own[name].GetRootLayer(), staging / name)
            else:
                _copy_thin_layer(base / path, staging / name)
            order.append(staging / name)
        write_texture_images(model.images, staging)
        compose_layers(staging / ROOT_FILE, order, doc=f"Largo da Ordem demo district (seed {seed}) scenario, "
                                                       f"drawn by a randomised dataset.")
    return out_dir / ROOT_FILE


def _copy_thin_layer(source: Path, target: Path) -> None:
    """Copy a thin layer (render settings, environment, cameras) byte for byte, refusing one that sublayers,
    references or reads other files (a copy would lose them)."""
    layer = open_layer(source)
    if layer.GetCompositionAssetDependencies() or layer.GetExternalAssetDependencies():
        raise InputError(f"{source}: sublayers or references other files; expected the thin layers of a scenario "
                         f"written by synthua create district")
    shutil.copyfile(source, target)
