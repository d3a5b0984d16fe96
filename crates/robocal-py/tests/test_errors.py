"""Bad input raises clear robocal exceptions, never a crash."""

import numpy as np
import pytest

import robocal
from conftest import example


def good(n=40, seed=0):
    ur5 = robocal.Robot.from_file(example("ur5.toml"))
    q = np.random.default_rng(seed).uniform(-90, 90, (n, 6))
    return ur5, q, ur5.fk(q)


@pytest.mark.parametrize(
    "q, words",
    [
        (np.zeros((4, 5)), "expected shape (n, 6)"),
        (np.zeros((2, 3, 6)), "got (2, 3, 6)"),
        (np.zeros(7), "got (7,)"),
        (np.array([["a"] * 6]), "dtype <U1"),
        (np.zeros((1, 6), dtype=complex), "dtype complex128"),
        (np.zeros((1, 6), dtype=bool), "dtype bool"),
        (np.array([[0, 0, 0, 0, None, 0]], dtype=object), "dtype object"),
        ([[1, 2, 3, 4, 5, 6], [1, 2]], "not an array of numbers"),
        ("not an array", "dtype <U12"),
    ],
)
def test_bad_joint_arrays(q, words):
    ur5 = robocal.Robot.from_file(example("ur5.toml"))
    for f in (ur5.fk, ur5.fk_pose, ur5.jacobian, ur5.joint_jacobian):
        with pytest.raises(robocal.InputError) as e:
            f(q)
        assert words in str(e.value), str(e.value)
        assert str(e.value).startswith("q: ")


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_values_name_row_and_column(bad):
    ur5, q, xyz = good()
    q[3, 2] = bad
    with pytest.raises(robocal.InputError, match=r"q: row 3, column 2: .* not a finite number"):
        ur5.fk(q)
    _, q, xyz = good()
    xyz[5, 1] = bad
    with pytest.raises(robocal.InputError, match=r"calibration xyz: row 5, column 1"):
        robocal.calibrate(ur5, q, xyz)


def test_implausible_joint_values_are_refused():
    ur5, q, _ = good()
    q[2, 4] = 1e300
    with pytest.raises(robocal.InputError, match=r"q: row 2, column 4: .*out of range"):
        ur5.fk(q)
    assert ur5.fk(np.zeros((0, 6))).shape == (0, 3)
    with pytest.raises(robocal.InputError, match="no calibration points"):
        robocal.calibrate(ur5, np.zeros((0, 6)), np.zeros((0, 3)))


def test_calibrate_shapes():
    ur5, q, xyz = good()
    with pytest.raises(robocal.InputError, match="40 row.*39"):
        robocal.calibrate(ur5, q, xyz[:39])
    with pytest.raises(robocal.InputError, match=r"expected shape \(n, 3\)"):
        robocal.calibrate(ur5, q, xyz[:, :2])
    with pytest.raises(robocal.UsageError, match=r"validate: expected a pair"):
        robocal.calibrate(ur5, q, xyz, validate=q)
    with pytest.raises(robocal.InputError, match="validation q"):
        robocal.calibrate(ur5, q, xyz, validate=(q[:, :5], xyz))


def test_bad_options():
    ur5, q, xyz = good()
    cases = [
        (dict(objective="fastest"), robocal.UsageError, "objective: `fastest`"),
        (dict(fix=["a2", "zz9"]), robocal.UsageError, "fix: unknown parameter `zz9`"),
        (dict(fix="a2", free="a2"), robocal.InputError, "given both to `fix` and to `free`"),
        (dict(beta=[9]), robocal.UsageError, "beta: joint 9 does not exist"),
        (dict(harmonics=9), robocal.UsageError, "harmonics"),
        (dict(max_iterations=0), robocal.UsageError, "max_iterations"),
        (dict(rank_tol=1e-20), robocal.UsageError, "rank_tol"),
        (dict(tracker_sigma=(0, 0)), robocal.UsageError, "tracker_sigma"),
        (dict(tracker_sigma=(1,)), robocal.UsageError, "tracker_sigma"),
        (dict(payload_kg=5.0), robocal.UsageError, "payload_kg"),
        (dict(robust_scale=-1.0), robocal.UsageError, "robust_scale: -1 is not a positive length"),
        (dict(robust_scale=1e300), robocal.UsageError, "robust_scale: at most 1000000 mm"),
        (dict(orientation_weight=0.0), robocal.UsageError, "orientation_weight: 0"),
        (dict(max_iterations=-3), robocal.UsageError, "max_iterations: at least 1, got -3"),
        (dict(max_iterations="many"), robocal.UsageError, "max_iterations: expected an int"),
    ]
    for kw, exc, words in cases:
        with pytest.raises(exc) as e:
            robocal.calibrate(ur5, q, xyz, **kw)
        assert words in str(e.value), (kw, str(e.value))
    with pytest.raises(TypeError):
        robocal.calibrate(ur5, q, xyz, no_such_option=1)
    with pytest.raises(TypeError):
        robocal.calibrate_files(ur5, "x.csv", no_such_option=1)


def test_joint_limits_and_numerical_failures():
    ur5, q, xyz = good()
    q[7, 0] = 400.0
    with pytest.raises(robocal.InputError, match="nominal_limits=True"):
        robocal.calibrate(ur5, q, ur5.fk(q))
    # Too few points for the identifiable parameters: a numerical failure (exit code 5).
    _, q, xyz = good(n=6)
    with pytest.raises(robocal.RobocalError) as e:
        robocal.calibrate(ur5, q, xyz)
    assert e.value.exit_code in (3, 5)


def test_wrong_unit_is_implausible_unless_accepted():
    ur5, q, xyz = good(n=60)
    with pytest.raises(robocal.ImplausibleError) as e:
        robocal.calibrate(ur5, q, xyz / 1000.0)
    assert e.value.exit_code == 6 and "accept_implausible=True" in str(e.value)
    with pytest.warns(RuntimeWarning, match="IMPLAUSIBLE"):
        res = robocal.calibrate(ur5, q, xyz / 1000.0, accept_implausible=True)
    assert res.status == robocal.STATUS_IMPLAUSIBLE


def test_robots_and_files():
    with pytest.raises(robocal.UsageError, match="unknown robot preset `ur6`"):
        robocal.Robot.preset("ur6")
    with pytest.raises(robocal.FileError, match="nothing.toml"):
        robocal.Robot.from_file("/nonexistent/nothing.toml")
    with pytest.raises(robocal.InputError):
        robocal.Robot.from_toml("joints = 3")
    ur5 = robocal.Robot.from_file(example("ur5.toml"))
    with pytest.raises(robocal.InputError, match="unknown parameter `nope`"):
        ur5.get("nope")
    with pytest.raises(robocal.InputError):
        ur5.set("d1", float("nan"))
    with pytest.raises(robocal.UsageError, match="target"):
        ur5.fk(np.zeros(6), target=3)
    with pytest.raises(robocal.FileError):
        robocal.calibrate_files(ur5, "/nonexistent/data.csv")


def test_every_error_is_a_robocal_error():
    for c in (robocal.UsageError, robocal.InputError, robocal.FileError, robocal.NumericalError,
              robocal.ImplausibleError):
        assert issubclass(c, robocal.RobocalError)
