"""Constraint data with the model options of tracker data (issue 31): ``calibrate_files`` on a
constraint file takes ``model`` and the families (``compliance``, ``harmonics``, ``thermal``,
...) as the CLI's ``calibrate`` does on such a file, and returns ``model_selection``."""

import json

import pytest

import robocal

KR = "kuka-kr480-r3330"


@pytest.fixture(scope="module")
def points(cli, tmp_path_factory):
    d = tmp_path_factory.mktemp("constraint_model")
    data, dist = d / "p.csv", d / "d.csv"
    cli(
        "simulate", "--robot", KR, "--truth", "random", "--constraint", "point",
        "--noise-mm", "0.01", "--seed", "3", "--out", str(data), "--distances-out", str(dist),
    )
    return d, data, dist


def cli_result(cli, d, data, dist, name, *flags):
    out = d / name
    cli("calibrate", "--robot", KR, "--data", str(data), "--distances", str(dist), *flags,
        "--out", str(out))
    return json.loads(out.read_text())


def test_the_default_model_choice_is_the_clis(points, cli):
    d, data, dist = points
    r = robocal.calibrate_files(robocal.Robot.preset(KR), data, distances=dist)
    c = cli_result(cli, d, data, dist, "auto.json")
    assert r.data["model_selection"] == c["model_selection"]
    assert r.data["parameters"] == c["parameters"]
    sel = r.data["model_selection"]
    assert sum(x["chosen"] for x in sel["candidates"]) == 1
    assert any(x["families"] == ["compliance"] for x in sel["candidates"])


def test_explicit_families_are_the_clis(points, cli):
    d, data, dist = points
    with pytest.warns(RuntimeWarning, match="overfitting"):
        r = robocal.calibrate_files(
            robocal.Robot.preset(KR), data, distances=dist, compliance="auto", harmonics=1
        )
    c = cli_result(cli, d, data, dist, "fam.json", "--compliance", "auto", "--harmonics", "1")
    assert r.data["parameters"] == c["parameters"]
    assert r.data["model_selection"] == c["model_selection"]
    assert not r.data["parameters"]["grav2_o3"]["fixed"]
    assert not r.data["parameters"]["tsin1_1"]["fixed"]


def test_the_geometric_model_is_the_clis(points, cli):
    d, data, dist = points
    r = robocal.calibrate_files(robocal.Robot.preset(KR), data, distances=dist, model="geometric")
    c = cli_result(cli, d, data, dist, "geo.json", "--model", "geometric")
    assert r.data["parameters"] == c["parameters"]
    assert "model_selection" not in r.data and "model_selection" not in c


def test_a_family_without_its_columns_is_an_input_error(points):
    _, data, dist = points
    kr = robocal.Robot.preset(KR)
    with pytest.raises(robocal.InputError, match="temperature_c"):
        robocal.calibrate_files(kr, data, distances=dist, thermal="auto")
    with pytest.raises(robocal.InputError, match="dir1..dirN"):
        robocal.calibrate_files(kr, data, distances=dist, backlash="auto")
    with pytest.raises(robocal.UsageError, match="model"):
        robocal.calibrate_files(kr, data, distances=dist, model="everything")
