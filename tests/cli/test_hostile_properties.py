"""Property tests (Hypothesis) of parameters and small documents: whatever the value, synthua either does
its job (exit 0, or 1 for findings and failed checks where the command has them) or refuses with exit 2 and
one line naming the file or option; never a traceback, an internal error (exit 3) or a non-finite result."""

from __future__ import annotations

import json
import math
import tempfile
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from hostile import assert_refused
from importers.hostile_corpus import (CITYJSON, CLASSMAP, GCP_MODEL, GCP_SURVEYED, GEOJSON, MTL, OBJ, RULES, doc,
                                      run_inprocess, write)

PROPERTY = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
DOCUMENT = settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])

any_float = st.one_of(st.floats(), st.sampled_from([0.0, -0.0, 1e-300, 1e300, 1e-9, 1e9]))
number_text = st.one_of(any_float.map(repr), st.integers(min_value=-10**30, max_value=10**30).map(str),
                        st.sampled_from(["nan", "inf", "-inf", "1e400", "9" * 5000, "", "0x10", "1_000"]))


def _check(result, allowed=(0,), *mentions):
    assert "Traceback" not in result.stderr, result.stderr
    assert result.code in (*allowed, 2), f"exit {result.code}: {result.stderr}"
    if result.code == 2:
        return assert_refused(result, *mentions)
    return None


FLIGHT_OPTIONS = ["--altitude-m", "--fov-deg", "--frontal-overlap", "--lateral-overlap", "--area-width-m",
                  "--area-length-m", "--sensor-width-mm", "--focal-length-mm", "--image-width-px"]
FLIGHT_DEFAULTS = {"--altitude-m": "150", "--fov-deg": "84", "--area-width-m": "1225", "--area-length-m": "1225",
                   "--sensor-width-mm": "13.2", "--focal-length-mm": "10.26", "--image-width-px": "5472"}


@PROPERTY
@given(values=st.dictionaries(st.sampled_from(FLIGHT_OPTIONS), number_text, min_size=1, max_size=3))
def test_flight_plan_any_values(capsys, values):
    options = {**FLIGHT_DEFAULTS, **values}
    args = ["survey", "flight-plan", "--json"] + [x for kv in options.items() for x in kv]
    result = run_inprocess(capsys, *args)
    message = _check(result)
    if message is None:
        plan = json.loads(result.stdout)
        assert all(math.isfinite(v) for v in plan.values() if isinstance(v, float)), plan
        assert 1 <= plan["images"] <= 1_000_000, plan
    else:
        assert any(option in message for option in values) or "images" in message, message
        assert "_m " not in message and "altitude_m" not in message, message


@PROPERTY
@given(value=number_text)
def test_gcp_threshold_any_value(capsys, value):
    result = run_inprocess(capsys, "survey", "gcp", GCP_SURVEYED, GCP_MODEL,
                           "--threshold-m", value)
    message = _check(result, (0, 1))
    if message is not None:
        assert "--threshold-m" in message


TWIN_OPTIONS = {"--scale": ("mesh", 1e-3, 1e3), "--max-deviation-m": ("pointcloud", 1e-3, 1.0),
                "--plane-threshold-m": ("pointcloud", 1e-3, 1.0), "--storey-height-m": ("footprints", 2.0, 10.0)}


@PROPERTY
@given(option=st.sampled_from(sorted(TWIN_OPTIONS)), value=any_float)
def test_twin_import_option_any_value(capsys, tmp_path, option, value):
    """A nonsense value names the option; a plainly sensible one gets past it (to the absent input)."""
    kind, low, high = TWIN_OPTIONS[option]
    rules = ["--rules", RULES] if kind == "mesh" else []
    result = run_inprocess(capsys, "twin", "import", kind, tmp_path / "absent.input", *rules, option, repr(value),
                           "--out", tmp_path / "out")
    message = assert_refused(result)
    if not math.isfinite(value) or value <= 0 or value > 1e6 or value < 1e-6:
        assert option in message, message
    if low <= value <= high:
        assert "absent.input" in message and option not in message, message


