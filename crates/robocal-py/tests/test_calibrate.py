"""calibrate: the CLI's results to 1e-12 on the real UR5 data and on the demo's data, and as fast."""

import time

import numpy as np
import pytest

import robocal
from conftest import example, load_csv, read_json

TOL = 1e-12


def assert_same_numbers(a, b, path="result"):
    """Every number of `a` equals `b`'s within TOL (relative to its size), recursively."""
    if isinstance(a, dict):
        assert set(a) == set(b), f"{path}: keys differ: {set(a) ^ set(b)}"
        for k in a:
            assert_same_numbers(a[k], b[k], f"{path}.{k}")
    elif isinstance(a, list):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b)):
            assert_same_numbers(x, y, f"{path}[{i}]")
    elif isinstance(a, float) or isinstance(b, float):
        assert abs(a - b) <= TOL * max(1.0, abs(a)), f"{path}: {a!r} != {b!r}"
    else:
        assert a == b, f"{path}: {a!r} != {b!r}"


def max_abs_diff(a, b):
    """The largest absolute difference between the numbers of `a` and `b` (same layout)."""
    if isinstance(a, dict):
        return max([max_abs_diff(a[k], b[k]) for k in a], default=0.0)
    if isinstance(a, list):
        return max([max_abs_diff(x, y) for x, y in zip(a, b)], default=0.0)
    if isinstance(a, float) or isinstance(b, float):
        return abs(a - b)
    return 0.0


def identity_figure(py: dict, cli: dict) -> float:
    """The largest absolute difference over the numeric sections of two results."""
    return max(max_abs_diff(py[s], cli[s]) for s in SECTIONS if s in py)


# The result's sections that hold numbers; `settings` names the files, `points` their lines.
SECTIONS = ["parameters", "tracker_frame", "errors", "identifiability", "uncertainty",
            "prediction", "registration", "robot", "status", "plausibility", "solver"]


def compare(py: dict, cli: dict):
    for s in SECTIONS:
        assert (s in py) == (s in cli), s
        if s in py:
            assert_same_numbers(py[s], cli[s], s)
    # Per-point errors: the same values, point for point (their line numbers differ: arrays
    # number rows from 1, files count the header).
    if "points" in cli:
        assert_same_numbers(strip_lines(py["points"]), strip_lines(cli["points"]), "points")


def strip_lines(v):
    """`v` without its `line`/`lines` keys (where the points came from)."""
    if isinstance(v, dict):
        return {k: strip_lines(x) for k, x in v.items() if k not in ("line", "lines")}
    if isinstance(v, list):
        return [strip_lines(x) for x in v]
    return v


@pytest.fixture(scope="module")
def ur5_cli(real_data, cli, tmp_path_factory):
    out = tmp_path_factory.mktemp("ur5") / "cli.json"
    t = time.perf_counter()
    cli("calibrate", "--robot", example("ur5.toml"), "--data", str(real_data / "jacobi_ur5_grid.csv"),
        "--validate", str(real_data / "jacobi_ur5_random.csv"), "--out", str(out))
    return read_json(out), time.perf_counter() - t


def test_ur5_arrays_are_the_cli(ur5, real_data, ur5_cli):
    q, xyz, _ = load_csv(real_data / "jacobi_ur5_grid.csv")
    vq, vxyz, _ = load_csv(real_data / "jacobi_ur5_random.csv")
    assert q.shape == (1000, 6)
    res = robocal.calibrate(ur5, q, xyz, validate=(vq, vxyz))
    compare(res.data, ur5_cli[0])
    print(f"\nUR5 real data, Python vs CLI result: max abs difference {identity_figure(res.data, ur5_cli[0]):.1e}")
    assert res.status == robocal.STATUS_CALIBRATED
    p = res.parameters
    assert p["a2"].unit == "mm" and isinstance(p["a2"].fixed, bool)
    assert set(res.stds) == {n for n, e in p.items() if not e.fixed}
    assert res.errors["validation"]["after"]["n"] == 20
    assert res.identifiability is not None


def test_ur5_files_are_the_cli(ur5, real_data, ur5_cli):
    res = robocal.calibrate_files(ur5, real_data / "jacobi_ur5_grid.csv", real_data / "jacobi_ur5_random.csv")
    compare(res.data, ur5_cli[0])
    # Read from the same files, even the settings and per-point lines are the CLI's.
    cli = ur5_cli[0]
    assert res.data["points"] == cli["points"]
    assert res.data["settings"]["data"] == cli["settings"]["data"]


