"""``robocal.iso9283_plan`` and ``robocal.iso9283_evaluate``: the ISO 9283 acceptance test (the
CLI's ``robocal iso9283 plan`` and ``evaluate``)."""

from __future__ import annotations

import json
import os
from typing import TYPE_CHECKING, Any, Dict, Optional, Sequence

from . import _robocal
from ._importing import _PathLike
from ._robocal import Iso9283Plan, Robot

if TYPE_CHECKING:
    from . import Result

def iso9283_plan(
    robot: Optional[Robot] = None,
    result: Optional[Result] = None,
    *,
    cycles: int = 30,
    cube_mm: Optional[float] = None,
    center: Optional[Sequence[float]] = None,
    orientation: Optional[Sequence[float]] = None,
    floor_mm: float = 0.0,
    footprint_mm: Optional[float] = None,
    poses_from: Optional[Iso9283Plan] = None,
) -> Iso9283Plan:
    """The ISO 9283 test plan: the CLI's ``robocal iso9283 plan``.

    The largest cube (edges parallel to the base axes) that ``robot`` reaches at every test pose
    with the tool ``orientation`` (A, B, C in degrees; default the tool's at the middle of the
    joint ranges), within the joint limits and away from singularities, whole above the floor
    ``floor_mm`` (default 0: the base plane the robot is mounted on) and outside the footprint
    ``footprint_mm`` (default 15 % of the chain's length; 0 allows a cube above the robot);
    ``cube_mm`` and ``center`` (x, y, z mm) fix either or both. P1 is the centre, P2..P5 on the
    measuring plane's diagonals at 10 % from the corners, ``cycles`` cycles of P1, P5, P4, P3,
    P2. With ``result`` (its robot, or ``robot``) the joints are the compensated ones on its
    calibrated model, on a cube searched as without it (shrunk in 1 % steps where the
    compensated joints fail at its boundary); ``poses_from`` (an earlier :class:`Iso9283Plan`,
    the test before calibration) gives the cube, poses and orientation exactly, as the CLI's
    ``--poses-from``.

    Returns an :class:`Iso9283Plan`: the cube, the commanded ``poses`` (5, 6), the ``joints``
    (5, dof) in degrees, the CSV the CLI writes (:meth:`Iso9283Plan.to_csv`, ``write``) and the
    robot program (:meth:`Iso9283Plan.program`). The GIL is released while the cube is searched.
    """
    return _robocal.iso9283_plan(
        robot,
        None if result is None else result.to_json(),
        cycles=cycles,
        cube_mm=cube_mm,
        center=None if center is None else [float(v) for v in center],
        orientation=None if orientation is None else [float(v) for v in orientation],
        floor_mm=floor_mm,
        footprint_mm=footprint_mm,
        poses_from=poses_from,
    )


def iso9283_evaluate(
    plan: _PathLike,
    data: _PathLike,
    result: Optional[Result] = None,
    *,
    robot: Optional[Robot] = None,
    frame: Optional[str] = None,
    spec: Optional[str] = None,
    tracker_mpe: Optional[str] = None,
) -> Dict[str, Any]:
    """The ISO 9283 figures of a measured test: the CLI's ``robocal iso9283 evaluate --json``.

    ``plan``: the plan CSV (:meth:`Iso9283Plan.write`); ``data``: the plan's rows with the
    attained ``x, y, z`` (and ``a, b, c``, ``time_s``) in the tracker frame of ``result``, or in
    the base frame with ``frame="base"`` and ``robot``. ``spec`` (``"ap=MM,rp=MM"``) gives
    pass/fail, ``tracker_mpe`` (``"MM[,MM_PER_M]"``) the tracker's MPE beside RP. Returns the
    JSON the CLI prints as a dict: ``poses`` (per pose ``ap_mm``, ``ap_x_mm``.., ``rp_mm``,
    ``tracker_mpe_mm``, ``rp_below_tracker``, ``pass``, ...), ``distance``, ``distances``,
    ``pass`` (True, False, or None without a spec). A failed spec is a result, not an error.
    Bad input raises :class:`InputError` naming the file, line and column.
    """
    text = _robocal.iso9283_evaluate(
        os.fspath(plan),
        os.fspath(data),
        None if result is None else result.to_json(),
        robot=robot,
        frame=frame,
        spec=spec,
        tracker_mpe=tracker_mpe,
    )
    return json.loads(text)
