"""Calibration without a laser tracker (issue 31) from Python: ``calibrate_files`` on a
constraint file gives the CLI's result to the last bit, with the CLI's refusals."""

import json

import pytest

import robocal

KR = "kuka-kr480-r3330"


@pytest.fixture(scope="module")
def points(cli, tmp_path_factory):
    d = tmp_path_factory.mktemp("constraints")
    data, dist = d / "p.csv", d / "d.csv"
    cli(
        "simulate", "--robot", KR, "--truth", "random", "--constraint", "point",
        "--features", "4", "--per-feature", "12", "--noise-mm", "0.01",
        "--out", str(data), "--distances-out", str(dist),
    )
    return d, data, dist


def test_constraint_file_is_the_clis(points, cli):
    d, data, dist = points
    kr = robocal.Robot.preset(KR)
    r = robocal.calibrate_files(kr, data, distances=dist)
    out = d / "cli.json"
    cli("calibrate", "--robot", KR, "--data", str(data), "--distances", str(dist), "--out", str(out))
    cli_json = json.loads(out.read_text())
    py_json = r.data
    assert py_json["parameters"] == cli_json["parameters"]
    assert py_json["constraint"] == cli_json["constraint"]
    assert r.status == "calibrated"
    c = r.constraint
    assert c is not None and not c["base_pose_known"]
    assert "up to the base pose" in c["frame"]
    assert [f["name"] for f in c["features"]] == ["P1", "P2", "P3", "P4"]
    assert c["scale"]["known"]
    # The result reads back, and its calibrated robot is the CLI's.
    p = d / "py.json"
    r.write(p)
    q = [10.0, -80.0, 90.0, 0.0, 40.0, 0.0]
    fk = json.loads(cli("fk", "--params", str(p), "--joints", ",".join(map(str, q)), "--json"))
    assert list(robocal.Result.read(p).calibrated_robot().fk(q)) == [fk["x"], fk["y"], fk["z"]]


def test_unknown_scale_is_refused_unless_accepted(points):
    _, data, _ = points
    kr = robocal.Robot.preset(KR)
    with pytest.raises(robocal.NumericalError) as e:
        robocal.calibrate_files(kr, data)
    assert "scale is not determined" in str(e.value)
    assert "accept_unknown_scale=True" in str(e.value)
    with pytest.warns(RuntimeWarning, match="scale is not determined"):
        r = robocal.calibrate_files(kr, data, accept_unknown_scale=True)
    assert not r.constraint["scale"]["known"]


def test_options_that_do_not_apply_are_refused(points, tmp_path):
    _, data, dist = points
    kr = robocal.Robot.preset(KR)
    with pytest.raises(robocal.UsageError, match="objective"):
        robocal.calibrate_files(kr, data, distances=dist, objective="least-squares")
    with pytest.raises(robocal.UsageError, match="validate"):
        robocal.calibrate_files(kr, data, data, distances=dist)
    tracker = tmp_path / "t.csv"
    tracker.write_text("q1,q2,q3,q4,q5,q6,x,y,z\n" + "0,-90,90,0,30,0,1,2,3\n" * 3)
    with pytest.raises(robocal.UsageError, match="constraint column"):
        robocal.calibrate_files(kr, tracker, distances=dist)


def test_bad_constraint_rows_are_input_errors(points, tmp_path):
    _, data, _ = points
    kr = robocal.Robot.preset(KR)
    text = data.read_text().replace("point:P2", "point:P9", 1)
    bad = tmp_path / "typo.csv"
    bad.write_text(text)
    with pytest.raises(robocal.InputError, match="used on 1 row"):
        robocal.calibrate_files(kr, bad, accept_unknown_scale=True)