def test_ur5_calibration_is_as_fast_as_the_cli(ur5, real_data, cli, tmp_path):
    q, xyz, _ = load_csv(real_data / "jacobi_ur5_grid.csv")
    vq, vxyz, _ = load_csv(real_data / "jacobi_ur5_random.csv")
    robocal.calibrate(ur5, q, xyz, validate=(vq, vxyz))
    # The CLI and the Python call in turn, the fastest of each compared: the other tests run
    # beside this one, and one run of either can fall on a busy moment.
    runs, clis = [], []
    for _ in range(3):
        t = time.perf_counter()
        cli("calibrate", "--robot", example("ur5.toml"), "--data",
            str(real_data / "jacobi_ur5_grid.csv"), "--validate",
            str(real_data / "jacobi_ur5_random.csv"), "--out", str(tmp_path / "cli.json"))
        clis.append(time.perf_counter() - t)
        t = time.perf_counter()
        res = robocal.calibrate(ur5, q, xyz, validate=(vq, vxyz))
        runs.append((time.perf_counter() - t, res.library_seconds))
    py, lib = min(runs)
    cli = min(clis)
    print(f"\ncalibration of 1000 UR5 poses: Python call {py * 1e3:.0f} ms, of which the library "
          f"{lib * 1e3:.0f} ms; the whole CLI process {cli * 1e3:.0f} ms")
    # Within 1.5x of the library's own time, and no slower than the CLI.
    assert py <= 1.5 * lib, (py, lib)
    assert py <= 1.5 * cli, (py, cli)


@pytest.fixture(scope="module")
def demo(cli, tmp_path_factory):
    d = tmp_path_factory.mktemp("demo")
    cli("demo", "--out", str(d / "run"))
    run = d / "run"
    out = d / "cli.json"
    # The calibration the demo prints to reproduce its result by hand.
    cli("calibrate", "--robot", "kuka-kr480-r3330", "--model", "geometric", "--objective", "sum-of-norms",
        "--data", str(run / "cell.csv"),
        "--validate", str(run / "validation.csv"), "--out", str(out))
    return run, read_json(out)


def test_demo_data_arrays_are_the_cli(demo):
    run, cli_res = demo
    kr = robocal.Robot.preset("kuka-kr480-r3330")
    q, xyz, sets = load_csv(run / "cell.csv")
    vq, vxyz, _ = load_csv(run / "validation.csv")
    plane = sets == "plane"
    cal = ~plane & (sets != "validation")
    assert plane.sum() == 3
    res = robocal.calibrate(kr, q[cal], xyz[cal], plane=(q[plane], xyz[plane]), validate=(vq, vxyz),
                            objective="sum-of-norms", model="geometric")
    compare(res.data, cli_res)
    print(f"\ndemo data, Python vs CLI result: max abs difference {identity_figure(res.data, cli_res):.1e}")
    # And the demo's own result (the library's experiment) says the same.
    demo_res = read_json(run / "result.json")
    for name, e in demo_res["parameters"].items():
        assert abs(res.parameters[name].calibrated - e["calibrated"]) <= TOL * max(1, abs(e["calibrated"])), name


def test_demo_data_files_are_the_cli(demo):
    run, cli_res = demo
    kr = robocal.Robot.preset("kuka-kr480-r3330")
    res = robocal.calibrate_files(kr, run / "cell.csv", run / "validation.csv", objective="sum-of-norms",
                                  model="geometric")
    compare(res.data, cli_res)
    assert res.data["points"] == cli_res["points"]


def test_options_reach_the_library(ur5, real_data):
    q, xyz, _ = load_csv(real_data / "jacobi_ur5_grid.csv")
    q, xyz = q[:200], xyz[:200]
    res = robocal.calibrate(ur5, q, xyz, fix=["a2"], objective="least-squares", beta="parallel",
                            tracker_sigma=(0.01, 0.005))
    assert res.parameters["a2"].fixed
    assert "beta3" in res.parameters or "beta2" in res.parameters
    assert res.data["settings"]["fix"] == ["a2"]
    assert res.data["settings"]["objective"] == "least-squares"


def _timed(f):
    t = time.perf_counter()
    f()
    return time.perf_counter() - t


def test_explicit_families_that_overfit_warn(ur5):
    # As the CLI's remark: compliance and harmonics given explicitly on the example's 60 points
    # do not beat the geometric model's cross-validated error.
    with pytest.warns(RuntimeWarning, match="overfitting"):
        res = robocal.calibrate_files(ur5, example("data/ur5-cell.csv"), compliance="auto", harmonics=1)
    sel = res.model_selection
    assert "overfitting" in sel["remark"]
    ref = [c for c in sel["candidates"] if c.get("reference")]
    assert len(ref) == 1 and ref[0]["families"] == []


def test_screened_candidates_carry_their_estimates(ur5):
    # The default model choice on the example's geometric 60 points: the families, far from
    # lowering the geometric model's error, are estimated from its fit and not fitted. They are
    # marked, keep their cross-validated estimates, and are not the choice (as the CLI's table).
    res = robocal.calibrate_files(ur5, example("data/ur5-cell.csv"))
    cands = res.model_selection["candidates"]
    screened = [c for c in cands if c.get("screened")]
    assert [c["families"] for c in screened] == [["compliance"], ["harmonics 1"]], cands
    chosen = [c for c in cands if c["chosen"]]
    assert len(chosen) == 1 and chosen[0]["families"] == [] and not chosen[0].get("screened")
    for c in screened:
        assert not c["chosen"] and c["cv_mean_mm"] > 0 and c["cv_std_error_mm"] > 0
