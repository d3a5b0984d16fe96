"""simulate and plan: bad input raises clear robocal exceptions, never a crash."""

import re
import subprocess

import numpy as np
import pytest

import robocal
from conftest import example

KR = "kuka-kr480-r3330"


@pytest.fixture(scope="module")
def kr():
    return robocal.Robot.preset(KR)


@pytest.mark.parametrize(
    "kw, exc, words",
    [
        (dict(), robocal.UsageError, "poses: give the number of random calibration poses"),
        (dict(poses=-1), robocal.UsageError, "poses -1: must be at least 0"),
        (dict(poses=0), robocal.UsageError, "poses: at least 1, got 0"),
        (dict(poses=1.5), robocal.UsageError, "poses: expected an int, got 1.5 (float)"),
        (dict(poses=True), robocal.UsageError, "poses: expected an int"),
        (dict(poses="75"), robocal.UsageError, "poses: expected an int"),
        (dict(poses=10**30), robocal.UsageError, "poses 1000000000000000000000000000000: at most 18446744073709551615"),
        (dict(poses=20_000_000), robocal.UsageError, "poses: at most 10000000 (about 5 GB"),
        (dict(poses=10, validation=-5), robocal.UsageError, "validation -5: must be at least 0"),
        (dict(poses=6_000_000, validation=6_000_000), robocal.UsageError,
         "validation: `poses` 6000000 and `validation` 6000000 are 12000000 poses in all"),
        (dict(poses=10, seed=-1), robocal.UsageError, "seed -1: must be at least 0"),
        (dict(poses=-10**40), robocal.UsageError, "poses -10000000000000000000000000000000000000000: must be at least 0"),
        (dict(poses=10, truth="ur6"), robocal.UsageError, "truth: unknown robot preset `ur6`"),
        (dict(poses=10, truth="/nonexistent/t.truth.json"), robocal.FileError, "truth: "),
        (dict(poses=10, truth=3), robocal.UsageError, "truth: expected"),
        (dict(poses=10, truth=example("ur5.toml")), robocal.InputError, "uses dh parameters"),
        (dict(poses=10, truth="kuka-kr480-r3330-table3", length_error_mm=1.0), robocal.UsageError,
         "truth: `length_error_mm`, `angle_error_deg` and `tilt_parallel_axes` apply only to `truth` random"),
        (dict(poses=10, length_error_mm=-1.0), robocal.InputError, "length_error_mm"),
        (dict(poses=10, noise_mm=float("nan")), robocal.InputError, "noise_mm"),
        (dict(poses=10, noise_mm=-0.1), robocal.InputError, "noise_mm"),
        (dict(poses=10, tracker=(1, 2, 3)), robocal.UsageError, "tracker: expected 6 values"),
        (dict(poses=10, tracker="north"), robocal.UsageError, "tracker: expected 6 numbers"),
        (dict(poses=10, tracker=(1, 2, 3, 4, float("inf"), 6)), robocal.InputError, "tracker: B"),
        (dict(poses=10, floor_mm=float("nan")), robocal.InputError, "floor_mm"),
        (dict(poses=10, compliance=[1e-7] * 4, payload_kg=10), robocal.UsageError,
         "compliance: 4 values; give one for all joints or one per joint (6)"),
        (dict(poses=10, compliance="stiff"), robocal.UsageError, "compliance: expected a number"),
        (dict(poses=10, compliance=1e-7), robocal.InputError, "payload_kg"),
        (dict(poses=10, payload_kg=5.0), robocal.UsageError, "payload_kg: models gravity deflection: give `compliance` too"),
        (dict(poses=10, outlier_fraction=2.0), robocal.InputError, "outlier_fraction"),
        (dict(poses=10, outlier_min_mm=1.0), robocal.UsageError, "outlier_min_mm: shapes the outliers: give `outlier_fraction` too"),
        (dict(poses=10, outlier_fraction=0.1, outlier_min_mm=5, outlier_max_mm=1), robocal.InputError,
         "outlier_min_mm"),
        (dict(poses=10, outlier_fraction=0.1, orientation_sigma_deg=0.01), robocal.UsageError,
         "outliers are drawn for single points"),
        (dict(poses=10, orientation_sigma_deg=20.0), robocal.InputError, "orientation_sigma_deg: 20: not an angle noise"),
        (dict(poses=10, all_targets=True), robocal.UsageError, "all_targets: robot `"),
        (dict(poses=10, joints=np.zeros((2, 6))), robocal.UsageError, "poses: not with given joints"),
        (dict(joints=np.zeros((2, 6)), validation=3), robocal.UsageError, "validation: not with given joints"),
    ],
)
def test_bad_simulate_arguments(kr, kw, exc, words):
    kw.setdefault("truth", "random")
    truth = kw.pop("truth")
    with pytest.raises(exc) as e:
        robocal.simulate(kr, truth, **kw)
    assert words in str(e.value), str(e.value)
    assert e.value.exit_code in (2, 3, 4)


