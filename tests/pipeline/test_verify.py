"""``synthua verify`` and ``synthua replay`` on damaged and malformed datasets: replay compares the re-render
with the files on disk, verify reports files the manifest does not list, and a malformed manifest,
generate.json, record or annotation document is one line or a listed problem, never an internal error."""

from __future__ import annotations

import hashlib
import json
import shutil
from pathlib import Path

import pytest

from synthua_usd.pipeline.verify import verify


def _names(root: Path) -> list[str]:
    return [img["name"] for img in json.loads((root / "manifest.json").read_text())["images"]]


def _rewrite_with_checksum(root: Path, relative: str, content: bytes) -> None:
    """Replace a file and make the manifest agree with it: only the checks beyond checksums can notice."""
    (root / relative).write_bytes(content)
    manifest = json.loads((root / "manifest.json").read_text())
    for entry in manifest["dataset_files"] + [e for img in manifest["images"] for e in img["files"]]:
        if entry["path"] == relative:
            entry["sha256"], entry["bytes"] = hashlib.sha256(content).hexdigest(), len(content)
    (root / "manifest.json").write_text(json.dumps(manifest))


def test_replay_compares_the_re_render_with_the_files_on_disk(generated_copy, run_cli):
    """class.png overwritten after generation (its record's checksums unchanged): replay says which file differs."""
    first, second = _names(generated_copy)[:2]
    target = f"frames/{second}/class.png"
    shutil.copyfile(generated_copy / "frames" / first / "class.png", generated_copy / target)
    image_id = json.loads((generated_copy / "records" / f"{second}.json").read_text())["id"]
    code, out, err = run_cli("replay", generated_copy, str(image_id))
    assert code == 1, out + err
    assert f"differs: {target}" in out.splitlines() and "byte-identical" not in out, out


def test_replay_of_an_image_whose_file_is_missing_says_so(generated_copy, run_cli):
    name = _names(generated_copy)[1]
    (generated_copy / "frames" / name / "instance.png").unlink()
    image_id = json.loads((generated_copy / "records" / f"{name}.json").read_text())["id"]
    code, out, _ = run_cli("replay", generated_copy, str(image_id))
    assert code == 1 and f"differs: frames/{name}/instance.png" in out, out


def test_verify_reports_files_the_manifest_does_not_list(generated_copy, run_cli):
    (generated_copy / "notes.txt").write_text("mine")
    (generated_copy / "frames" / "x").mkdir()
    (generated_copy / "frames" / "x" / ".hidden").write_text("")
    (generated_copy / "link.png").symlink_to(generated_copy / "manifest.json")
    code, out, _ = run_cli("verify", generated_copy)
    assert code == 1
    problems = [line for line in out.splitlines() if line.startswith("problem:")]
    for rel in ("notes.txt", "frames/x/.hidden", "link.png"):
        assert any(rel in line and "not listed in the manifest" in line for line in problems), out
    assert len(problems) == 3, out


@pytest.mark.parametrize("spoil,mentions", [
    (lambda m: m | {"images": {"a": 1}}, ("manifest.json", "images")),
    (lambda m: m | {"images": [m["images"][0] | {"files": "all"}]}, ("manifest.json", "images[0].files")),
    (lambda m: m | {"dataset_files": [{"path": "x"}]}, ("manifest.json", "dataset_files[0]")),
    (lambda m: [m], ("manifest.json",)),
    (lambda m: "[" * 100_000 + "]" * 100_000, ("manifest.json", "nested")),
])
def test_a_malformed_manifest_is_one_line_naming_it(generated_copy, spoil, mentions, run_cli):
    manifest = json.loads((generated_copy / "manifest.json").read_text())
    spoiled = spoil(manifest)
    (generated_copy / "manifest.json").write_text(spoiled if isinstance(spoiled, str) else json.dumps(spoiled))
    for command in (["verify", generated_copy], ["stats", generated_copy, "--out", generated_copy.parent / "report"]):
        code, _, err = run_cli(*command)
        lines = err.strip().splitlines()
        assert code == 2 and len(lines) == 1 and lines[0].startswith("synthua: error: "), err
        assert all(m in lines[0] for m in mentions), lines[0]


@pytest.mark.parametrize("plan", [{"a": 1}, [{"id": "one"}], [{"id": 1, "bogus": 2}]])
def test_a_malformed_generate_json_is_one_line_naming_it(generated_copy, plan, run_cli):
    job = json.loads((generated_copy / "generate.json").read_text())
    (generated_copy / "generate.json").write_text(json.dumps(job | {"plan": plan}))
    commands = [["replay", generated_copy, "1"]] + ([["verify", generated_copy]] if not isinstance(plan, list) or
                                         not isinstance(plan[0]["id"], int) else [])
    for command in commands:
        code, _, err = run_cli(*command)
        assert code == 2 and err.count("synthua: error:") == 1 and "generate.json" in err, err
        assert "internal error" not in err


@pytest.mark.parametrize("spoil", [
    lambda doc: doc | {"annotations": {"a": 1}},
    lambda doc: doc | {"images": "all"},
    lambda doc: [doc],
])
def test_a_malformed_coco_document_is_a_problem_not_a_crash(generated_copy, spoil):
    relative = "annotations/instances_train.json"
    doc = json.loads((generated_copy / relative).read_text())
    _rewrite_with_checksum(generated_copy, relative, json.dumps(spoil(doc)).encode())
    result = verify(generated_copy)
    assert any(relative in p and "not a COCO instances document" in p for p in result.problems), result.problems


@pytest.mark.parametrize("counts", ["!!garbage!!", "o", "PPYo0"])
def test_garbage_rle_in_the_dataset_is_a_problem_before_pycocotools_reads_it(generated_copy, counts):
    relative = "annotations/instances_train.json"
    doc = json.loads((generated_copy / relative).read_text())
    doc["annotations"][0]["segmentation"]["counts"] = counts
    _rewrite_with_checksum(generated_copy, relative, json.dumps(doc).encode())
    result = verify(generated_copy)
    assert any("segmentation: counts" in p for p in result.problems), result.problems


def test_a_record_that_is_not_a_record_is_a_problem(generated_copy):
    name = _names(generated_copy)[0]
    _rewrite_with_checksum(generated_copy, f"records/{name}.json", json.dumps({"id": "x"}).encode())
    result = verify(generated_copy)
    assert any(f"records/{name}.json: not an image record" in p for p in result.problems), result.problems


@pytest.mark.parametrize("spoil, field", [
    (lambda r: r["qa"].update(verdict="maybe"), "qa.verdict"),
    (lambda r: r["instances"][0].update(bbox="everywhere"), "instances[0].bbox"),
    (lambda r: r["files"].pop("instance"), "files"),
    (lambda r: r.update(surprise=1), "surprise"),
])
def test_a_hand_corrupted_record_is_a_problem_naming_its_field(generated_copy, spoil, field):
    """Every record verify reads is validated against schemas/record.schema.json: a malformed one is one problem
    naming the record and the field (its checksum made to agree, so only the validation can notice)."""
    name = _names(generated_copy)[0]
    relative = f"records/{name}.json"
    record = json.loads((generated_copy / relative).read_text())
    spoil(record)
    _rewrite_with_checksum(generated_copy, relative, json.dumps(record).encode())
    result = verify(generated_copy)
    assert [p for p in result.problems if p.startswith(f"{relative}: not an image record: {field}: ")], result.problems
    assert result.images == len(_names(generated_copy)) - 1