def test_tracker_points_are_registered_to_a_constraint_result(points, cli):
    from conftest import load_csv

    d, data, dist = points
    kr = robocal.Robot.preset(KR)
    r = robocal.calibrate_files(kr, data, distances=dist)
    trk = d / "t.csv"
    cli(
        "simulate", "--robot", KR, "--truth", str(d / "p.truth.json"), "--poses", "30",
        "--no-plane", "--noise-mm", "0.01", "--out", str(trk),
    )
    q, xyz, _ = load_csv(trk)
    with pytest.warns(RuntimeWarning, match="up to the base pose"):
        out = r.evaluate(q, xyz)
    cal = out["calibrated"]["stats"]["mean_mm"]
    nom = out["nominal"]["stats"]["mean_mm"]
    assert cal < 0.1 and nom > 10 * cal, (nom, cal)
    # The CLI's figures for the same points.
    res = d / "r.json"
    r.write(res)
    j = json.loads(cli("evaluate", "--params", str(res), "--data", str(trk), "--json"))
    assert j["calibrated"]["mean_mm"] == pytest.approx(cal, rel=1e-9)


@pytest.mark.parametrize("kind", ["point", "sphere"])
def test_simulate_constraints_writes_the_clis_files(kind, cli, tmp_path):
    kr = robocal.Robot.preset(KR)
    py_out, py_dist = tmp_path / "py.csv", tmp_path / "py.d.csv"
    truth = robocal.simulate_constraints(
        kr, py_out, kind, per_feature=8, seed=5, distances_out=py_dist
    )
    assert truth == str(tmp_path / "py.truth.json")
    cli_out, cli_dist = tmp_path / "cli.csv", tmp_path / "cli.d.csv"
    cli(
        "simulate", "--robot", KR, "--truth", "random", "--constraint", kind,
        "--per-feature", "8", "--seed", "5", "--noise-mm", "0.01",
        "--out", str(cli_out), "--distances-out", str(cli_dist),
    )
    assert py_out.read_bytes() == cli_out.read_bytes()
    assert py_dist.read_bytes() == cli_dist.read_bytes()
    py_truth = json.loads((tmp_path / "py.truth.json").read_text())
    cli_truth = json.loads((tmp_path / "cli.truth.json").read_text())
    assert py_truth["sets"]["constraint"]["file"] == "py.csv"
    py_truth["sets"]["constraint"]["file"] = "cli.csv"
    assert py_truth == cli_truth
    # Planes have no distances; a kind that is not one is a usage error.
    with pytest.raises(robocal.UsageError, match="planes have no distances"):
        robocal.simulate_constraints(kr, tmp_path / "x.csv", "plane", distances_out=py_dist)
    with pytest.raises(robocal.UsageError, match="not point, sphere or plane"):
        robocal.simulate_constraints(kr, tmp_path / "x.csv", "circle")


def constraint_arrays(path):
    """A constraint measurement CSV as (q degrees, labels, radii or None), as written."""
    import csv

    import numpy as np

    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    qcols = [k for k in rows[0] if k.startswith("q") and k[1:].isdigit()]
    q = np.array([[float(r[k]) for k in qcols] for r in rows])
    labels = [r["constraint"] for r in rows]
    radii = None
    if "radius_mm" in rows[0]:
        radii = np.array([float(r["radius_mm"]) if r["radius_mm"] else np.nan for r in rows])
    return q, labels, radii


def distance_list(path):
    import csv

    with open(path, newline="") as f:
        return [(r["from"], r["to"], float(r["distance_mm"])) for r in csv.DictReader(f)]


def test_constraint_arrays_give_the_files_result(points):
    _, data, dist = points
    kr = robocal.Robot.preset(KR)
    q, labels, radii = constraint_arrays(data)
    a = robocal.calibrate_constraints(kr, q, labels, radius_mm=radii, distances=distance_list(dist))
    f = robocal.calibrate_files(kr, data, distances=dist)
    assert a.data["parameters"] == f.data["parameters"]
    assert a.data["constraint"] == f.data["constraint"]
    assert a.status == f.status == "calibrated"


def test_sphere_arrays_with_unknown_radius(cli, tmp_path):
    kr = robocal.Robot.preset(KR)
    data = tmp_path / "s.csv"
    cli(
        "simulate", "--robot", KR, "--truth", "random", "--constraint", "sphere",
        "--features", "3", "--per-feature", "12", "--unknown-radius", "--radius-mm", "150",
        "--noise-mm", "0.01", "--out", str(data),
    )
    q, labels, radii = constraint_arrays(data)
    assert radii is not None and all(r != r for r in radii)  # NaN: unknown
    with pytest.raises(robocal.NumericalError, match="scale is not determined"):
        robocal.calibrate_constraints(kr, q, labels, radius_mm=radii)
    with pytest.warns(RuntimeWarning, match="scale is not determined"):
        a = robocal.calibrate_constraints(kr, q, labels, radius_mm=radii, accept_unknown_scale=True)
    with pytest.warns(RuntimeWarning, match="scale is not determined"):
        f = robocal.calibrate_files(kr, data, accept_unknown_scale=True)
    assert a.data["parameters"] == f.data["parameters"]
    assert a.data["constraint"] == f.data["constraint"]