@pytest.mark.parametrize(
    "joints, words",
    [
        (np.zeros((4, 5)), "joints: expected shape (n, 6)"),
        (np.zeros((2, 3, 6)), "got (2, 3, 6)"),
        (np.array([["a"] * 6]), "dtype <U1"),
        (np.zeros((1, 6), dtype=complex), "dtype complex128"),
        (np.array([[0, 0, np.nan, 0, 0, 0]]), "joints: row 0, column 2: NaN is not a finite number"),
        (np.array([[0, 0, 0, 0, 1e300, 0]]), "joints: row 0, column 4"),
        ("/nonexistent/joints.csv", "joints.csv"),
    ],
)
def test_bad_joints(kr, joints, words):
    with pytest.raises((robocal.InputError, robocal.FileError)) as e:
        robocal.simulate(kr, "random", joints=joints)
    assert words in str(e.value), str(e.value)


def test_no_joints_and_joints_outside_limits(kr):
    with pytest.raises(robocal.InputError, match="no data rows"):
        robocal.simulate(kr, "random", joints=np.zeros((0, 6)))
    q = np.zeros((2, 6))
    q[1, 0] = 200.0
    with pytest.warns(RuntimeWarning, match="q1 outside the joint limits"):
        sim = robocal.simulate(kr, "random", joints=q)
    assert len(sim) == 2


def test_write_refuses_what_the_cli_refuses(kr, tmp_path):
    sim = robocal.simulate(kr, "random", 10)
    with pytest.raises(robocal.UsageError, match="no validation rows"):
        sim.write(tmp_path / "a.csv", tmp_path / "v.csv")
    with pytest.raises(robocal.UsageError, match="the same file"):
        robocal.simulate(kr, "random", 10, validation=2).write(tmp_path / "a.csv", tmp_path / "a.csv")
    with pytest.raises(robocal.FileError):
        sim.write("/nonexistent/dir/a.csv")
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize(
    "kw, exc, words",
    [
        (dict(poses=0), robocal.UsageError, "poses: at least 1, got 0"),
        (dict(poses=-3), robocal.UsageError, "poses -3: must be at least 0"),
        (dict(poses=2.5), robocal.UsageError, "poses: expected an int"),
        (dict(poses=300_000), robocal.UsageError, "poses: at most 200000 (no calibration measures more), got 300000"),
        (dict(poses=75, candidates=50), robocal.UsageError, "candidates: at least 75, got 50"),
        (dict(candidates=-1), robocal.UsageError, "candidates -1"),
        (dict(seed=-2), robocal.UsageError, "seed -2"),
        (dict(poses=10), robocal.InputError, "10 poses for 26 identifiable parameters"),
        (dict(criterion="best"), robocal.UsageError, "criterion: `best`"),
        (dict(noise_mm=0.0), robocal.InputError, "noise_mm: 0: not a positive length"),
        (dict(noise_mm=float("nan")), robocal.InputError, "noise_mm: NaN"),
        (dict(noise_per_m=-1.0), robocal.InputError, "noise_per_m: -1"),
        (dict(floor_mm=1e300), robocal.InputError, "floor_mm: "),
        (dict(floor_mm=float("inf")), robocal.InputError, "floor_mm"),
        (dict(footprint_mm=-5.0), robocal.InputError, "footprint_mm"),
        (dict(tracker=(0, 0)), robocal.UsageError, "tracker: expected 6 values"),
        (dict(range_mm=(5000, 100)), robocal.InputError, "range_mm: 5000..100 mm is not a range"),
        (dict(range_mm=5000), robocal.UsageError, "range_mm: expected (min, max)"),
        (dict(include=np.zeros((3, 5))), robocal.InputError, "include: expected shape (n, 6)"),
        (dict(include=np.full((3, 6), np.nan)), robocal.InputError, "include: row 0, column 0"),
        (dict(include=np.zeros((3, 6), dtype=bool)), robocal.InputError, "dtype bool"),
        (dict(include="/nonexistent/include.csv"), robocal.FileError, "include.csv"),
    ],
)
def test_bad_plan_arguments(kr, kw, exc, words):
    kw.setdefault("candidates", 400)
    if kw["candidates"] == 400 and kw.get("poses", 75) > 400:
        kw["candidates"] = 200_000
    with pytest.raises(exc) as e:
        robocal.plan(kr, **kw)
    assert words in str(e.value), str(e.value)


