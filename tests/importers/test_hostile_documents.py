"""Hostile JSON documents wherever synthua reads one: class maps (``validate classes``, ``--class-map``),
rules files (``--rules``), CityJSON and GeoJSON inputs. Every case: exit 2, no traceback, one line naming
the file, nothing changed in the output folder or beside it."""

from __future__ import annotations

import os

import pytest

from importers.hostile_corpus import CITYJSON, CLASSMAP, GEOJSON, RULES, doc, mesh_input, write

BIG = "9" * 5000


def _classmap_validate(f, w):
    return ["validate", "classes", f]


def _classmap_option(f, w):
    return ["twin", "import", "footprints", GEOJSON, "--class-map", f, "--out", w / "out"]


def _rules(f, w):
    return ["twin", "import", "mesh", mesh_input(w), "--rules", f, "--out", w / "out"]


def _cityjson(f, w):
    return ["twin", "import", "cityjson", f, "--out", w / "out"]


def _geojson(f, w):
    return ["twin", "import", "footprints", f, "--out", w / "out"]


#: role -> (command for a document file, the valid document, where to put a spoiled value in it)
ROLES = {
    "classmap-validate": (_classmap_validate, CLASSMAP, ("classes", 1, "color")),
    "classmap-option": (_classmap_option, CLASSMAP, ("classes", 1, "color")),
    "rules": (_rules, RULES, ("rules", 0, "pattern")),
    "cityjson": (_cityjson, CITYJSON, ("vertices", 0)),
    "geojson": (_geojson, GEOJSON, ("features", 0, "properties", "height")),
}


def _spoiled(base, where, value) -> dict:
    out = doc(base)
    node = out
    for key in where[:-1]:
        node = node[key]
    node[where[-1]] = value
    return out


def _placeholder(base, where) -> str:
    """The document as text with ``@@`` where the spoiled value goes."""
    return __import__("json").dumps(_spoiled(base, where, "@@")).replace('"@@"', "@@")


#: case -> (file content from (base, where), words the message must contain besides the file name)
BODIES = {
    "nested-100000": (lambda b, w: "[" * 100_000 + "]" * 100_000, ("nested",)),
    "nested-object-5000": (lambda b, w: '{"a": ' * 5000 + "1" + "}" * 5000, ("nested",)),
    "nested-900-inside": (lambda b, w: _placeholder(b, w).replace("@@", "[" * 900 + "]" * 900), ("nested",)),
    "int-5000-digits": (lambda b, w: _placeholder(b, w).replace("@@", BIG), ("digits",)),
    "float-1e400": (lambda b, w: _placeholder(b, w).replace("@@", "1e400"), ("1e400",)),
    "nan-literal": (lambda b, w: _placeholder(b, w).replace("@@", "NaN"), ("NaN",)),
    "not-utf8": (lambda b, w: _placeholder(b, w).replace("@@", '"\udcff"').encode("utf-8", "surrogateescape"),
                 ("UTF-8",)),
    "utf16": (lambda b, w: _placeholder(b, w).replace("@@", "1").encode("utf-16"), ("UTF-8",)),
    "empty": (lambda b, w: b"", ("JSON",)),
    "truncated": (lambda b, w: _placeholder(b, w).replace("@@", "1")[:-5], ("JSON",)),
    "top-level-list": (lambda b, w: "[1, 2, 3]", ("object",)),
    "top-level-string": (lambda b, w: '"hello"', ("object",)),
}


@pytest.mark.parametrize("role", ROLES)
@pytest.mark.parametrize("body", BODIES)
def test_malformed_document(refuse, workdir, role, body):
    if role == "classmap-validate" and body.startswith("top-level"):
        pytest.skip("a readable JSON value that is no class map is a schema finding (exit 1): see below")
    command, base, where = ROLES[role]
    make, words = BODIES[body]
    path = write(workdir / f"hostile_{body}.json", make(base, where))
    refuse(*command(path, workdir), mentions=(path.name, *words))


@pytest.mark.parametrize("role", ROLES)
def test_document_over_size_limit(refuse, workdir, role):
    path = workdir / "huge.json"
    with open(path, "wb") as fh:  # sparse: costs no disk, and must not be read at all
        fh.truncate(65 * 2**20)
    refuse(*ROLES[role][0](path, workdir), mentions=(path.name, "MiB"))


