"""Which of a model's classes score as which class of a test set.

A real test set names its classes its own way (``wheelchair``, ``pedestrian``); a model trained on a generated
dataset predicts our classes (``manual_wheelchair``, ``electric_wheelchair``, ``person``). A mapping says, per test
class, the model classes whose detections count as it: ``--map wheelchair=manual_wheelchair,electric_wheelchair
--map person=person``. Test classes mapped to nothing are not scored (their boxes are left out, neither required
nor penalised), and so are detections of model classes no test class takes.

Without ``--map``, each test class takes the model class of the same name, and a test class named in
:data:`DEFAULT_ALIASES` takes the model classes listed there (``wheelchair``: both wheelchair classes).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Iterable, Sequence

from synthua_usd.core.errors import InputError, echo

#: Test-set class names that take several of our classes when no --map is given.
DEFAULT_ALIASES = {"wheelchair": ("manual_wheelchair", "electric_wheelchair")}

_OPTION = re.compile(r"^\s*([^=,]+?)\s*=\s*([^=]+?)\s*$")


@dataclass(frozen=True)
class ClassMapping:
    """``pairs``: (test class, model classes) for each scored test class, in the test set's class order."""

    pairs: tuple[tuple[str, tuple[str, ...]], ...]

    @property
    def test_classes(self) -> tuple[str, ...]:
        return tuple(t for t, _ in self.pairs)

    def test_class_of(self) -> dict[str, str]:
        """Model class -> the test class its detections score as (model classes no test class takes are absent)."""
        return {m: t for t, models in self.pairs for m in models}

    def document(self) -> dict[str, list[str]]:
        return {t: list(models) for t, models in self.pairs}

    def text(self) -> str:
        """The mapping as --map options would give it."""
        return " ".join(f"--map {t}={','.join(models)}" for t, models in self.pairs)


def parse_map_options(options: Iterable[str]) -> dict[str, tuple[str, ...]]:
    """``TEST=MODEL[,MODEL...]`` options -> {test class: model classes}; a bad option raises :class:`InputError`."""
    out: dict[str, tuple[str, ...]] = {}
    for option in options:
        match = _OPTION.match(option)
        models = tuple(m.strip() for m in match.group(2).split(",")) if match else ()
        if not match or not all(models):
            raise InputError(f"--map: {echo(option)!r}; expected TEST_CLASS=MODEL_CLASS[,MODEL_CLASS...], e.g. "
                             f"wheelchair=manual_wheelchair,electric_wheelchair")
        test = match.group(1)
        if test in out:
            raise InputError(f"--map: {echo(test)!r} is mapped twice; expected one --map per test class")
        out[test] = models
    return out


def build_mapping(options: Sequence[str], test_names: Sequence[str], model_names: Sequence[str],
                  test_side: str = "the test set", model_side: str = "the model") -> ClassMapping:
    """The mapping of ``options`` (``--map`` values; none: same names and :data:`DEFAULT_ALIASES`) between a test
    set's classes and a model's. Every name must exist on its side, a model class may score as one test class only,
    and at least one test class must be scored. ``test_side`` and ``model_side`` name the two sides in messages."""
    given = parse_map_options(options)
    tests, models = list(test_names), set(model_names)
    model_list = ", ".join(model_names)
    for test, chosen in given.items():
        if test not in tests:
            raise InputError(f"--map {echo(test)}=...: {echo(test)!r} is not a class of {test_side}; expected one of "
                             f"{echo(', '.join(tests), 200)}")
        unknown = [m for m in chosen if m not in models]
        if unknown:
            raise InputError(f"--map {echo(test)}=...: {echo(', '.join(unknown))}: not a class of {model_side}; expected "
                             f"some of {model_list}")
    if not given:
        for test in tests:
            if test in models:
                given[test] = (test,)
            elif test in DEFAULT_ALIASES and any(m in models for m in DEFAULT_ALIASES[test]):
                given[test] = tuple(m for m in DEFAULT_ALIASES[test] if m in models)
    taken: dict[str, str] = {}
    for test, chosen in given.items():
        for m in chosen:
            if m in taken and taken[m] != test:
                raise InputError(f"--map: model class {m!r} is mapped to both {taken[m]!r} and {test!r}; expected each "
                                 f"model class in one test class")
            taken[m] = test
    if not given:
        raise InputError(f"the classes of {test_side} ({echo(', '.join(tests), 200)}) share no name with those of "
                         f"{model_side} ({model_list}); expected --map TEST_CLASS=MODEL_CLASS[,...], e.g. "
                         f"--map wheelchair=manual_wheelchair,electric_wheelchair --map person=person")
    return ClassMapping(tuple((t, tuple(dict.fromkeys(given[t]))) for t in tests if t in given))