def test_unknown_keywords_are_type_errors(kr):
    with pytest.raises(TypeError):
        robocal.simulate(kr, "random", 10, no_such_option=1)
    with pytest.raises(TypeError):
        robocal.plan(kr, 10, no_such_option=1)
    with pytest.raises(TypeError):
        robocal.simulate(kr, "random", 10, noise_mm="much")


# The same bad setting given to the CLI and to Python: the library checks it once, so both refuse
# it with the same exit code and the same message, the CLI naming its flag where Python names its
# keyword argument.
def as_keywords(cli_line):
    """A CLI message with each flag (`--outlier-max-mm`) written as its keyword (`outlier_max_mm`)
    and no backticks: the two messages then read the same."""
    return re.sub(r"--([a-z][a-z0-9-]*)", lambda m: m.group(1).replace("-", "_"), cli_line).replace("`", "")


SAME = [
    (["--poses", "0"], dict(poses=0), "--poses", "poses"),
    (["--poses", "20000000"], dict(poses=20_000_000), "--poses", "poses"),
    (["--poses", "10", "--noise-mm", "-1"], dict(poses=10, noise_mm=-1.0), "--noise-mm", "noise_mm"),
    (["--poses", "10", "--orientation-sigma-deg", "20"], dict(poses=10, orientation_sigma_deg=20.0),
     "--orientation-sigma-deg", "orientation_sigma_deg"),
    (["--poses", "10", "--all-targets"], dict(poses=10, all_targets=True), "--all-targets", "all_targets"),
    (["--poses", "10", "--compliance", "1e-7,1e-7"], dict(poses=10, compliance=[1e-7, 1e-7], payload_kg=1.0),
     "--compliance", "compliance"),
    (["--poses", "10", "--outlier-fraction", "0.1", "--outlier-min-mm", "5", "--outlier-max-mm", "1"],
     dict(poses=10, outlier_fraction=0.1, outlier_min_mm=5.0, outlier_max_mm=1.0),
     "--outlier-min-mm", "outlier_min_mm"),
]


@pytest.mark.parametrize("flags, kw, flag, keyword", SAME)
def test_simulate_refuses_as_the_cli(kr, cli, tmp_path, flags, kw, flag, keyword):
    out = tmp_path / "s.csv"
    args = [str(cli.exe), "simulate", "--robot", KR, "--truth", "random", "--out", str(out), *flags]
    if "--compliance" in flags:
        args += ["--payload-kg", "1"]
    p = subprocess.run(args, capture_output=True, text=True)
    assert not out.exists()
    with pytest.raises(robocal.RobocalError) as e:
        robocal.simulate(kr, "random", **kw)
    assert p.returncode == e.value.exit_code, (p.stderr, str(e.value))
    line = [l for l in p.stderr.splitlines() if l.startswith("error: ")][0][len("error: "):]
    assert line.startswith(flag + ":"), line
    assert str(e.value).startswith(keyword + ":"), str(e.value)
    assert as_keywords(line) == str(e.value).replace("`", ""), (line, str(e.value))


PLAN_SAME = [
    (["--poses", "0"], dict(poses=0), "--poses", "poses"),
    (["--poses", "300000"], dict(poses=300_000), "--poses", "poses"),
    (["--poses", "75", "--candidates", "50"], dict(poses=75, candidates=50), "--candidates", "candidates"),
    (["--poses", "30", "--noise-mm", "0"], dict(poses=30, noise_mm=0.0), "--noise-mm", "noise_mm"),
    (["--poses", "30", "--range-mm", "5000,100"], dict(poses=30, range_mm=(5000, 100)), "--range-mm", "range_mm"),
    (["--poses", "30", "--floor-mm", "1e300"], dict(poses=30, floor_mm=1e300), "--floor-mm", "floor_mm"),
]


@pytest.mark.parametrize("flags, kw, flag, keyword", PLAN_SAME)
def test_plan_refuses_as_the_cli(kr, cli, tmp_path, flags, kw, flag, keyword):
    out = tmp_path / "p.csv"
    p = subprocess.run([str(cli.exe), "plan", "--robot", KR, "--out", str(out), *flags],
                       capture_output=True, text=True)
    assert not out.exists()
    with pytest.raises(robocal.RobocalError) as e:
        robocal.plan(kr, **kw)
    assert p.returncode == e.value.exit_code, (p.stderr, str(e.value))
    line = [l for l in p.stderr.splitlines() if l.startswith("error: ")][0][len("error: "):]
    assert line.startswith(flag + ":"), line
    assert str(e.value).startswith(keyword + ":"), str(e.value)
    assert as_keywords(line) == str(e.value).replace("`", ""), (line, str(e.value))
