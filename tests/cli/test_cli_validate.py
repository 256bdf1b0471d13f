import json

from conftest import DATA, SCENARIO


def test_validate_classes_clean_exits_0(run_cli):
    code, out, err = run_cli("validate", "classes")
    assert code == 0 and out == "" and "0 errors, 0 warnings" in err


def test_validate_classes_findings_exit_1_and_name_the_entry(run_cli):
    code, out, _ = run_cli("validate", "classes", DATA / "invalid" / "rule_duplicate_color.json")
    assert code == 1
    assert "classes[2] 'person'" in out and "(unique-colors)" in out


def test_validate_classes_json_output(run_cli):
    code, out, _ = run_cli("validate", "classes", "--json", DATA / "invalid" / "schema_unknown_group.json")
    assert code == 1
    (finding,) = json.loads(out)
    assert finding == {"rule": "schema", "where": "classes[2].group", "severity": "error",
                       "message": finding["message"]}


def test_validate_classes_unusable_input_exit_2_one_line(run_cli, tmp_path):
    missing = tmp_path / "nope.json"
    code, out, err = run_cli("validate", "classes", missing)
    assert code == 2 and out == ""
    assert err.strip() == f"synthua: error: {missing}: file not found; expected a JSON document"
    code, _, err = run_cli("validate", "classes", DATA / "invalid" / "not_json.json")
    assert code == 2 and len(err.strip().splitlines()) == 1 and "not valid JSON" in err


def test_validate_stage_shipped_scenario_is_clean(run_cli):
    code, out, err = run_cli("validate", "stage", SCENARIO)
    assert code == 0, out
    assert "0 errors, 0 warnings" in err


def test_validate_stage_findings_exit_1(run_cli):
    code, out, _ = run_cli("validate", "stage", DATA / "invalid" / "unknown_label.usda")
    assert code == 1
    assert "/World/Ground: label 'spaceship' is not a class" in out


def test_validate_stage_malformed_exit_2(run_cli):
    path = DATA / "invalid" / "malformed.usda"
    code, out, err = run_cli("validate", "stage", path)
    assert code == 2 and out == ""
    assert err.startswith(f"synthua: error: {path}: not a readable USD stage")
    assert len(err.strip().splitlines()) == 1


def test_help_teaches(run_cli):
    code, out, _ = run_cli("--help")
    assert code == 0 and "synthua render stages/scenario.usda" in out
    code, out, _ = run_cli("render", "--help")
    assert code == 0 and "depth.exr (z-depth" in out


def test_usage_error_exit_2(run_cli):
    code, _, err = run_cli("render")
    assert code == 2 and "Missing argument 'SCENARIO'" in err
