"""simulate and plan: bad input raises clear robocal exceptions, never a crash."""

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
        (dict(), robocal.UsageError, "give poses"),
        (dict(poses=-1), robocal.UsageError, "poses -1: must be at least 0"),
        (dict(poses=0), robocal.InputError, "poses: must be at least 1"),
        (dict(poses=1.5), robocal.UsageError, "poses: expected an int, got 1.5 (float)"),
        (dict(poses=True), robocal.UsageError, "poses: expected an int"),
        (dict(poses="75"), robocal.UsageError, "poses: expected an int"),
        (dict(poses=10**30), robocal.UsageError, "at most 10000000"),
        (dict(poses=10, validation=-5), robocal.UsageError, "validation -5: must be at least 0"),
        (dict(poses=6_000_000, validation=6_000_000), robocal.UsageError, "12000000 poses in all"),
        (dict(poses=10, seed=-1), robocal.UsageError, "seed -1: must be at least 0"),
        (dict(poses=-10**40), robocal.UsageError, "poses -10000000000000000000000000000000000000000: must be at least 0"),
        (dict(poses=10, truth="ur6"), robocal.UsageError, "truth: unknown robot preset `ur6`"),
        (dict(poses=10, truth="/nonexistent/t.truth.json"), robocal.FileError, "truth: "),
        (dict(poses=10, truth=3), robocal.UsageError, "truth: expected"),
        (dict(poses=10, truth=example("ur5.toml")), robocal.InputError, "uses dh parameters"),
        (dict(poses=10, truth="kuka-kr480-r3330-table3", length_error_mm=1.0), robocal.UsageError,
         "only to truth=\"random\""),
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
        (dict(poses=10, payload_kg=5.0), robocal.UsageError, "give compliance too"),
        (dict(poses=10, outlier_fraction=2.0), robocal.InputError, "outlier_fraction"),
        (dict(poses=10, outlier_min_mm=1.0), robocal.UsageError, "give outlier_fraction too"),
        (dict(poses=10, outlier_fraction=0.1, outlier_min_mm=5, outlier_max_mm=1), robocal.InputError,
         "outlier_min_mm"),
        (dict(poses=10, outlier_fraction=0.1, orientation_sigma_deg=0.01), robocal.UsageError,
         "outliers are drawn for single points"),
        (dict(poses=10, orientation_sigma_deg=20.0), robocal.UsageError, "orientation_sigma_deg 20"),
        (dict(poses=10, all_targets=True), robocal.UsageError, "all_targets: robot `"),
        (dict(poses=10, joints=np.zeros((2, 6))), robocal.UsageError, "poses: not with joints"),
        (dict(joints=np.zeros((2, 6)), validation=3), robocal.UsageError, "validation: not with joints"),
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
        (dict(poses=0), robocal.UsageError, "poses 0: must be at least 1"),
        (dict(poses=-3), robocal.UsageError, "poses -3: must be at least 1"),
        (dict(poses=2.5), robocal.UsageError, "poses: expected an int"),
        (dict(poses=300_000), robocal.UsageError, "poses 300000: at most 200000"),
        (dict(poses=75, candidates=50), robocal.UsageError, "candidates 50: must be at least 75"),
        (dict(candidates=-1), robocal.UsageError, "candidates -1"),
        (dict(seed=-2), robocal.UsageError, "seed -2"),
        (dict(poses=10), robocal.InputError, "10 poses for 26 identifiable parameters"),
        (dict(criterion="best"), robocal.UsageError, "criterion: `best`"),
        (dict(noise_mm=0.0), robocal.UsageError, "noise_mm 0"),
        (dict(noise_mm=float("nan")), robocal.UsageError, "noise_mm NaN"),
        (dict(noise_per_m=-1.0), robocal.UsageError, "noise_per_m -1"),
        (dict(floor_mm=1e300), robocal.UsageError, "floor_mm 1e300: at most"),
        (dict(floor_mm=float("inf")), robocal.InputError, "floor_mm"),
        (dict(footprint_mm=-5.0), robocal.InputError, "footprint_mm"),
        (dict(tracker=(0, 0)), robocal.UsageError, "tracker: expected 6 values"),
        (dict(range_mm=(5000, 100)), robocal.UsageError, "range_mm (5000, 100): not a range"),
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
