"""Result: the result JSON in and out, and the calibrated robot it holds."""

import json

import numpy as np
import pytest

import robocal
from conftest import example


@pytest.fixture(scope="module")
def fit(ur5, real_data):
    from conftest import load_csv

    q, xyz, _ = load_csv(real_data / "jacobi_ur5_grid.csv")
    # The geometric model: the result's robots are the given robot's parameters.
    return robocal.calibrate(ur5, q, xyz, model="geometric")


def test_json_round_trip(fit, tmp_path):
    text = fit.to_json()
    again = robocal.Result.from_json(text)
    assert again.to_json() == text
    p = tmp_path / "r.json"
    fit.write(p)
    assert p.read_text() == text
    assert robocal.Result.read(p).to_json() == text
    assert fit.tracker_frame.keys() == {"x", "y", "z", "a", "b", "c"}


def test_calibrated_robot_is_the_clis(fit, cli, tmp_path):
    p = tmp_path / "r.json"
    fit.write(p)
    cal = fit.calibrated_robot()
    q = [10.0, -80.0, 90.0, 0.0, 90.0, 0.0]
    out = json.loads(cli("fk", "--params", str(p), "--joints", ",".join(map(str, q)), "--json"))
    assert np.array_equal(cal.fk(q), [out["x"], out["y"], out["z"]])
    # Degrees in the file, radians inside: the round trip may move the last bit.
    for name, e in fit.parameters.items():
        assert cal.get(name) == pytest.approx(e.calibrated, rel=1e-14, abs=1e-12)
        assert fit.nominal_robot().get(name) == pytest.approx(e.nominal, rel=1e-14, abs=1e-12)


def test_calibrated_robot_checks_the_nominal(fit):
    kr = robocal.Robot.preset("kuka-kr480-r3330")
    with pytest.raises(robocal.RobocalError):
        fit.calibrated_robot(kr)


def test_bad_json_is_an_input_error():
    with pytest.raises(robocal.InputError) as e:
        robocal.Result.from_json('{"parameters": 3}')
    assert e.value.exit_code == 3
    with pytest.raises(robocal.InputError):
        robocal.Result.from_json("not json")


def test_missing_file_is_a_file_error(tmp_path):
    with pytest.raises(robocal.FileError) as e:
        robocal.Result.read(tmp_path / "none.json")
    assert "none.json" in str(e.value) and e.value.exit_code == 4


def test_evaluate_is_the_clis(fit, real_data, cli, tmp_path):
    from conftest import load_csv

    p = tmp_path / "r.json"
    fit.write(p)
    vq, vxyz, _ = load_csv(real_data / "jacobi_ur5_random.csv")
    ev = fit.evaluate(vq, vxyz)
    out = json.loads(cli("evaluate", "--params", str(p), "--data", str(real_data / "jacobi_ur5_random.csv"),
                         "--against", "model", "--json"))
    for series in ("nominal", "calibrated"):
        for k, v in ev[series]["stats"].items():
            assert abs(v - out[series][k]) <= 1e-12 * max(1, abs(v)), (series, k, v, out[series][k])
        assert ev[series]["errors"].shape == (20, 3)
        assert np.allclose(np.linalg.norm(ev[series]["errors"], axis=1), ev[series]["norms"], rtol=0, atol=1e-12)
    assert robocal.evaluate(fit, vq, vxyz)["calibrated"]["stats"] == ev["calibrated"]["stats"]
    with pytest.raises(robocal.InputError, match="xyz"):
        fit.evaluate(vq, vxyz[:, :2])


def test_compensate_is_the_clis(fit, real_data, cli, tmp_path):
    from conftest import load_csv

    p = tmp_path / "r.json"
    fit.write(p)
    data = real_data / "jacobi_ur5_random.csv"
    vq, _, _ = load_csv(data)
    c = fit.compensate(vq)
    assert c["commanded"].shape == (20, 6) and len(c["status"]) == 20
    out = tmp_path / "commanded.csv"
    cli("compensate", "--params", str(p), "--joints", str(data), "--out", str(out))
    import numpy as np_

    a = np_.genfromtxt(out, delimiter=",", names=True, dtype=None, encoding="utf-8")
    cq = np_.column_stack([a[f"q{i}"].astype(float) for i in range(1, 7)])
    # The CLI writes its joints rounded for the file; the same solve otherwise.
    assert np.allclose(c["commanded"], cq, rtol=0, atol=1e-8), np.abs(c["commanded"] - cq).max()
    # Rounded as the file rounds them, the same digits.
    text = open(out).read().splitlines()
    col = text[0].split(",").index("q1")
    written = [l.split(",")[col:col + 6] for l in text[1:]]
    digits = len(written[0][0].split(".")[1])
    assert [[f"{v:.{digits}f}" for v in row] for row in c["commanded"]] == written
    assert all(s == "converged" for s in c["status"])
    # The calibrated model at the commanded joints reaches the nominal model's point.
    cal = fit.calibrated_robot()
    assert np.allclose(cal.fk(c["commanded"]), fit.nominal_robot().fk(vq), atol=1e-5)
    assert np.array_equal(c["desired_position"], fit.nominal_robot().fk(vq))
    one = robocal.compensate(fit, vq[0])
    assert one["commanded"].shape == (6,)
    with pytest.raises(robocal.UsageError, match="max_iterations"):
        fit.compensate(vq, max_iterations=0)
    # Position only, as `--position-only`: the same point, other joints than the full pose.
    pc = fit.compensate(vq, position_only=True)
    out2 = tmp_path / "commanded-position.csv"
    cli("compensate", "--params", str(p), "--joints", str(data), "--out", str(out2), "--position-only")
    b = np_.genfromtxt(out2, delimiter=",", names=True, dtype=None, encoding="utf-8")
    bq = np_.column_stack([b[f"q{i}"].astype(float) for i in range(1, 7)])
    assert np.allclose(pc["commanded"], bq, rtol=0, atol=1e-8)
    assert np.allclose(cal.fk(pc["commanded"]), fit.nominal_robot().fk(vq), atol=1e-5)
    assert np.all(c["residual_deg"] <= 1e-6)
