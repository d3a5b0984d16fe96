"""``robocal.import_measurements``: tracker exports and joint logs into a measurement CSV (the
CLI's ``robocal import``)."""

from __future__ import annotations

import os
from typing import NamedTuple, Optional, Sequence, Union

from . import _robocal
from ._robocal import Robot


class Imported(NamedTuple):
    """What :func:`import_measurements` made: the measurement CSV's text and the report."""

    csv: str
    report: Sequence[str]


_PathLike = Union[str, "os.PathLike[str]"]


def import_measurements(
    points: _PathLike,
    joints: _PathLike,
    match_by: str,
    out: Optional[_PathLike] = None,
    *,
    points_format: str = "auto",
    joints_format: str = "auto",
    time_offset: Optional[float] = None,
    length_unit: Optional[str] = None,
    angle_unit: Optional[str] = None,
    joint_columns: Optional[Sequence[str]] = None,
    name_column: Optional[str] = None,
    robot: Optional[Robot] = None,
    still_deg: Optional[float] = None,
    dwell_min_s: Optional[float] = None,
    time_tolerance: float = 0.2,
    nominal_limits: bool = False,
) -> Imported:
    """A tracker export and a joint log into a measurement CSV, as ``robocal import`` does.

    ``points``: a Leica, SpatialAnalyzer, xyz, headerless text or CSV export
    (``points_format``, detected by default); ``joints``: a CSV or UR RTDE joint log
    (``joints_format``). ``match_by``: ``"name"``, ``"order"`` or ``"time"`` (the log's dwells,
    with the clock offset ``time_offset``, tracker minus log in seconds, found when not given).
    ``length_unit`` (mm, m, in) for exports that do not say it; ``angle_unit`` (deg, rad) of a
    CSV log; ``joint_columns`` names a log's joint columns (controller values, written as
    ``axis1..axisN``); ``robot`` checks the joint count and each paired point's joint values
    against the robot's limits (outside them, or a log in radians read as degrees, is an
    :class:`InputError`; with ``nominal_limits`` each point outside is a warning line of the
    report and kept). Writes the CSV to ``out`` when given.
    Returns an :class:`Imported`: the CSV's text and the report's lines (the CLI prints them).
    Bad input raises :class:`InputError` naming the file, line and field.
    """
    csv, report = _robocal.import_measurements(
        os.fspath(points),
        os.fspath(joints),
        match_by,
        None if out is None else os.fspath(out),
        points_format=points_format,
        joints_format=joints_format,
        time_offset=time_offset,
        length_unit=length_unit,
        angle_unit=angle_unit,
        joint_columns=None if joint_columns is None else list(joint_columns),
        name_column=name_column,
        robot=robot,
        still_deg=still_deg,
        dwell_min_s=dwell_min_s,
        time_tolerance=time_tolerance,
        nominal_limits=nominal_limits,
    )
    return Imported(csv, report)
