"""The stage metadata a layer authored over a stage states: read from the stage, refused where it is not
metadata a stage may have."""

import pytest
from pxr import Usd

from synthua_usd.core.errors import InputError
from synthua_usd.usd.stage_io import stage_metadata


def test_stage_metadata_is_what_the_stage_states():
    stage = Usd.Stage.CreateInMemory()
    stage.SetMetadata("upAxis", "Z")
    stage.SetMetadata("metersPerUnit", 0.01)
    stage.SetTimeCodesPerSecond(30.0)
    stage.SetStartTimeCode(2.0)
    meta = stage_metadata(stage)
    # no time range (only a start): the start for both ends; no default prim: World
    assert (meta.up_axis, meta.meters_per_unit, meta.time_codes_per_second) == ("Z", 0.01, 30.0)
    assert (meta.start_time_code, meta.end_time_code, meta.default_prim) == (2.0, 2.0, "World")
    stage.SetEndTimeCode(9.0)
    stage.SetDefaultPrim(stage.DefinePrim("/Root"))
    meta = stage_metadata(stage)
    assert (meta.start_time_code, meta.end_time_code, meta.default_prim) == (2.0, 9.0, "Root")


def test_stage_metadata_refuses_what_a_stage_may_not_state():
    stage = Usd.Stage.CreateInMemory()
    stage.SetStartTimeCode(9.0)
    stage.SetEndTimeCode(2.0)
    with pytest.raises(InputError, match=r"start <= end, but were \[9.0, 2.0\]"):
        stage_metadata(stage)
