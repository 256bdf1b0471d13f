
import numpy as np
import pytest

from conftest import DATA
from synthua_usd.core.findings import Severity
from synthua_usd.core.schemas import bundled_path, read_json
from synthua_usd.model.classmap_checks import MIN_CIEDE2000, check_classmap, ciede2000_matrix

CASES = {
    "schema_missing_color": ("schema", "classes[1]", "'color' is a required property"),
    "schema_color_out_of_range": ("schema", "classes[1].color[0]", "300 is greater than the maximum of 255"),
    "schema_unknown_group": ("schema", "classes[2].group", "'robots' is not one of"),
    "schema_unknown_key": ("schema", "classes[2]", "Additional properties are not allowed ('colour'"),
    "rule_duplicate_id": ("unique-ids", "classes[2] 'person'", "id 1 is already used by classes[1] 'road'"),
    "rule_duplicate_alias": ("unique-names", "classes[2] 'person'", "alias 'Road' is the same (ignoring case)"),
    "rule_duplicate_color": ("unique-colors", "classes[2] 'person'", "colour [128, 64, 128] is already used"),
    "rule_void_not_black": ("void-class", "classes[0] 'unlabelled'", "id 0 has colour [10, 10, 10]"),
    "rule_no_void": ("void-class", "classes", "no class with id 0"),
    "rule_close_colors": ("color-distance", "classes[2] 'person'", "CIEDE2000 from classes[1] 'road'"),
}


def test_bundled_class_map_is_clean():
    assert check_classmap(read_json(bundled_path("classmap.json"))) == []


def test_small_valid_map_is_clean():
    assert check_classmap(read_json(DATA / "valid" / "classmap_small.json")) == []


@pytest.mark.parametrize("name", sorted(CASES))
def test_each_bad_map_gives_its_finding(name):
    rule, where, text = CASES[name]
    findings = check_classmap(read_json(DATA / "invalid" / f"{name}.json"))
    matching = [f for f in findings if f.rule == rule and f.where == where and text in f.message]
    assert matching, [f.format() for f in findings]


def test_close_colour_is_a_warning_with_the_distance():
    (finding,) = check_classmap(read_json(DATA / "invalid" / "rule_close_colors.json"))
    assert finding.severity is Severity.WARNING
    assert "expected at least 10" in finding.message


def test_bundled_colours_are_at_least_the_minimum_apart(class_map):
    colors = np.array([c.color for c in class_map.classes])
    dist = ciede2000_matrix(colors)
    off_diagonal = dist[~np.eye(len(colors), dtype=bool)]
    assert off_diagonal.min() >= MIN_CIEDE2000


def test_ciede2000_matrix_is_a_sane_distance():
    # colour-science implements CIEDE2000 itself (and tests it on Sharma's data); here we check our use
    # of it: zero diagonal, symmetry, and near colours closer than far ones.
    colors = np.array([[10, 200, 30], [12, 198, 33], [200, 10, 30]])
    dist = ciede2000_matrix(colors)
    assert np.allclose(np.diag(dist), 0)
    assert np.allclose(dist, dist.T)
    assert dist[0, 1] < 2.0 < dist[0, 2]
