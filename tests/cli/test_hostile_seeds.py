"""One seed range, one owner (``synthua_usd.model.ranges.SEED``): every command's ``--seed`` and every seed of a
config takes the same integers, so the ``synthua render --seed N`` that ``synthua randomise`` prints for a dataset
image always runs; a seed past the range is one line naming the option."""

from __future__ import annotations

import click
import pytest

from conftest import DATA
from synthua_usd.cli.main import cli
from synthua_usd.cli.options import InRange
from synthua_usd.core.schemas import load_schema
from synthua_usd.model.ranges import SEED
from synthua_usd.model.render_config import sampler_seed

TINY = DATA / "valid" / "tiny_scene.usda"


def _seed_options(group: click.Group, path: str = "synthua") -> dict[str, click.Parameter]:
    out = {}
    for name, command in group.commands.items():
        where = f"{path} {name}"
        if isinstance(command, click.Group):
            out |= _seed_options(command, where)
        out |= {where: p for p in command.params if p.name == "seed"}
    return out


def test_every_seed_option_takes_the_one_range():
    """render and contact-sheet took seeds below 2^31, train too, while randomise printed render commands with
    seeds up to 2^32-1."""
    options = _seed_options(cli)
    assert {"synthua render", "synthua randomise", "synthua contact-sheet", "synthua train"} <= set(options)
    wrong = {where: str(p.type) for where, p in options.items()
             if not (isinstance(p.type, InRange) and p.type.allowed == SEED)}
    assert wrong == {}, wrong


def test_the_config_schema_states_the_same_seed_range():
    found = []

    def walk(node, where):
        if isinstance(node, dict):
            if "seed" in where.rsplit("/", 1)[-1] and ("maximum" in node or "items" in node):
                item = node.get("items", node)
                found.append((where, item.get("minimum"), item.get("maximum")))
            for key, value in node.items():
                walk(value, f"{where}/{key}")
        elif isinstance(node, list):
            for k, value in enumerate(node):
                walk(value, f"{where}/{k}")

    walk(load_schema("generate"), "")
    assert len(found) >= 4 and all((lo, hi) == (SEED.low, SEED.high) for _, lo, hi in found), found


def test_render_takes_the_largest_seed(run_cli, tmp_path):
    """render refused 2^32-1 (its range ended at 2^31-1), and a seed above 42,948 failed inside Mitsuba (exit 3:
    the pass seed seed * 100003 + k no longer fit 32 bits)."""
    for seed in (100_000, SEED.high):
        code, out, err = run_cli("render", TINY, "--camera", "/World/Cam", "--width", "8", "--height", "6", "--spp",
                                 "1", "--seed", seed, "--out", tmp_path / str(seed))
        assert code == 0 and "Traceback" not in err, err
        assert (tmp_path / str(seed) / "rgb.png").is_file()


@pytest.mark.parametrize("command", [["render", TINY, "--camera", "/World/Cam"], ["contact-sheet", TINY],
                                     ["train", "set"], ["agents", "populate", TINY], ["twin", "demo"]])
def test_a_seed_past_the_range_is_one_line(refuse, workdir, command):
    refuse(*command, "--seed", str(SEED.high + 1), "--out", workdir / "new.png",
           mentions=("--seed", f"[0, {SEED.high}]"))


def test_sampler_seeds_fit_32_bits_and_keep_the_earlier_ones():
    """Seeds below 42,949 keep the pass seeds every earlier image was rendered with (same bytes); every seed's
    passes fit Mitsuba's 32-bit seed."""
    assert [sampler_seed(7, k) for k in range(3)] == [700_021, 700_022, 700_023]
    assert sampler_seed(42_948, 2) == 42_948 * 100_003 + 2
    assert all(0 <= sampler_seed(s, k) < 2**32 for s in (42_949, 2**31, SEED.high) for k in (0, 4095))
    assert len({sampler_seed(s, 0) for s in range(0, 2**32, 2**20)}) == 2**12  # distinct seeds, distinct passes
