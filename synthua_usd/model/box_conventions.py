"""Named box conventions: how a detection set boxes the people who use mobility aids, the one place that says what
``--convention NAME`` means (``synthua train``, ``synthua evaluate-real``, ``synthua stats --compare``,
``tools/sim2real.py``). Plain data, so that the command line builds its options without loading the readers;
:func:`synthua_usd.analytics.detection_targets.targets_for` turns a convention into the boxes drawn from a generated
dataset's records.

* ``synthua`` (the default): every visible person is a ``person`` box, an aid user too (COCO's convention, and what
  a pedestrian detector must find); a mobility aid's box covers the aid and its user; person and the eight aids.
* ``wheelchair-sets``: as the public wheelchair photo sets box them (lexra/wheelchair, the set in
  ``../shared/data/real_photos/wheelchair_dev``, and most others): a ``wheelchair`` box covers the chair *and the
  person seated in it*, who has no ``person`` box; the classes are person and the two wheelchairs, so the users of
  walkers, crutches and canes, on foot, stay persons. The same as ``--aid-box with_user --no-aid-users-as-person
  --classes person,manual_wheelchair,electric_wheelchair``.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class BoxConvention:
    """``aid_box`` (``with_user`` or ``device``) and ``aid_users_as_person`` as
    :class:`~synthua_usd.analytics.detection_targets.DetectionTargets` takes them; ``classes`` the classes trained
    under it unless others are asked for (None: person and every mobility aid); ``about`` what it means, one
    sentence for --help."""

    aid_box: str
    aid_users_as_person: bool
    classes: tuple[str, ...] | None
    about: str


#: The named conventions, by the name ``--convention`` takes.
CONVENTIONS = {
    "synthua": BoxConvention(
        "with_user", True, None,
        "every visible person is a person box, an aid user too (COCO's convention); a mobility aid's box covers the "
        "aid and its user; classes person and the eight aids"),
    "wheelchair-sets": BoxConvention(
        "with_user", False, ("person", "manual_wheelchair", "electric_wheelchair"),
        "as the public wheelchair photo sets box them: a wheelchair's box covers the chair and the person seated in "
        "it, who has no person box; classes person and the two wheelchairs, so the users of walkers, crutches and "
        "canes, on foot, are persons (--aid-box with_user --no-aid-users-as-person --classes "
        "person,manual_wheelchair,electric_wheelchair)"),
}
DEFAULT_CONVENTION = "synthua"