@pytest.mark.parametrize("role", ROLES)
def test_document_is_a_folder(refuse, workdir, role):
    path = workdir / "folder.json"
    path.mkdir()
    refuse(*ROLES[role][0](path, workdir), mentions=(path.name,))


@pytest.mark.parametrize("role", ROLES)
def test_document_missing(refuse, workdir, role):
    path = workdir / "absent.json"
    refuse(*ROLES[role][0](path, workdir), mentions=(path.name,))


@pytest.mark.parametrize("role", ROLES)
def test_document_is_dev_zero(refuse, workdir, role):
    """A character device reads forever: refused before reading, as not a regular file."""
    refuse(*ROLES[role][0]("/dev/zero", workdir), mentions=("/dev/zero", "regular file"))


@pytest.mark.parametrize("role", ROLES)
def test_document_is_fifo(refuse, workdir, role):
    """Opening a FIFO with no writer blocks forever: refused before opening. The FIFO lies beside the
    snapshotted folder (tests/hostile.py's tree_state would block reading it)."""
    path = workdir.parent / f"{workdir.name}.pipe.json"
    os.mkfifo(path)
    refuse(*ROLES[role][0](path, workdir), mentions=(path.name, "regular file"))


# --- rules files -----------------------------------------------------------------------------------------

def _rules_doc(pattern: str, field: str = "object") -> dict:
    return {"rules": [{"field": field, "pattern": pattern, "class": "road"}]}


@pytest.mark.parametrize("pattern", [r"(a)\1", r"road(?=_)", r"(?<=x)road", r"(?P<n>a)(?P=n)", r"a++",
                                     r"((a{100}){100}){100}", r"[", "x" * 1001])
def test_rules_pattern_refused(refuse, workdir, pattern):
    """Patterns the linear-time engine (RE2) cannot run, and overlong ones, are refused naming the field."""
    path = write(workdir / "rules.json", _rules_doc(pattern))
    refuse("twin", "import", "mesh", mesh_input(workdir), "--rules", path, "--out", workdir / "out",
           mentions=("rules.json", "rules[0].pattern"))


@pytest.mark.parametrize("spoil, mentions", [
    ({"rules": {"field": "object", "pattern": "a", "class": "road"}}, ("rules",)),
    ({"rules": [{"field": "object", "pattern": "a", "class": "nope"}]}, ("rules[0].class", "nope")),
    ({"rules": [{"field": "object", "pattern": "a", "class": "road"}], "default": "nope"}, ("default", "nope")),
    ({"rules": [{"field": "colour", "pattern": "a", "class": "road"}]}, ("rules[0].field",)),
    ({"rules": [{"field": "object", "pattern": 5, "class": "road"}]}, ("rules[0].pattern",)),
    ({"rules": [{"field": "object", "pattern": "a", "class": "road"}] * 1001}, ("rules",)),
])
def test_rules_document_refused(refuse, workdir, spoil, mentions):
    path = write(workdir / "rules.json", spoil)
    refuse("twin", "import", "mesh", mesh_input(workdir), "--rules", path, "--out", workdir / "out",
           mentions=("rules.json", *mentions))


# --- class maps ------------------------------------------------------------------------------------------

@pytest.mark.parametrize("where, value, mentions", [
    (("classes", 1, "id"), -1, ("classes[1].id",)),
    (("classes", 1, "id"), 1.5, ("classes[1].id",)),
    (("classes", 1, "color"), [300, 0, 0], ("classes[1].color",)),
    (("classes",), {"a": 1}, ("classes",)),
    (("classes", 1, "name"), "x" * 10_000, ("classes[1].name",)),
])
def test_classmap_refused(refuse, run_cli, workdir, where, value, mentions):
    """``validate classes`` reports schema violations as findings (exit 1); ``--class-map`` refuses."""
    path = write(workdir / "classes.json", _spoiled(CLASSMAP, where, value))
    code, out, err = run_cli("validate", "classes", path)
    assert code == 1 and "Traceback" not in err, (code, out, err)
    assert mentions[0] in out, out
    refuse("twin", "import", "footprints", GEOJSON, "--class-map", path, "--out", workdir / "out",
           mentions=("classes.json", *mentions))


@pytest.mark.parametrize("content", ["[1, 2, 3]", '"hello"', "null"])
def test_validate_classes_not_a_class_map(run_cli, workdir, content):
    path = write(workdir / "classes.json", content)
    code, out, err = run_cli("validate", "classes", path)
    assert code == 1 and "Traceback" not in err and "(document)" in out, (code, out, err)
