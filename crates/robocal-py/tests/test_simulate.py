"""simulate: the same seed gives the CLI's files byte for byte and its numbers exactly."""

import time

import numpy as np
import pytest

import robocal
from conftest import example, read_json
from test_calibrate import compare

KR = "kuka-kr480-r3330"


def read_csv(path):
    """A CSV as (header, rows of strings)."""
    lines = open(path).read().splitlines()
    return lines[0].split(","), [l.split(",") for l in lines[1:]]


def numbers(path, columns):
    """The named columns of a CSV as a float array, parsed as the CLI parses them."""
    header, rows = read_csv(path)
    idx = [header.index(c) for c in columns]
    return np.array([[float(r[i]) for i in idx] for r in rows]).reshape(len(rows), len(columns))


def same_files(a, b):
    """The files' bytes are equal (the truth file's too)."""
    assert open(a, "rb").read() == open(b, "rb").read(), f"{a} and {b} differ"


def max_diff(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    assert a.shape == b.shape, (a.shape, b.shape)
    return float(np.max(np.abs(a - b))) if a.size else 0.0


def run_both(cli, tmp_path, robot_arg, robot, cli_args, **kw):
    """The CLI's session and Python's, written to cli/cell.csv and py/cell.csv."""
    (tmp_path / "cli").mkdir()
    (tmp_path / "py").mkdir()
    c, p = tmp_path / "cli" / "cell.csv", tmp_path / "py" / "cell.csv"
    cli("simulate", "--robot", robot_arg, "--out", str(c), *cli_args)
    sim = robocal.simulate(robot, **kw)
    sim.write(p)
    return sim, c, p


def check_arrays(sim, csv, dof=6):
    """The arrays are the CLI file's numbers exactly."""
    q = numbers(csv, [f"q{i}" for i in range(1, dof + 1)])
    xyz = numbers(csv, ["x", "y", "z"])
    d = max(max_diff(sim.q, q), max_diff(sim.xyz, xyz))
    assert d == 0.0, d
    return d


def test_random_session_is_the_cli(cli, tmp_path):
    kr = robocal.Robot.preset(KR)
    sim, c, p = run_both(cli, tmp_path, KR, kr,
                         ["--truth", "random", "--poses", "75", "--validation", "73", "--seed", "5"],
                         truth="random", poses=75, validation=73, seed=5)
    same_files(c, p)
    same_files(c.with_suffix(".truth.json"), p.with_suffix(".truth.json"))
    assert sim.to_csv() == c.read_text()
    check_arrays(sim, c)
    header, rows = read_csv(c)
    assert sim.sets == [r[header.index("set")] for r in rows]
    assert sim.ids == [r[header.index("id")] for r in rows]
    assert [len(sim.plane[0]), len(sim.calibration[0]), len(sim.validation[0])] == [3, 75, 73]
    assert len(sim) == 151 and sim.target is None and sim.abc is None
    # The truth robot and tracker frame are the truth file's, to the bit.
    truth = read_json(c.with_suffix(".truth.json"))
    for name, e in truth["parameters"].items():
        assert sim.truth.get(name) == e["calibrated"], name
        assert sim.nominal.get(name) == e["nominal"], name
    assert sim.tracker_frame == truth["tracker_frame"]
    assert sim.plane_z_mm == truth["plane_z_mm"]
    # The exact readings lie within the noise of the written ones.
    assert np.max(np.abs(sim.exact - sim.xyz)) < 0.2


def test_every_option_is_the_cli(cli, tmp_path):
    kr = robocal.Robot.preset(KR)
    args = ["--truth", "random", "--poses", "60", "--validation", "20", "--seed", "11",
            "--validation-out", str(tmp_path / "cli" / "val.csv"),
            "--tracker", "2500,-3000,800,110,0.5,-0.2", "--noise-mm", "0.02", "--noise-per-m", "0.01",
            "--length-error-mm", "0.8", "--angle-error-deg", "0.05", "--tilt-parallel-axes",
            "--floor-mm", "200", "--footprint-mm", "900", "--plane-z-mm", "1500",
            "--compliance", "1e-7,2e-7,2e-7,1e-6,1e-6,1e-6", "--link-masses-kg", "100",
            "--payload-kg", "300", "--outlier-fraction", "0.1", "--outlier-min-mm", "1",
            "--outlier-max-mm", "3"]
    (tmp_path / "cli").mkdir()
    (tmp_path / "py").mkdir()
    c, p = tmp_path / "cli" / "cell.csv", tmp_path / "py" / "cell.csv"
    cli("simulate", "--robot", KR, "--out", str(c), *args)
    sim = robocal.simulate(kr, "random", 60, validation=20, seed=11,
                           tracker=(2500, -3000, 800, 110, 0.5, -0.2), noise_mm=0.02, noise_per_m=0.01,
                           length_error_mm=0.8, angle_error_deg=0.05, tilt_parallel_axes=True,
                           floor_mm=200, footprint_mm=900, plane_z_mm=1500,
                           compliance=[1e-7, 2e-7, 2e-7, 1e-6, 1e-6, 1e-6], link_masses_kg=100,
                           payload_kg=300, outlier_fraction=0.1, outlier_min_mm=1, outlier_max_mm=3)
    sim.write(p, tmp_path / "py" / "val.csv")
    for f in ("cell.csv", "val.csv", "cell.truth.json"):
        same_files(tmp_path / "cli" / f, tmp_path / "py" / f)
    truth = read_json(c.with_suffix(".truth.json"))
    assert [o["line"] for o in truth["outliers"]] != []
    assert len(sim.outlier_rows) == len(truth["outliers"]) == sim.outlier_displacements.shape[0]
    assert sim.deflection_mm is not None and sim.deflection_mm.shape == (len(sim),)
    assert "beta3" in sim.truth.parameter_names
    assert sim.tracker_frame["x"] == 2500.0


def test_targets_and_orientations_are_the_cli(cli, tmp_path):
    toml = open(example("kr480-r3330.toml")).read().replace(
        "tool = [42.4163, -70.9065, 239.5558, -0.038, 0.237, 0.054]",
        "tools = [[42.4163, -70.9065, 239.5558, -0.038, 0.237, 0.054], [142.4, 29.1, 239.6, 0, 0, 0],"
        " [-57.6, 29.1, 239.6, 0, 0, 0]]")
    f = tmp_path / "kr3.toml"
    f.write_text(toml)
    robot = robocal.Robot.from_file(f)
    assert robot.target_count == 3
    sim, c, p = run_both(cli, tmp_path, str(f), robot,
                         ["--truth", "random", "--poses", "20", "--seed", "2", "--all-targets",
                          "--orientation-sigma-deg", "0.001"],
                         truth="random", poses=20, seed=2, all_targets=True, orientation_sigma_deg=0.001)
    same_files(c, p)
    check_arrays(sim, c)
    assert max_diff(sim.abc, numbers(c, ["a", "b", "c"])) == 0.0
    assert list(sim.target) == [int(t) for t in numbers(c, ["target"])[:, 0]]
    assert set(sim.target) == {1, 2, 3}


def test_measuring_joints_is_the_cli(cli, tmp_path):
    kr = robocal.Robot.preset(KR)
    plan_csv = tmp_path / "plan.csv"
    cli("plan", "--robot", KR, "--poses", "30", "--candidates", "500", "--out", str(plan_csv))
    q = numbers(plan_csv, [f"q{i}" for i in range(1, 7)])
    sim, c, p = run_both(cli, tmp_path, KR, kr,
                         ["--truth", "kuka-kr480-r3330-table3", "--joints", str(plan_csv), "--seed", "4"],
                         truth="kuka-kr480-r3330-table3", joints=str(plan_csv), seed=4)
    same_files(c, p)
    same_files(c.with_suffix(".truth.json"), p.with_suffix(".truth.json"))
    # The same joints as an array: the same readings.
    arr = robocal.simulate(kr, "kuka-kr480-r3330-table3", joints=q, seed=4)
    check_arrays(arr, c)
    assert arr.sets is None and len(arr) == 30
    # A truth file as the truth: its robot and its tracker frame.
    again = robocal.simulate(kr, c.with_suffix(".truth.json"), joints=q, seed=4)
    assert max_diff(again.xyz, arr.xyz) == 0.0
    # A Robot object as the truth.
    table3 = robocal.Robot.preset("kuka-kr480-r3330-table3")
    assert max_diff(robocal.simulate(kr, table3, joints=q, seed=4).xyz, arr.xyz) == 0.0


def test_simulated_data_calibrate_as_the_cli(cli, tmp_path):
    """robocal simulate + robocal calibrate on its file == simulate + calibrate in Python."""
    kr = robocal.Robot.preset(KR)
    c = tmp_path / "cell.csv"
    out = tmp_path / "cli.json"
    cli("simulate", "--robot", KR, "--truth", "random", "--poses", "75", "--validation", "73",
        "--seed", "9", "--out", str(c))
    cli("calibrate", "--robot", KR, "--data", str(c), "--out", str(out))
    sim = robocal.simulate(kr, "random", 75, validation=73, seed=9)
    res = robocal.calibrate(kr, *sim.calibration, plane=sim.plane, validate=sim.validation)
    cli_res = read_json(out)
    compare(res.data, cli_res)
    worst = max(abs(res.parameters[n].calibrated - e["calibrated"]) for n, e in cli_res["parameters"].items())
    print(f"\nsimulate + calibrate, Python vs CLI: max parameter difference {worst:.1e}")
    # And the calibration explains the simulated robot to the tracker's noise.
    assert res.errors["validation"]["after"]["mean_mm"] < 0.1


def test_simulation_timing(cli, tmp_path):
    kr = robocal.Robot.preset(KR)
    n = 20000
    t = time.perf_counter()
    sim = robocal.simulate(kr, "random", n, seed=1)
    py = time.perf_counter() - t
    t = time.perf_counter()
    cli("simulate", "--robot", KR, "--truth", "random", "--poses", str(n), "--seed", "1",
        "--out", str(tmp_path / "c.csv"))
    c = time.perf_counter() - t
    print(f"\nsimulate {n} poses: Python {py * 1e3:.0f} ms, the whole CLI process {c * 1e3:.0f} ms")
    assert len(sim) == n + 3
    assert py <= 2.0 * c + 0.5, (py, c)


@pytest.mark.parametrize("robot_file", ["ur5.toml", "kr480-track.toml", "fanuc-like.toml", "wam.toml"])
def test_robot_files_simulate_as_the_cli(cli, tmp_path, robot_file):
    """Standard DH, a prismatic track, a controller coupling, seven joints: the CLI's files."""
    robot = robocal.Robot.from_file(example(robot_file))
    sim, c, p = run_both(cli, tmp_path, example(robot_file), robot,
                         ["--truth", "random", "--poses", "40", "--validation", "10", "--seed", "6"],
                         truth="random", poses=40, validation=10, seed=6)
    same_files(c, p)
    same_files(c.with_suffix(".truth.json"), p.with_suffix(".truth.json"))
    check_arrays(sim, c, robot.dof)


def test_tracker_weighting_default_and_off_are_the_cli(cli, tmp_path):
    """Data in a tracker's frame are weighted by the typical tracker by default; "off" (the
    CLI's `--tracker-sigma off`) weighs every point the same; both as the CLI does."""
    kr = robocal.Robot.preset(KR)
    c = tmp_path / "cell.csv"
    cli("simulate", "--robot", KR, "--truth", "random", "--poses", "75", "--seed", "12",
        "--out", str(c))
    sim = robocal.simulate(kr, "random", 75, seed=12)
    for extra, source in [((), "automatic"), (("--tracker-sigma", "off"), "none")]:
        out = tmp_path / f"{source}.json"
        cli("calibrate", "--robot", KR, "--data", str(c), "--out", str(out), *extra)
        kw = {"tracker_sigma": "off"} if extra else {}
        res = robocal.calibrate(kr, *sim.calibration, plane=sim.plane, **kw)
        cli_res = read_json(out)
        assert cli_res["settings"]["weighting"]["source"] == source
        assert res.data["settings"]["weighting"]["source"] == source
        compare(res.data, cli_res)


def test_real_cell_session_and_families_are_the_cli(cli, tmp_path):
    """The real cell's effects (repeatability, backlash, thermal growth, another station) as the
    CLI's flags, and a calibration with the backlash and thermal families as the CLI's."""
    kr = robocal.Robot.preset(KR)
    sim, c, p = run_both(cli, tmp_path, KR, kr,
                         ["--truth", "kuka-kr480-r3330-table3", "--poses", "60", "--seed", "3",
                          "--repeatability-deg", "default", "--backlash-deg", "auto",
                          "--thermal", "auto", "--thermal-rise-c", "6", "--thermal-start-s", "600",
                          "--seconds-per-pose", "30", "--station", "2"],
                         truth="kuka-kr480-r3330-table3", poses=60, seed=3,
                         repeatability_deg="default", backlash_deg="auto", thermal="auto",
                         thermal_rise_c=6, thermal_start_s=600, seconds_per_pose=30, station=2)
    same_files(c, p)
    same_files(c.with_suffix(".truth.json"), p.with_suffix(".truth.json"))
    header, _ = read_csv(c)
    for col in ["temperature_c", "time_s"] + [f"dir{j}" for j in range(1, 7)]:
        assert col in header, col
        assert col in sim.columns, col
    out = tmp_path / "cli.json"
    cli("calibrate", "--robot", KR, "--data", str(c), "--model", "geometric", "--backlash", "auto",
        "--thermal", "auto", "--out", str(out))
    with pytest.warns(RuntimeWarning, match="thermal expansion referred to"):
        res = robocal.calibrate_files(kr, c, model="geometric", backlash="auto", thermal="auto")
    compare(res.data, read_json(out))
    assert "thermal_k" in res.parameters and "backlash1" in res.parameters
    # Settings the CLI refuses.
    with pytest.raises(robocal.UsageError, match="thermal"):
        robocal.simulate(kr, "random", 10, thermal_rise_c=5)
    with pytest.raises(robocal.UsageError, match="backlash_deg"):
        robocal.simulate(kr, "random", 10, backlash_deg="some")
    with pytest.raises((robocal.UsageError, robocal.InputError), match="station"):
        robocal.simulate(kr, "random", 10, station=100000)


def test_links_growing_unevenly_are_the_cli(cli, tmp_path):
    """``thermal_link_gain`` (one gain per link) writes the CLI's files for --thermal-link-gain,
    and is refused as the CLI refuses it: without thermal growth, or with a wrong count."""
    kr = robocal.Robot.preset(KR)
    gains = [1.0, 1.5, 0.5, 1.0, 1.0, 2.0]
    _, c, p = run_both(cli, tmp_path, KR, kr,
                       ["--truth", "kuka-kr480-r3330-table3", "--poses", "30", "--seed", "4",
                        "--thermal", "auto", "--thermal-link-gain", ",".join(map(str, gains))],
                       truth="kuka-kr480-r3330-table3", poses=30, seed=4, thermal="auto",
                       thermal_link_gain=gains)
    same_files(c, p)
    same_files(c.with_suffix(".truth.json"), p.with_suffix(".truth.json"))
    even = robocal.simulate(kr, "kuka-kr480-r3330-table3", 30, seed=4, thermal="auto")
    uneven = robocal.simulate(kr, "kuka-kr480-r3330-table3", 30, seed=4, thermal="auto",
                              thermal_link_gain=gains)
    assert (even.xyz != uneven.xyz).any()
    with pytest.raises(robocal.UsageError, match="link_gain"):
        robocal.simulate(kr, "random", 10, thermal_link_gain=gains)
    with pytest.raises((robocal.UsageError, robocal.InputError), match="link_gain"):
        robocal.simulate(kr, "random", 10, thermal="auto", thermal_link_gain=[1.0, 2.0])
