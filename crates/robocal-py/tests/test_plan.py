"""plan: the same seed gives the CLI's poses exactly, and the figures it prints."""

import time

import numpy as np
import pytest

import robocal
from conftest import example
from test_simulate import max_diff, numbers

KR = "kuka-kr480-r3330"


def printed_lines(p):
    """The table lines `robocal plan` prints for plan `p`, formatted as the CLI formats them."""
    a, b = p.planned, p.random
    lines = [
        f"{'observability index O1 (scaled Jacobian)':<44}{a.observability:>14.4f}{b.observability:>14.4f}",
        f"{'predicted workspace model error, RMS (mm)':<44}{a.workspace_rms_mm:>14.4f}{b.workspace_rms_mm:>14.4f}",
    ]
    for i, (name, unit) in enumerate(zip(p.parameters, p.units)):
        lines.append(f"{name:<12}{a.std[i]:>14.5f}{b.std[i]:>14.5f}{unit:>8}")
    return lines


def both(cli, tmp_path, robot_arg, robot, cli_args, **kw):
    c = tmp_path / "cli.csv"
    t = time.perf_counter()
    out = cli("plan", "--robot", robot_arg, "--out", str(c), *cli_args)
    tc = time.perf_counter() - t
    t = time.perf_counter()
    p = robocal.plan(robot, **kw)
    tp = time.perf_counter() - t
    dof = robot.dof
    d = max_diff(p.poses, numbers(c, [f"q{i}" for i in range(1, dof + 1)]))
    assert d == 0.0, d
    assert p.to_csv() == c.read_text()
    p.write(tmp_path / "py.csv")
    assert (tmp_path / "py.csv").read_bytes() == c.read_bytes()
    for line in printed_lines(p):
        assert line in out, f"{line!r} not in the CLI's output:\n{out}"
    return p, tc, tp


def test_default_plan_is_the_cli(cli, tmp_path):
    kr = robocal.Robot.preset(KR)
    p, tc, tp = both(cli, tmp_path, KR, kr, ["--poses", "75", "--seed", "1"], poses=75, seed=1)
    print(f"\nplan 75 of 10000 candidates: Python {tp * 1e3:.0f} ms, the whole CLI process {tc * 1e3:.0f} ms")
    assert p.poses.shape == (75, 6) and len(p) == 75
    assert p.criterion == "workspace" and p.candidates == 10000 and p.seed == 1
    assert p.planned.observability > p.random.observability > 0
    assert p.planned.workspace_rms_mm < p.random.workspace_rms_mm
    assert len(p.parameters) == len(p.planned.std) == len(p.units) == len(p.stds)
    assert "d2" not in p.parameters or "d3" not in p.parameters
    assert robocal.Robot.preset(KR).within_limits(p.poses).all()


def test_every_option_is_the_cli(cli, tmp_path):
    kr = robocal.Robot.preset(KR)
    inc = tmp_path / "include.csv"
    cli("plan", "--robot", KR, "--poses", "26", "--candidates", "300", "--seed", "8", "--out", str(inc))
    included = numbers(inc, [f"q{i}" for i in range(1, 7)])
    args = ["--poses", "30", "--candidates", "3000", "--seed", "4", "--criterion", "d-optimal",
            "--tracker", "3000,-2000,1000,120,0,0", "--range-mm", "1500,5500", "--include", str(inc),
            "--floor-mm", "300", "--footprint-mm", "800", "--noise-mm", "0.02", "--noise-per-m", "0.01"]
    kw = dict(poses=30, candidates=3000, seed=4, criterion="d-optimal", tracker=(3000, -2000, 1000, 120, 0, 0),
              range_mm=(1500, 5500), floor_mm=300, footprint_mm=800, noise_mm=0.02, noise_per_m=0.01)
    p, _, _ = both(cli, tmp_path, KR, kr, args, include=included, **kw)
    assert p.included == 26 and p.criterion == "d-optimal" and p.noise == (0.02, 0.01)
    # The included poses as the file: the same plan.
    again = robocal.plan(kr, include=inc, **kw)
    assert max_diff(again.poses, p.poses) == 0.0
    # Every pose within the tracker's range.
    tool = kr.fk(p.poses)
    d = np.linalg.norm(tool - np.array([3000, -2000, 1000]), axis=1)
    assert d.min() >= 1500 and d.max() <= 5500


@pytest.mark.parametrize("robot_file", ["ur5.toml", "kr480-track.toml"])
def test_robot_file_plan_is_the_cli(cli, tmp_path, robot_file):
    """Standard DH, and a prismatic track (its poses in mm)."""
    robot = robocal.Robot.from_file(example(robot_file))
    both(cli, tmp_path, example(robot_file), robot, ["--poses", "40", "--candidates", "2000", "--seed", "3"],
         poses=40, candidates=2000, seed=3)


def test_plan_then_simulate_then_calibrate(tmp_path):
    """The paper's experiment on planned poses, all in Python."""
    kr = robocal.Robot.preset(KR)
    p = robocal.plan(kr, 75, candidates=3000, seed=2)
    sim = robocal.simulate(kr, "kuka-kr480-r3330-table3", joints=p.poses, seed=7)
    assert max_diff(sim.q, p.poses) == 0.0
    val = robocal.simulate(kr, "kuka-kr480-r3330-table3", 73, plane=False, seed=8)
    res = robocal.calibrate(kr, sim.q, sim.xyz, validate=(val.q, val.xyz))
    assert res.errors["validation"]["after"]["mean_mm"] < 0.1 < res.errors["validation"]["before"]["mean_mm"]
