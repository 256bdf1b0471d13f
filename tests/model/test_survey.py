import math

import numpy as np
import pytest

from conftest import DATA
from synthua_usd.core.errors import InputError
from synthua_usd.model.survey import FlightPlanInput, footprint_m, gcp_report, plan_flight, read_points_csv


def test_paper_footprint_reproduces():
    # SYNTHUA-DT: h = 150 m, theta = 84 degrees -> W ~ 270 m; 80 % lateral overlap -> D ~ 54 m.
    w = footprint_m(150, 84)
    assert w == pytest.approx(270.1, abs=0.05)
    plan = plan_flight(FlightPlanInput(150, 84, 0.7, 0.8, 1000, 1000))
    assert plan.lateral_spacing_m == pytest.approx(0.2 * w)
    assert plan.lateral_spacing_m == pytest.approx(54.0, abs=0.05)
    assert plan.frontal_spacing_m == pytest.approx(0.3 * w)


def test_image_count_by_hand():
    # W = 2*100*tan(45 deg) = 200 m; frontal 50 % -> 100 m, lateral 75 % -> 50 m.
    plan = plan_flight(FlightPlanInput(100, 90, 0.5, 0.75, area_width_m=210, area_length_m=300))
    assert plan.footprint_m == pytest.approx(200.0)
    assert plan.flight_lines == math.ceil(210 / 50) + 1 == 6
    assert plan.images_per_line == 300 // 100 + 1 == 4
    assert plan.images == 24


def test_gsd_by_hand():
    # Mavic 2 Pro: 13.2 mm sensor, 10.26 mm lens, 5472 px at 150 m -> 3.53 cm/px.
    plan = plan_flight(FlightPlanInput(150, 84, 0.7, 0.8, 100, 100, 13.2, 10.26, 5472))
    assert plan.gsd_m == pytest.approx(13.2 * 150 / (10.26 * 5472))
    assert plan.gsd_m == pytest.approx(0.0353, abs=1e-4)


@pytest.mark.parametrize("kwargs,text", [
    (dict(altitude_m=0), "altitude_m: 0; expected a number in [1, 20000] m"),
    (dict(fov_deg=180), "fov_deg: 180; expected a number in [1, 170] deg"),
    (dict(frontal_overlap=1.0), "frontal_overlap: 1; expected a number in [0, 0.95]"),
    (dict(sensor_width_mm=13.2), "go together"),
])
def test_bad_flight_inputs(kwargs, text):
    args = dict(altitude_m=150, fov_deg=84, frontal_overlap=0.7, lateral_overlap=0.8, area_width_m=1, area_length_m=1)
    args.update(kwargs)
    with pytest.raises(InputError, match=text.replace("(", r"\(").replace("[", r"\[").replace(")", r"\)")):
        FlightPlanInput(**args)


def test_gcp_report_by_hand():
    report = gcp_report(read_points_csv(DATA / "valid" / "gcp_surveyed.csv"),
                        read_points_csv(DATA / "valid" / "gcp_model.csv"))
    # Errors: GCP1 sqrt(.03^2 + .04^2) = .05, GCP2 .02, GCP3 .01.
    assert report.errors_m == pytest.approx([0.05, 0.02, 0.01], abs=1e-6)
    assert report.rmse_m == pytest.approx(math.sqrt((0.05 ** 2 + 0.02 ** 2 + 0.01 ** 2) / 3), abs=1e-6)
    assert report.passed  # 0.0316 m <= 0.05 m


def test_gcp_cli_exit_codes(run_cli):
    code, out, _ = run_cli("survey", "gcp", DATA / "valid" / "gcp_surveyed.csv", DATA / "valid" / "gcp_model.csv")
    assert code == 0 and "RMSE 0.0316 m" in out and "pass" in out
    code, out, _ = run_cli("survey", "gcp", DATA / "valid" / "gcp_surveyed.csv", DATA / "valid" / "gcp_model.csv",
                           "--threshold-m", "0.02")
    assert code == 1 and "FAIL" in out


def test_flight_plan_cli(run_cli):
    code, out, _ = run_cli("survey", "flight-plan", "--altitude-m", "150", "--fov-deg", "84", "--area-width-m", "1000",
                           "--area-length-m", "1000")
    assert code == 0 and "footprint W        270.1 m" in out and "lateral spacing    54.0 m" in out


@pytest.mark.parametrize("name,text", [
    ("gcp_missing_z.csv", "missing columns ['z']"),
    ("gcp_not_number.csv", "line 2: y: 'two' is not a number; expected a number in"),
])
def test_bad_gcp_files(name, text):
    with pytest.raises(InputError, match=text.replace("[", r"\[").replace("]", r"\]")):
        read_points_csv(DATA / "invalid" / name)


def test_gcp_id_mismatch():
    a = {"A": np.zeros(3), "B": np.zeros(3)}
    with pytest.raises(InputError, match=r"only in surveyed: \['B'\]"):
        gcp_report(a, {"A": np.zeros(3)})
