"""``robocal.calibrate_constraints``: calibration without a tracker from arrays of constraint
rows (the array form of ``calibrate_files`` on a file with a ``constraint`` column); and
``robocal.plan_constraints``: the configurations worth measuring for it."""

from __future__ import annotations

import json
import os
from typing import TYPE_CHECKING, Any, Dict, List, NamedTuple, Optional, Sequence, Tuple

from . import _robocal
from ._importing import _PathLike
from ._robocal import InputError, Robot

if TYPE_CHECKING:
    from . import Result


def calibrate_constraints(
    robot: Robot,
    q: Any,
    constraint: Sequence[str],
    *,
    radius_mm: Optional[Any] = None,
    distances: Optional[Sequence[Tuple[str, str, float]]] = None,
    accept_unknown_scale: bool = False,
    accept_implausible: bool = False,
    nominal_limits: bool = False,
    rank_tol: Optional[float] = None,
) -> "Result":
    """Calibrates ``robot`` from constraint rows given as arrays: the CLI's ``robocal calibrate
    --data DATA [--distances D] [--accept-unknown-scale]`` on a file with a ``constraint`` column.

    ``q`` (n, dof): joint values in degrees (mm for a prismatic joint) at which the tool point
    touched its feature; ``constraint``: one label per row, ``point:NAME``, ``sphere:NAME`` or
    ``plane:NAME``; ``radius_mm``: one value per row (a sphere's known radius; NaN where it is
    unknown or the row is not a sphere's), or None for no radius column; ``distances``: known
    distances between points or sphere centres as ``(from, to, mm)``. The rows are read by the
    file form's reader, so every refusal is the file's (:class:`InputError` naming the row, the
    arrays' rows numbered from 1, the distances' entries from line 2); without a known distance
    or radius the scale is undetermined and :class:`NumericalError` is raised unless
    ``accept_unknown_scale``. The model is chosen as :func:`calibrate_files` chooses it by default
    on a constraint file (``model="auto"``: the families the rows support, by cross-validation by
    configuration; the result's ``model_selection``). The result is up to the base pose (its
    ``constraint`` section).
    """
    from . import _finish

    if isinstance(constraint, (str, bytes)):
        raise InputError("constraint: expected one label per row, got a single string")
    labels = [str(c) for c in constraint]
    radii = None
    if radius_mm is not None:
        try:
            radii = [float(v) for v in radius_mm]
        except (TypeError, ValueError) as e:
            raise InputError(f"radius_mm: expected one number per row (NaN: unknown): {e}") from None
    dist = None
    if distances is not None:
        dist = []
        for i, d in enumerate(distances):
            try:
                a, b, mm = d
                dist.append((str(a), str(b), float(mm)))
            except (TypeError, ValueError):
                raise InputError(
                    f"distances: entry {i + 1} is not (from, to, distance_mm)"
                ) from None
    return _finish(
        _robocal.calibrate_constraint_arrays(
            robot,
            q,
            labels,
            radii,
            dist,
            accept_unknown_scale,
            accept_implausible,
            nominal_limits,
            rank_tol,
        )
    )


class ConstraintPlan(NamedTuple):
    """A constraint plan: what ``robocal plan --constraint`` writes and prints.

    ``q`` (n, dof): the configurations in degrees, exactly as the CLI writes them; ``constraint``
    the feature label of each row; ``radius_mm`` each row's radius (NaN: unknown) when the plan
    has spheres, else None; ``features``: each feature's label, nominal place (base frame, mm),
    normal and radius; ``parameters``: the robot parameters the design covers; ``unseen``: what
    such data cannot see, as the calibration says it; ``scale_known``: whether the data carry a
    length; ``planned`` and ``random``: observability, log_det, workspace_rms_mm (the predicted
    model error over the workspace) and std (per parameter) of the chosen configurations and of
    as many random ones; ``weakest``: the parameter combinations the plan sees least, each with
    its share of the predicted model error (``rms_mm``) and its ``parameters`` (name, weight).
    """

    q: Any
    constraint: List[str]
    radius_mm: Optional[Any]
    features: List[Dict[str, Any]]
    parameters: List[str]
    unseen: List[str]
    scale_known: bool
    planned: Dict[str, Any]
    random: Dict[str, Any]
    weakest: List[Dict[str, Any]]


def plan_constraints(
    robot: Robot,
    constraint: str = "point",
    *,
    features: int = 4,
    features_file: Optional[_PathLike] = None,
    per_feature: int = 20,
    candidates_per_feature: int = 200,
    radius_mm: float = 25.0,
    unknown_radius: bool = False,
    distances: bool = False,
    tilt_deg: float = 60.0,
    span_mm: float = 300.0,
    noise_mm: float = 0.01,
    seed: int = 1,
    criterion: str = "workspace",
    floor_mm: float = 0.0,
    footprint_mm: Optional[float] = None,
    out: Optional[_PathLike] = None,
) -> ConstraintPlan:
    """The configurations touching fixed points, spheres or planes worth measuring: the CLI's
    ``robocal plan --constraint KIND`` (or ``--features-file``), every argument the flag of the
    same name. ``out``: write the CLI's file there (a measurement CSV with the ``constraint``
    column, to measure). The GIL is released while planning.
    """
    import numpy as np

    q, extra, summary = _robocal.plan_constraint_configurations(
        robot,
        constraint,
        features,
        None if features_file is None else os.fspath(features_file),
        per_feature,
        candidates_per_feature,
        radius_mm,
        unknown_radius,
        distances,
        tilt_deg,
        span_mm,
        noise_mm,
        seed,
        criterion,
        floor_mm,
        footprint_mm,
        None if out is None else os.fspath(out),
    )
    cols = dict(extra)
    s = json.loads(summary)
    radii = None
    if "radius_mm" in cols:
        radii = np.array([float(v) if v else np.nan for v in cols["radius_mm"]])
    return ConstraintPlan(
        q=q,
        constraint=list(cols["constraint"]),
        radius_mm=radii,
        features=s["features"],
        parameters=s["parameters"],
        unseen=s["unseen"],
        scale_known=s["scale_known"],
        planned=s["planned"],
        random=s["random"],
        weakest=s["weakest"],
    )