# --- small documents ----------------------------------------------------------------------------------------

json_values = st.recursive(
    st.one_of(st.none(), st.booleans(), st.integers(min_value=-2**70, max_value=2**70),
              st.floats(allow_nan=False, allow_infinity=False), st.text(max_size=8)),
    lambda children: st.one_of(st.lists(children, max_size=4), st.dictionaries(st.text(max_size=6), children,
                                                                              max_size=4)),
    max_leaves=12)


def _paths(node, prefix=()):
    yield prefix
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _paths(v, prefix + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _paths(v, prefix + (i,))


def _replace(document, path, value):
    if not path:
        return value
    node = document
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    return document


def _mutations(base: Path):
    paths = list(_paths(doc(base)))
    return st.lists(st.tuples(st.sampled_from(paths), json_values), min_size=1, max_size=3)


def _mutated(base: Path, mutations) -> dict:
    document = doc(base)
    for path, value in mutations:
        try:
            document = _replace(document, path, value)
        except (KeyError, IndexError, TypeError):
            pass  # an earlier mutation removed the path
    return document


@DOCUMENT
@given(mutations=_mutations(CITYJSON))
def test_cityjson_mutations(capsys, mutations):
    with tempfile.TemporaryDirectory() as tmp:
        path = write(Path(tmp) / "city.json", _mutated(CITYJSON, mutations))
        result = run_inprocess(capsys, "twin", "import", "cityjson", path, "--out", Path(tmp) / "out")
        _check(result, (0,), "city.json")
        if result.code == 0:
            assert (Path(tmp) / "out" / "scenario.usda").is_file()


@DOCUMENT
@given(mutations=_mutations(GEOJSON))
def test_geojson_mutations(capsys, mutations):
    with tempfile.TemporaryDirectory() as tmp:
        path = write(Path(tmp) / "blocks.geojson", _mutated(GEOJSON, mutations))
        result = run_inprocess(capsys, "twin", "import", "footprints", path, "--out", Path(tmp) / "out")
        _check(result, (0,), "blocks.geojson")


@DOCUMENT
@given(mutations=_mutations(CLASSMAP))
def test_classmap_mutations(capsys, mutations):
    with tempfile.TemporaryDirectory() as tmp:
        path = write(Path(tmp) / "classes.json", _mutated(CLASSMAP, mutations))
        _check(run_inprocess(capsys, "validate", "classes", path), (0, 1), "classes.json")


regex_text = st.text(alphabet=st.sampled_from(list("ab()[]{}+*?|\\^$.=!<:-,0123456789PkdwsSbB")), max_size=20)


@DOCUMENT
@given(pattern=regex_text, field=st.sampled_from(["object", "material", "group", "any"]))
def test_rules_any_pattern(capsys, pattern, field):
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        (tmp / MTL.name).write_bytes(MTL.read_bytes())
        obj = write(tmp / OBJ.name, OBJ.read_bytes())
        rules = write(tmp / "rules.json", {"rules": [{"field": field, "pattern": pattern, "class": "road"}]})
        result = run_inprocess(capsys, "twin", "import", "mesh", obj, "--rules", rules, "--out", tmp / "out")
        message = _check(result, (0,), "rules.json")
        if message is not None:
            assert "rules[0].pattern" in message or "(document)" in message or "rules[0]" in message, message


csv_cell = st.one_of(number_text, st.text(max_size=6))


@DOCUMENT
@given(rows=st.lists(st.lists(csv_cell, min_size=0, max_size=5), max_size=5),
       header=st.sampled_from(["id,x,y,z", "id,x,y", "x,y,z,id", "", "ID, X ,Y,Z"]))
def test_gcp_csv_any_rows(capsys, rows, header):
    with tempfile.TemporaryDirectory() as tmp:
        text = header + "\n" + "\n".join(",".join(r) for r in rows) + "\n"
        path = write(Path(tmp) / "gcp.csv", text.encode("utf-8", "surrogatepass"))
        _check(run_inprocess(capsys, "survey", "gcp", path, GCP_MODEL), (0, 1), "gcp.csv")