def test_constraint_arrays_refuse_what_the_file_refuses(points):
    import numpy as np

    _, data, dist = points
    kr = robocal.Robot.preset(KR)
    q, labels, _ = constraint_arrays(data)
    d = distance_list(dist)
    # A label used once (a typo), named with its row.
    typo = list(labels)
    typo[13] = "point:P9"
    with pytest.raises(robocal.InputError, match=r"constraint arrays:14.*used on 1 row"):
        robocal.calibrate_constraints(kr, q, typo, distances=d)
    # A sphere given two radii.
    sph = ["sphere:S"] * len(labels)
    r = np.full(len(labels), 25.0)
    r[5] = 30.0
    with pytest.raises(robocal.InputError, match="radius 30 mm here but 25 mm"):
        robocal.calibrate_constraints(kr, q, sph, radius_mm=r)
    # A radius on a point's row.
    with pytest.raises(robocal.InputError, match="not a sphere"):
        robocal.calibrate_constraints(kr, q, labels, radius_mm=np.full(len(labels), 25.0), distances=d)
    # A bad label, counts that do not match, an unknown name in the distances.
    with pytest.raises(robocal.InputError, match="unknown constraint kind `line`"):
        robocal.calibrate_constraints(kr, q, ["line:A"] * len(labels))
    with pytest.raises(robocal.InputError, match="one label per row"):
        robocal.calibrate_constraints(kr, q, labels[:-1], distances=d)
    with pytest.raises(robocal.InputError, match="one per row"):
        robocal.calibrate_constraints(kr, q, labels, radius_mm=[1.0], distances=d)
    with pytest.raises(robocal.InputError, match="`P7` is not a point or sphere"):
        robocal.calibrate_constraints(kr, q, labels, distances=d + [("P1", "P7", 100.0)])
    with pytest.raises(robocal.InputError, match="not a positive length"):
        robocal.calibrate_constraints(kr, q, labels, distances=[("P1", "P2", -1.0)])
    # Without distances: the scale, as the file.
    with pytest.raises(robocal.NumericalError, match="accept_unknown_scale=True"):
        robocal.calibrate_constraints(kr, q, labels)


def test_plan_constraints_writes_the_clis_file(cli, tmp_path):
    kr = robocal.Robot.preset(KR)
    py_out, cli_out = tmp_path / "py.csv", tmp_path / "cli.csv"
    p = robocal.plan_constraints(
        kr, "point", features=3, per_feature=8, candidates_per_feature=40, distances=True,
        seed=3, out=py_out,
    )
    cli(
        "plan", "--robot", KR, "--constraint", "point", "--features", "3", "--per-feature", "8",
        "--candidates-per-feature", "40", "--distances", "--seed", "3", "--out", str(cli_out),
    )
    assert py_out.read_bytes() == cli_out.read_bytes()
    q, labels, radii = constraint_arrays(cli_out)
    assert (p.q == q).all() and p.constraint == labels and p.radius_mm is None
    assert p.scale_known and "base pose" in p.unseen[0]
    assert p.planned["workspace_rms_mm"] < p.random["workspace_rms_mm"]
    assert len(p.planned["std"]) == len(p.parameters)
    with pytest.raises(robocal.UsageError, match="not point, sphere or plane"):
        robocal.plan_constraints(kr, "line")
    bad = tmp_path / "f.csv"
    bad.write_text("constraint,x,y,z\npoint:A,20000,0,0\n")
    with pytest.raises(robocal.InputError, match="out of the robot's reach"):
        robocal.plan_constraints(kr, features_file=bad, per_feature=4, candidates_per_feature=10)
