"""`cosim validate` contract: JSON fields for outside checks, table output, bad input exits 2."""

import json

import pytest

from cosim.cli.main import main
from cosim.cli.validate import _parse_setting


def test_json_contract_of_each_case(capsys, tmp_path):
    rc = main(["validate", "hydrostatic", "slosh", "dam-break", "--spacing", "0.0125", "--fill", "0.06", "--width", "0.1",
               "--json", "--out", str(tmp_path)])
    assert rc == 0
    doc = json.loads(capsys.readouterr().out)
    cases = {c["case"]: c for c in doc["cases"]}
    assert set(cases) == {"hydrostatic", "slosh", "dam-break"}
    hydro = cases["hydrostatic"]
    assert len(hydro["z"]) == len(hydro["pressure"]) > 0 and isinstance(hydro["leaked"], int)
    assert all(z > 0 for z in hydro["z"]) and all(p > 0 for p in hydro["pressure"])
    assert cases["slosh"]["frequency_hz"] > 0
    dam = cases["dam-break"]
    assert dam["a"] == pytest.approx(0.1)
    assert len(dam["t"]) == len(dam["front"]) > 10
    assert dam["front"][0] == pytest.approx(0.1, rel=0.01)  # the column's own width at release
    assert dam["front"][-1] > 2 * dam["front"][0]
    for case in doc["cases"]:
        assert {"passed", "wall_time_s", "parameters", "metrics"} <= set(case)
        assert case["parameters"]["spacing"] == pytest.approx(0.0125)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dam-break-2d.png", "hydrostatic-2d.png", "slosh-A0.060-2d.png"]


def test_gate_speed_reaches_the_dam_break(capsys):
    assert main(["validate", "dam-break", "--spacing", "0.0125", "--width", "0.1", "--gate-speed", "1.0", "--json", "--no-plot"]) == 0
    case = json.loads(capsys.readouterr().out)["cases"][0]
    assert case["parameters"]["gate_speed"] == 1.0
    assert case["gate_lift"][:5] == pytest.approx([1.0 * t for t in case["t"][:5]])  # rising at 1 m/s from the release
    assert case["gate_lift"][-1] < case["t"][-1]  # then stopped clear of the liquid
    assert len(case["tip_height"]) == len(case["front"]) == len(case["t"])
    assert case["height"] == pytest.approx(0.2)  # 2 a, the reference experiment's column, a = 0.1 m
    assert case["lauber_hager_speed"] == pytest.approx((9.81 * 0.2 / 2) ** 0.5, rel=1e-3)  # sqrt(g H / 2)


def test_table_output(capsys, tmp_path):
    assert main(["validate", "hydrostatic", "--spacing", "0.0125", "--width", "0.1", "--fill", "0.05", "--no-plot"]) == 0
    out = capsys.readouterr().out
    assert "pressure (worst probe)" in out and "vertical reaction" in out


def test_density_tolerance_reaches_the_solver(capsys):
    argv = ["validate", "hydrostatic", "--spacing", "0.0125", "--width", "0.1", "--fill", "0.05", "--no-plot", "--json"]
    assert main(argv) == 0
    default = json.loads(capsys.readouterr().out)["cases"][0]
    assert main([*argv, "--density-tolerance", "1e-5"]) == 0
    tight = json.loads(capsys.readouterr().out)["cases"][0]
    assert tight["max_density_error"] < default["max_density_error"]


@pytest.mark.slow
def test_a_tank_rounded_to_whole_spacings_says_so(capsys):
    assert main(["validate", "dam-break", "--dim", "3", "--width", "0.05", "--spacing", "0.006", "--json", "--no-plot"]) == 0
    captured = capsys.readouterr()
    case = json.loads(captured.out)["cases"][0]
    assert case["parameters"]["depth"] == pytest.approx(17 * 0.006)  # 0.1 m is 16.7 spacings
    assert case["a"] == pytest.approx(8 * 0.006)  # 8.33 spacings: the column is 8 wide, and T and Z are scaled by it
    assert "depth 0.102 m: 0.1 m rounded to whole particle spacings" in captured.err
    assert "width 0.048 m: 0.05 m rounded to whole particle spacings" in captured.err


@pytest.mark.parametrize("argv", [["validate", "nope"], ["validate", "slosh", "--width", "-1"], ["validate", "--spacing", "nan"],
                                  ["validate", "hydrostatic", "--device", "tpu"], ["validate", "--density-tolerance", "-1"],
                                  ["validate", "slosh-plant", "--shape", "cylinder"], ["validate", "slosh-plant", "--spacing", "0.05"],
                                  ["validate", "dam-break", "--gate-speed", "0"], ["validate", "dam-break", "--gate-speed", "inf"],
                                  ["validate", "hydrostatic", "--free-liquid", "maybe"],
                                  # refused before the first case prints its progress line
                                  ["validate", "hydrostatic", "--spacing", "0.05"], ["validate", "slosh", "dam-break", "--spacing", "0.05"],
                                  ["validate", "hydrostatic", "--scene", "/nonexistent/scene.toml"]])
def test_bad_input_exits_2_with_one_line(argv, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("cosim validate: error:")


@pytest.mark.parametrize(("text", "value"), [("true", True), ("False", False), (" false ", False)])
def test_a_switch_is_read_from_true_or_false(text, value):
    assert _parse_setting("free_liquid", text) is value
