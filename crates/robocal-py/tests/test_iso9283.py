"""iso9283_plan and iso9283_evaluate: the CLI's plan CSV, program and figures exactly; the
library's settings checks with the keywords named; bad input as the CLI's exit codes."""

import json

import numpy as np
import pytest

import robocal
from conftest import example

KR = "kuka-kr480-r3330"


def test_plan_is_the_cli(cli, tmp_path):
    kr = robocal.Robot.preset(KR)
    c, prog = tmp_path / "cli.csv", tmp_path / "cli.src"
    cli("iso9283", "plan", "--robot", KR, "--cycles", "4", "--floor-mm", "500",
        "--out", str(c), "--program", str(prog), "--dwell-s", "1.5")
    p = robocal.iso9283_plan(kr, cycles=4, floor_mm=500)
    assert p.to_csv() == c.read_text()
    assert p.program("krl", dwell_s=1.5) == prog.read_text()
    p.write(tmp_path / "py.csv")
    assert (tmp_path / "py.csv").read_bytes() == c.read_bytes()
    assert p.cycles == 4 and not p.compensated
    assert p.poses.shape == (5, 6) and p.joints.shape == (5, 6)
    np.testing.assert_array_equal(p.joints, p.nominal_joints)
    # P1 the centre; the whole cube above the floor; every pose reached on the nominal model.
    assert np.allclose(p.poses[0, :3], p.centre, atol=1e-9)
    assert p.centre[2] - p.edge_mm / 2 >= 500
    assert np.abs(kr.fk(p.joints) - p.poses[:, :3]).max() < 1e-6
    assert "Iso9283Plan(cube of" in repr(p)


def test_compensated_plan_and_evaluation_are_the_cli(cli, tmp_path):
    ur5 = robocal.Robot.from_file(example("ur5.toml"))
    res_path = tmp_path / "r.json"
    cli("calibrate", "--robot", example("ur5.toml"), "--data", example("data/ur5-cell.csv"),
        "--out", str(res_path))
    res = robocal.Result.read(res_path)
    before = robocal.iso9283_plan(ur5, cycles=5, cube_mm=400.0)
    # The same poses after calibration, compensated; as the CLI's --poses-from.
    after = robocal.iso9283_plan(result=res, cycles=5, poses_from=before)
    assert after.compensated and not before.compensated
    np.testing.assert_allclose(after.poses, before.poses, atol=1e-9)
    np.testing.assert_allclose(after.nominal_joints, before.nominal_joints, atol=1e-6)
    assert np.abs(after.joints - before.joints).max() > 1e-3
    before.write(tmp_path / "before.csv")
    cli("iso9283", "plan", "--params", str(res_path), "--cycles", "5", "--poses-from",
        str(tmp_path / "before.csv"), "--out", str(tmp_path / "after-cli.csv"))
    # The CLI reads the cube back from the CSV: the same numbers to rounding.
    a = np.genfromtxt(tmp_path / "after-cli.csv", delimiter=",", skip_header=1)
    b = np.genfromtxt(after.to_csv().splitlines(), delimiter=",", skip_header=1)
    np.testing.assert_array_equal(a[:, :2], b[:, :2])
    np.testing.assert_allclose(a[:, 2:], b[:, 2:], rtol=0, atol=1e-8)
    with pytest.raises(robocal.UsageError):
        robocal.iso9283_plan(result=res, poses_from=before, cube_mm=100.0)
    plan = tmp_path / "plan.csv"
    after.write(plan)
    meas = tmp_path / "meas.csv"
    cli("simulate", "--robot", example("ur5.toml"), "--truth",
        example("data/ur5-cell.truth.json"), "--joints", str(plan), "--repeatability-deg",
        "0.001", "--seed", "3", "--out", str(meas))
    out = cli("iso9283", "evaluate", "--plan", str(plan), "--data", str(meas), "--params",
              str(res_path), "--json")
    ev = robocal.iso9283_evaluate(plan, meas, res)
    assert ev == json.loads(out)
    assert ev["pass"] is None and len(ev["poses"]) == 5
    # A spec that fails is a result (the CLI exits 7 with the same JSON).
    worst = max(p["ap_mm"] for p in ev["poses"])
    failed = robocal.iso9283_evaluate(plan, meas, res, spec=f"ap={worst / 2}")
    assert failed["pass"] is False
    passed = robocal.iso9283_evaluate(plan, meas, res, spec=f"ap={worst * 2},rp=10")
    assert passed["pass"] is True


def test_settings_refused_with_keywords(tmp_path):
    kr = robocal.Robot.preset(KR)
    for kw, name in [({"cycles": 1}, "cycles"), ({"cube_mm": -5.0}, "cube_mm"),
                     ({"footprint_mm": -1.0}, "footprint_mm"), ({"floor_mm": float("nan")}, "floor_mm"),
                     ({"center": [1.0, 2.0]}, "center")]:
        with pytest.raises(robocal.RobocalError) as e:
            robocal.iso9283_plan(kr, **kw)
        assert str(e.value).startswith(name), str(e.value)
        assert e.value.exit_code in (2, 3)
    with pytest.raises(robocal.InputError) as e:
        robocal.iso9283_plan(kr, center=[400.0, 0.0, -300.0], cube_mm=100.0)
    assert "below the floor" in str(e.value)
    p = robocal.iso9283_plan(kr, cycles=2)
    with pytest.raises(robocal.UsageError):
        p.program("gcode")
    with pytest.raises(robocal.InputError) as e:
        p.program("rapid", dwell_s=-1)
    assert str(e.value).startswith("dwell_s")
    with pytest.raises(robocal.UsageError):
        robocal.iso9283_plan()
    plan = tmp_path / "plan.csv"
    p.write(plan)
    with pytest.raises(robocal.UsageError):
        robocal.iso9283_evaluate(plan, plan)
    # Data without readings: bad input naming the file.
    with pytest.raises(robocal.InputError) as e:
        robocal.iso9283_evaluate(plan, plan, robot=kr, frame="base")
    assert "plan.csv" in str(e.value)
    with pytest.raises(robocal.FileError):
        robocal.iso9283_evaluate(tmp_path / "none.csv", plan, robot=kr, frame="base")
    with pytest.raises(robocal.InputError) as e:
        robocal.iso9283_evaluate(plan, plan, robot=kr, frame="base", spec="ap=fast")
    assert str(e.value).startswith("spec")
