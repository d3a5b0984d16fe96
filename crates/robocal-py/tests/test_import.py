"""import_measurements: the CLI's `robocal import`, the same CSV and report, the same errors."""

import pytest

import robocal
from conftest import example


def test_same_csv_and_report_as_the_cli(cli, tmp_path):
    pts, jts = example("import/kr480-points.xyz"), example("import/kr480-kuka-axes.csv")
    out = tmp_path / "py.csv"
    got = robocal.import_measurements(
        pts, jts, "name", out, length_unit="in",
        joint_columns=["A1", "A2", "A3", "A4", "A5", "A6"], name_column="Point",
    )
    assert out.read_text() == got.csv
    cli_out = tmp_path / "cli.csv"
    printed = cli("import", "--points", pts, "--joints", jts, "--match", "name", "--length-unit",
                  "in", "--joint-columns", "A1,A2,A3,A4,A5,A6", "--name-column", "Point",
                  "--out", str(cli_out))
    assert cli_out.read_text() == got.csv
    assert got.csv.splitlines()[0].startswith("axis1,axis2,axis3,axis4,axis5,axis6,x,y,z")
    # The same report; the CLI names the settings by its flags (`--length-unit`).
    assert len(printed.splitlines()) == len(got.report) + 1
    assert all(line in printed for line in got.report if "setting" not in line)
    assert any("the `length_unit` setting" in line for line in got.report)


def test_time_matching_finds_the_clock_offset():
    got = robocal.import_measurements(
        example("import/kr480-timed-leica.csv"), example("import/kr480-rtde.txt"), "time")
    assert any("found from the dwells" in line for line in got.report)
    assert len(got.csv.splitlines()) == 13


def test_bad_input_names_the_file_line_and_setting(tmp_path):
    f = tmp_path / "m.txt"
    f.write_text("0.1 0.2 0.3\n1.1 0.2 0.3\n0.1 1.2 0.3\n")
    with pytest.raises(robocal.InputError, match="length_unit"):
        robocal.import_measurements(f, example("import/kr480-joints.txt"), "order")
    with pytest.raises(robocal.UsageError, match="match_by"):
        robocal.import_measurements(f, example("import/kr480-joints.txt"), "sideways")
    assert not (tmp_path / "never.csv").exists()


def test_the_robot_checks_each_points_joint_values_against_its_limits(tmp_path):
    kr = robocal.Robot.preset("kuka-kr480-r3330")
    rows = open(example("import/kr480-joints.csv")).read().splitlines()
    cells = rows[2].split(",")
    cells[2] = "25"  # q2 of the point on line 3, beyond its 20 deg limit
    rows[2] = ",".join(cells)
    joints = tmp_path / "j.csv"
    joints.write_text("\n".join(rows) + "\n")
    pts = example("import/kr480-points.csv")
    with pytest.raises(robocal.InputError, match=r"j.csv:3: field `q2`: 25 deg is outside"):
        robocal.import_measurements(pts, joints, "name", robot=kr)
    got = robocal.import_measurements(pts, joints, "name", robot=kr, nominal_limits=True)
    warned = [l for l in got.report if l.startswith("warning: ")]
    assert len(warned) == 1 and "line 3: q2 = 25 deg (limits -130..20)" in warned[0], warned
