"""Shared fixtures: paths, the class map, a CLI runner, the shipped demo scenario, and Mitsuba variants.

Three conftests exist: this one, and ``tests/importers/conftest.py`` and ``tests/cli/conftest.py``, which both
only import the hostile-input suite's fixtures from ``importers/hostile_corpus.py``. The test folders mirror the
package; pytest puts tests/ on sys.path, so every test module can import ``conftest`` and the 13 helper modules
beside it: ``bank_maker`` (tiny cut-out banks), ``dataset_runs`` (a dataset's files and records, a generate run),
``format_readers`` (the real format readers set up), ``frame_checks``, ``hostile`` (the hostile-input harness),
``label_scenes`` (hand-made label maps and records), ``las_files``, ``layer_match`` (a generated file against its
committed copy; ``test_layer_match.py`` tests it), ``normal_scenes``, ``reference_images``, ``reference_raycast``
(the independent Embree label renderer), ``snapshot_checks`` and ``texture_checks``.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

from synthua_usd.cli.main import main
from synthua_usd.model.taxonomy import ClassMap

REPO = Path(__file__).resolve().parents[1]
DATA = Path(__file__).resolve().parent / "data"
STAGES = REPO / "stages"
SCENARIO = STAGES / "scenario.usda"
DISTRICT = STAGES / "district"
SHARED = REPO.parent / "shared"

#: The paper's eight mobility-aid classes, by their class-map names.
MOBILITY_AIDS = frozenset({"manual_wheelchair", "electric_wheelchair", "walker", "crutch", "smart_cane", "wooden_cane",
                           "orthopedic_cane", "tripod_cane"})

#: The variants every Mitsuba backend test runs on, as Mitsuba's own suite does: scalar (Mitsuba's
#: kd-tree, one ray at a time) and LLVM (Dr.Jit, Embree). Scalar is slow: keep its images tiny.
MITSUBA_VARIANTS = ("scalar_rgb", "llvm_ad_rgb")


@pytest.fixture(scope="session")
def class_map() -> ClassMap:
    return ClassMap.default()


@pytest.fixture
def run_cli(capsys):
    """Run ``synthua ARGS...`` in-process; returns (exit status, stdout, stderr)."""
    def run(*args: str) -> tuple[int, str, str]:
        code = main([str(a) for a in args])
        out = capsys.readouterr()
        return code, out.out, out.err
    return run


@pytest.fixture(scope="session")
def demo_stage():
    from synthua_usd.usd.stage_io import open_stage

    return open_stage(SCENARIO)


@pytest.fixture(scope="session")
def tiny(class_map):
    """(snapshot, camera) of tests/data/valid/tiny_scene.usda at time code 1: a ground quad and a box."""
    from synthua_usd.usd.cameras import read_camera
    from synthua_usd.usd.reader import read_snapshot
    from synthua_usd.usd.stage_io import open_stage

    stage = open_stage(DATA / "valid" / "tiny_scene.usda")
    return read_snapshot(stage, 1.0, class_map), read_camera(stage, "/World/Cam", 1.0)


@pytest.fixture(scope="session")
def lamps_scenario(tmp_path_factory) -> Path:
    """tests/data/valid/tiny_street_lamps.usda composed under an environment layer that synthua authors with
    the shipped conditions: a tiny scenario (road, house with a window, lamp post, car with head lamps, a
    person; camera /World/Cam) for condition tests."""
    import shutil

    from synthua_usd.composition.scenario import SHIPPED_ENVIRONMENT, StageMetadata
    from synthua_usd.usd.authoring import save_layer_atomic
    from synthua_usd.usd.compose import compose_layers
    from synthua_usd.usd.scenario_layers import build_environment

    folder = tmp_path_factory.mktemp("lamps_scenario")
    shutil.copy(DATA / "valid" / "tiny_street_lamps.usda", folder / "street.usda")
    environment = build_environment(StageMetadata(end_time_code=2.0), SHIPPED_ENVIRONMENT)
    save_layer_atomic(environment.GetRootLayer(), folder / "environment.usda")
    return compose_layers(folder / "scenario.usda", [folder / "environment.usda", folder / "street.usda"])


def activate_variant(name: str):
    """The ``mitsuba`` module with ``name`` active, or skip the test when this machine cannot run it."""
    from synthua_usd.backends.mitsuba import variants
    from synthua_usd.core.errors import InputError

    try:
        return variants.activate(name)
    except InputError as exc:
        pytest.skip(f"Mitsuba variant {name} cannot run on this machine: {exc}")


@pytest.fixture(scope="module", params=MITSUBA_VARIANTS)
def variant(request) -> str:
    """The name of a Mitsuba variant to run the test on; llvm_ad_rgb is skipped, with the reason, where it
    cannot run (no libLLVM >= 19). Module-scoped so that a module can render once per variant; tests
    activate it themselves (``variants.activate(variant)``, or a ``RenderSession`` of that variant)."""
    activate_variant(request.param)
    return request.param


THIRD_PARTY = SHARED / "data" / "third_party"


def third_party(*parts: str) -> Path:
    """A file of ../shared/data/third_party, or skip the test when the shared folder is not beside the clone."""
    path = THIRD_PARTY.joinpath(*parts)
    if not path.exists():
        pytest.skip(f"{path} is absent: third-party test data lives in ../shared beside the repository (CI has it)")
    return path


def load_tool(script: str, name: str):
    """The module of ``tools/<script>`` imported as ``name`` (registered in sys.modules: its dataclasses look their
    module up)."""
    import importlib.util
    import sys

    spec = importlib.util.spec_from_file_location(name, REPO / "tools" / script)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


#: A generation config for tests: the demo street, 6 images of 64x48 at 2 spp over two conditions.
TINY_CONFIG = DATA / "configs" / "tiny.json"


def generate_dataset(out: Path, config: Path = TINY_CONFIG, scenario: Path = SCENARIO, **options):
    """Run ``synthua generate`` in-process (workers in their own processes) and return its summary."""
    from synthua_usd.pipeline.generate import GenerateRequest, generate

    return generate(GenerateRequest(scenario=scenario, config_path=config, out_dir=out, **options))


#: A randomised generation config: the demo street, 6 images of 96x72 over 3 seeds (scenes) and 2 conditions.
RANDOM_CONFIG = DATA / "configs" / "random.json"


def built_once(tmp_path_factory, name: str, build) -> Path:
    """``<temp>/<name>/dataset`` made by ``build(path)`` once for the whole run. With pytest-xdist (``make test``
    runs the suite on parallel workers) the workers share it: the first to need it builds it under a file lock,
    the others wait for it and read the same folder."""
    if os.environ.get("PYTEST_XDIST_WORKER") is None:
        out = tmp_path_factory.mktemp(name) / "dataset"
        build(out)
        return out
    from filelock import FileLock

    root = tmp_path_factory.getbasetemp().parent  # the run's folder, above each worker's own
    out, built = root / name / "dataset", root / name / "built"
    with FileLock(str(root / f"{name}.lock")):
        if not built.exists():
            shutil.rmtree(out.parent, ignore_errors=True)  # what a worker that failed building left
            out.parent.mkdir()
            build(out)
            built.touch()
    return out


@pytest.fixture(scope="session")
def generated_random(tmp_path_factory) -> Path:
    """A randomised dataset of the demo street made with tests/data/configs/random.json (do not modify it)."""
    return built_once(tmp_path_factory, "random", lambda out: generate_dataset(out, config=RANDOM_CONFIG))


@pytest.fixture(scope="session")
def generated(tmp_path_factory) -> Path:
    """A dataset of the demo street made with tests/data/configs/tiny.json (do not modify it: copy it)."""
    return built_once(tmp_path_factory, "generated", generate_dataset)


@pytest.fixture
def generated_copy(generated, tmp_path) -> Path:
    """A copy of the ``generated`` dataset, to damage."""
    out = tmp_path / "dataset"
    shutil.copytree(generated, out)
    return out


#: The test files that take longest (pytest-xdist workers on 2 cores, 2026-12-04; the Ray, view-score and settings
#: files added 2026-12-06 from a fresh-clone run's --durations), run first: with ``--dist loadfile
#: --no-loadscope-reorder`` (``make test``) pytest-xdist hands out files in collection order, and a long one handed
#: out last keeps one worker busy while the others idle. (Without ``--no-loadscope-reorder`` xdist reorders the
#: files by their number of tests, which put these few-test files last.)
LONGEST_FIRST = ("pipeline/test_districts.py", "pipeline/test_sim2real.py", "test_quickstart.py", "demo/test_district.py",
                 "test_wheel.py", "pipeline/test_generate_ray.py", "assets/test_bodies.py",
                 "pipeline/test_generate_randomised.py", "pipeline/test_view_scores.py",
                 "pipeline/test_generate_settings.py",
                 "pipeline/test_executors.py", "tools/test_bench_targets.py", "pipeline/test_generate.py",
                 "pipeline/test_randomiser.py", "backends/mitsuba/test_determinism.py", "pipeline/test_generate_resume.py",
                 "cli/test_hostile_subprocess.py", "pipeline/test_sequences.py", "backends/mitsuba/test_environment.py",
                 "agents/test_router.py")


def pytest_collection_modifyitems(config, items):
    tests = Path(__file__).resolve().parent

    def rank(item) -> int:
        path = Path(str(item.path)).resolve()
        name = path.relative_to(tests).as_posix() if path.is_relative_to(tests) else ""
        return LONGEST_FIRST.index(name) if name in LONGEST_FIRST else len(LONGEST_FIRST)

    items.sort(key=rank)
