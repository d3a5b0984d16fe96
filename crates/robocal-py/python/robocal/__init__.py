"""robocal: kinematic calibration of industrial robots from laser-tracker measurements.

The Python face of the robocal toolkit (the CLI ``robocal`` and the Rust library
``robocal-core``): robots from presets, robot files and result files; forward kinematics and
Jacobians of many poses at once on numpy arrays; the CLI's calibration with its options,
returning a :class:`Result` that reads and writes the CLI's result JSON; evaluation and
compensation with a result; simulated measurement sessions (:func:`simulate`) and pose plans
(:func:`plan`), whose arrays hold exactly the numbers the CLI writes for the same seed.

Units are those of every robocal interface: millimetres and degrees (mm for a prismatic
joint's value). Errors are :class:`RobocalError` subclasses carrying the CLI's exit code in
``exit_code`` and the library's message.

Example (the UR5 data of the README)::

    import numpy as np, robocal
    ur5 = robocal.Robot.from_file("examples/ur5.toml")
    d = np.loadtxt("jacobi_ur5_grid.csv", delimiter=",", skiprows=1)
    res = robocal.calibrate(ur5, d[:, :6], d[:, 6:9])
    print(res.errors["calibration"]["after"]["mean_mm"])

    # The paper's experiment in simulation: plan 75 poses, measure them on a robot with
    # random errors, calibrate.
    kr = robocal.Robot.preset("kuka-kr480-r3330")
    p = robocal.plan(kr, 75, seed=1)
    sim = robocal.simulate(kr, "random", joints=p.poses, seed=7)
    res = robocal.calibrate(kr, sim.q, sim.xyz)
"""

from __future__ import annotations

import json
import os
import warnings
from typing import Any, Dict, Mapping, NamedTuple, Optional, Sequence, Tuple, Union

from . import _robocal
from ._robocal import (
    FileError,
    ImplausibleError,
    InputError,
    NumericalError,
    RobocalError,
    Iso9283Plan,
    Plan,
    PlanQuality,
    Robot,
    Simulation,
    UsageError,
)

__version__: str = _robocal.__version__

__all__ = [
    "Robot",
    "Result",
    "Parameter",
    "calibrate",
    "calibrate_files",
    "calibrate_constraints",
    "plan_constraints",
    "ConstraintPlan",
    "evaluate",
    "compensate",
    "simulate",
    "simulate_constraints",
    "Simulation",
    "plan",
    "Plan",
    "PlanQuality",
    "RobocalError",
    "UsageError",
    "InputError",
    "FileError",
    "NumericalError",
    "ImplausibleError",
    "import_measurements",
    "Imported",
    "iso9283_plan",
    "iso9283_evaluate",
    "Iso9283Plan",
    "STATUS_CALIBRATED",
    "STATUS_PARTIAL",
    "STATUS_IMPLAUSIBLE",
]

#: ``Result.status`` of a finished calibration.
STATUS_CALIBRATED = "calibrated"
#: ``Result.status`` of a solver that did not converge (``keep_partial=True``).
STATUS_PARTIAL = "partial"
#: ``Result.status`` of a fit that failed the plausibility gate (``accept_implausible=True``).
STATUS_IMPLAUSIBLE = "implausible"


class Parameter(NamedTuple):
    """One model parameter of a result: values in ``unit`` (mm or deg)."""

    nominal: float
    calibrated: float
    unit: str
    fixed: bool
    std: Optional[float]


class Result:
    """A calibration result: the CLI's result JSON (``robocal calibrate --out``), read-only.

    Build one with :func:`calibrate`, :meth:`from_json` or :meth:`read`. The JSON text is kept
    exactly as robocal writes it (:meth:`to_json`); the properties read it.
    """

    __slots__ = ("_text", "_parsed", "library_seconds")

    def __init__(self, text: str, library_seconds: Optional[float] = None) -> None:
        """Wraps result JSON ``text`` already checked by robocal (use :meth:`from_json`)."""
        self._text = text
        self._parsed: Optional[Dict[str, Any]] = None
        #: Seconds the calibration spent in the library (robocal-core's ``calibrate``, the
        #: function the CLI calls); None for a result read from JSON.
        self.library_seconds = library_seconds

    @property
    def _data(self) -> Dict[str, Any]:
        # Parsed on first use: a calibration in a loop need not pay for it.
        if self._parsed is None:
            self._parsed = json.loads(self._text)
        return self._parsed

    @classmethod
    def from_json(cls, text: str) -> "Result":
        """A result from JSON text, checked as the CLI checks a result file."""
        return cls(_robocal.parse_result(text))

    @classmethod
    def read(cls, path: Union[str, os.PathLike]) -> "Result":
        """A result file (``robocal calibrate --out``)."""
        return cls(_robocal.read_result(os.fspath(path)))

    def to_json(self) -> str:
        """The result JSON, as ``robocal calibrate --out`` writes it."""
        return self._text

    def write(self, path: Union[str, os.PathLike]) -> None:
        """Writes the result JSON to ``path`` (atomically: nothing half-written)."""
        _robocal.write_result(self._text, os.fspath(path))

    @property
    def data(self) -> Dict[str, Any]:
        """The whole result JSON as Python objects (a copy)."""
        return json.loads(self._text)

    @property
    def status(self) -> str:
        """``"calibrated"``, ``"partial"`` or ``"implausible"``."""
        return self._data.get("status", STATUS_CALIBRATED)

    @property
    def parameters(self) -> Dict[str, Parameter]:
        """Every parameter, in model order: name -> :class:`Parameter`."""
        return {
            name: Parameter(
                e["nominal"], e["calibrated"], e["unit"], e["fixed"], e.get("std")
            )
            for name, e in self._data["parameters"].items()
        }

    @property
    def stds(self) -> Dict[str, Optional[float]]:
        """Standard deviation of every identified parameter (its unit); None where unavailable."""
        return {
            name: e.get("std")
            for name, e in self._data["parameters"].items()
            if not e["fixed"]
        }

    @property
    def tracker_frame(self) -> Dict[str, float]:
        """The tracker frame's pose in the base frame: x, y, z (mm), a, b, c (deg)."""
        return dict(self._data["tracker_frame"])

    @property
    def errors(self) -> Dict[str, Any]:
        """Error statistics (mm) before/after, for ``calibration`` and ``validation``."""
        return json.loads(json.dumps(self._data["errors"]))

    @property
    def identifiability(self) -> Optional[Dict[str, Any]]:
        """Which parameters were identified, which fixed and why (None in older files)."""
        v = self._data.get("identifiability")
        return None if v is None else json.loads(json.dumps(v))

    @property
    def model_selection(self) -> Optional[Dict[str, Any]]:
        """How the model was chosen (``model="auto"``): each candidate with its cross-validated
        error, and a ``remark`` when families given explicitly look like overfitting (None when
        no choice was made)."""
        v = self._data.get("model_selection")
        return None if v is None else json.loads(json.dumps(v))

    @property
    def constraint(self) -> Optional[Dict[str, Any]]:
        """A calibration from constraint data (no tracker): the features as estimated, where the
        scale came from, what the data cannot see, and the frame (up to the base pose); None for
        a tracker calibration."""
        v = self._data.get("constraint")
        return None if v is None else json.loads(json.dumps(v))

    @property
    def prediction(self) -> Optional[Dict[str, Any]]:
        """The predicted error at new poses spread like the calibration poses."""
        v = self._data.get("prediction")
        return None if v is None else dict(v)

    def evaluate(
        self,
        q: Any,
        xyz: Any,
        *,
        nominal: Optional[Robot] = None,
        nominal_limits: bool = False,
    ) -> Dict[str, Dict[str, Any]]:
        """The errors of measured points under this result's models: ``robocal evaluate
        --against model`` (validation, the paper's Table IV on new points).

        ``q`` (n, dof) in degrees, ``xyz`` (n, 3) in mm in the tracker frame. Returns
        ``{"nominal": S, "calibrated": S}`` with ``S = {"errors": (n, 3) measured minus model
        (mm, base frame), "norms": (n,), "stats": {n, mean_mm, std_mm, max_mm, rms_mm, p95_mm}}``.
        The measured points are moved into the base frame by the result's tracker frame (the
        nominal series by the frame fitted to the nominal model, as the CLI does).
        """
        out, notes = _robocal.evaluate_arrays(self._text, q, xyz, nominal, nominal_limits)
        for n in notes:
            warnings.warn(n, RuntimeWarning, stacklevel=2)
        return out

    def compensate(
        self,
        q: Any,
        *,
        nominal: Optional[Robot] = None,
        tolerance_mm: float = 1e-6,
        max_iterations: int = 500,
        payload_kg: Optional[float] = None,
        accept_implausible: bool = False,
        position_only: bool = False,
        tolerance_deg: float = 1e-6,
    ) -> Dict[str, Any]:
        """Compensated joint commands for desired poses (paper, eq. 12-14): ``robocal compensate
        --joints``. By default the full pose (position and orientation of the tool, on the
        desired configuration); ``position_only=True`` compensates the tool point only (the
        paper's eq. 14, ``--position-only``).

        ``q`` (n, dof): the desired joint values in degrees (the poses the nominal model would
        reach). Returns ``commanded`` (n, dof; degrees: the calibrated model puts the tool where
        the nominal one puts it at ``q``), ``desired_position`` (n, 3; mm, base frame),
        ``status`` (list: "converged", "joint_limit", "unreachable", "not_converged",
        "configuration_change", "singular"), ``residual_mm`` (n,), ``residual_deg`` (n,) and
        ``iterations`` (n,). A partial result raises
        :class:`InputError`; an implausible one :class:`ImplausibleError` unless
        ``accept_implausible``. ``payload_kg``: the payload now carried, for a result whose
        compliances are physical.
        """
        out, notes = _robocal.compensate_arrays(
            self._text,
            q,
            nominal,
            tolerance_mm,
            max_iterations,
            payload_kg,
            accept_implausible,
            position_only,
            tolerance_deg,
        )
        for n in notes:
            warnings.warn(n, RuntimeWarning, stacklevel=2)
        return out

    def robots(self, nominal: Optional[Robot] = None) -> Tuple[Robot, Robot]:
        """The nominal robot (the one the result embeds, or ``nominal`` checked to agree with it)
        and the calibrated one."""
        return _robocal.result_robots(self._text, nominal)

    def calibrated_robot(self, nominal: Optional[Robot] = None) -> Robot:
        """The calibrated model (see :meth:`robots`)."""
        return self.robots(nominal)[1]

    def nominal_robot(self) -> Robot:
        """The nominal model the result embeds."""
        return self.robots()[0]

    def __repr__(self) -> str:
        e = self._data["errors"]["calibration"]["after"]
        return (
            f"Result(status={self.status!r}, {len(self._data['parameters'])} parameters, "
            f"calibration after: mean {e['mean_mm']:.4f} mm, max {e['max_mm']:.4f} mm)"
        )


def _options(**kw: Any) -> Dict[str, Any]:
    return {k: v for k, v in kw.items() if v is not None}


def _finish(outcome: Tuple[str, str, Sequence[str], float]) -> Result:
    text, _status, notes, seconds = outcome
    for n in notes:
        warnings.warn(n, RuntimeWarning, stacklevel=3)
    return Result(text, seconds)


ArrayLike = Any
Names = Union[str, Sequence[str]]
Joints = Union[str, Sequence[int]]


def calibrate(
    robot: Robot,
    q: ArrayLike,
    xyz: ArrayLike,
    *,
    validate: Optional[Tuple[ArrayLike, ArrayLike]] = None,
    plane: Optional[Tuple[ArrayLike, ArrayLike]] = None,
    objective: str = "adaptive",
    robust_loss: str = "cauchy",
    robust_scale: Optional[float] = None,
    fix: Names = (),
    free: Names = (),
    beta: Joints = "none",
    compliance: Optional[Joints] = None,
    payload_kg: Optional[float] = None,
    harmonics: Optional[int] = None,
    backlash: Optional[Joints] = None,
    thermal: Optional[str] = None,
    model: str = "auto",
    affine: bool = False,
    rank_tol: Optional[float] = None,
    max_iterations: int = 1000,
    tracker_sigma: Optional[Tuple[float, float]] = None,
    orientation_weight: Optional[float] = None,
    validate_refit_frame: bool = False,
    nominal_limits: bool = False,
    keep_partial: bool = False,
    accept_implausible: bool = False,
) -> Result:
    """Calibrates ``robot`` from measured points: the CLI's ``robocal calibrate``.

    ``q`` (n, dof): joint values in degrees (mm for a prismatic joint); ``xyz`` (n, 3): the
    tracker's readings in mm. ``validate=(q, xyz)``: points held out and evaluated with the fitted
    frame; ``plane=(q, xyz)``: the paper's plane points for the initial frame. Every option is
    the CLI flag of the same name (README, "calibrate"): ``objective`` "adaptive" (default),
    "sum-of-norms" (the paper's eq. 4), "least-squares" or "robust" (with ``robust_loss``
    "cauchy" or "huber"); ``fix``/``free`` parameter names; ``beta`` "parallel", "none" or joint
    numbers; ``model`` "auto" (default: the families the data support, by cross-validation;
    ``result`` records the choice in ``model_selection``) or "geometric"; ``compliance`` "auto",
    "none" or joint numbers, with ``payload_kg``, ``harmonics`` 0..8, ``backlash`` "auto", "none"
    or joint numbers (against each row's approach direction: a file's ``dir1..dirN``, else the
    row order) and ``thermal`` "auto", "per-link" (one coefficient per link) or "none" (against
    a file's ``temperature_c``, referred to the calibration rows' mean temperature) fix that family (None: chosen by ``model="auto"``,
    none with "geometric"); ``tracker_sigma=(fixed_mm, per_m_mm)``; and so on.

    Rows outside the joint limits raise :class:`InputError` unless ``nominal_limits``. A solver
    that does not converge raises :class:`NumericalError` (``keep_partial=True``: a result marked
    "partial" and a warning); a fit that fails the plausibility gate raises
    :class:`ImplausibleError` (``accept_implausible=True``: marked "implausible"). The GIL is
    released while the calibration runs.
    """
    opts = _options(
        objective=objective,
        robust_loss=robust_loss,
        robust_scale=robust_scale,
        fix=fix,
        free=free,
        beta=beta,
        compliance=compliance,
        payload_kg=payload_kg,
        harmonics=harmonics,
        backlash=backlash,
        thermal=thermal,
        model=model,
        affine=affine,
        rank_tol=rank_tol,
        max_iterations=max_iterations,
        tracker_sigma=tracker_sigma,
        orientation_weight=orientation_weight,
        validate_refit_frame=validate_refit_frame,
        nominal_limits=nominal_limits,
        keep_partial=keep_partial,
        accept_implausible=accept_implausible,
    )
    return _finish(_robocal.calibrate_arrays(robot, q, xyz, plane, validate, opts))


def calibrate_files(
    robot: Robot,
    data: Union[str, os.PathLike],
    validate: Optional[Union[str, os.PathLike]] = None,
    *,
    distances: Optional[Union[str, os.PathLike]] = None,
    accept_unknown_scale: bool = False,
    **options: Any,
) -> Result:
    """Calibrates ``robot`` from measurement CSV files, as ``robocal calibrate --data DATA
    [--validate VALIDATE]``: the rows' ``set`` column (plane, validation), ``target``, 6-DoF
    ``a,b,c`` and ``sigma_mm`` columns, and the files' names in errors, all as the CLI reads
    them. ``options`` are those of :func:`calibrate`.

    A file with a ``constraint`` column (fixed points, spheres, planes; no tracker) is
    calibrated as ``robocal calibrate --data DATA [--distances DISTANCES]
    [--accept-unknown-scale]``: ``distances`` a CSV ``from,to,distance_mm``; without a known
    distance or sphere radius the scale is undetermined and :class:`NumericalError` is raised
    unless ``accept_unknown_scale``. The result is up to the base pose (its ``constraint``
    section says so, with the features and what the data cannot see). Of ``options`` the model
    (``model``, ``compliance``, ``payload_kg``, ``harmonics``, ``backlash``, ``thermal``, as
    for tracker data: ``model="auto"``, the default, chooses the families not given by
    cross-validation by configuration and the result has ``model_selection``),
    ``accept_implausible``, ``nominal_limits`` and ``rank_tol`` apply to such data.
    """
    known = calibrate.__kwdefaults__ or {}
    for k in options:
        if k not in known or k in ("validate", "plane"):
            raise TypeError(f"calibrate_files() got an unexpected keyword argument {k!r}")
    if _robocal.is_constraint_file(robot, os.fspath(data)):
        if validate is not None:
            raise UsageError(
                "validate: constraint data have no tracker points to validate against (not "
                "supported with a constraint file)"
            )
        applies = (
            "accept_implausible",
            "nominal_limits",
            "rank_tol",
            "model",
            "compliance",
            "payload_kg",
            "harmonics",
            "backlash",
            "thermal",
        )
        given = {k: v for k, v in options.items() if v != known.get(k)}
        for k in given:
            if k not in applies:
                raise UsageError(f"{k}: does not apply to constraint data (a constraint column)")
        return _finish(
            _robocal.calibrate_constraint_file_model(
                robot,
                os.fspath(data),
                None if distances is None else os.fspath(distances),
                accept_unknown_scale,
                given,
            )
        )
    if distances is not None or accept_unknown_scale:
        raise UsageError(
            "distances and accept_unknown_scale apply to constraint data (a measurement file "
            "with a constraint column)"
        )
    opts = _options(**options)
    return _finish(
        _robocal.calibrate_files(
            robot,
            os.fspath(data),
            None if validate is None else os.fspath(validate),
            opts,
        )
    )


def evaluate(result: Result, q: ArrayLike, xyz: ArrayLike, **options: Any) -> Dict[str, Dict[str, Any]]:
    """The CLI's ``robocal evaluate --params RESULT --against model`` on arrays: see
    :meth:`Result.evaluate`."""
    return result.evaluate(q, xyz, **options)


def compensate(result: Result, q: ArrayLike, **options: Any) -> Dict[str, Any]:
    """The CLI's ``robocal compensate --params RESULT --joints`` on arrays: see
    :meth:`Result.compensate`."""
    return result.compensate(q, **options)


def plan(
    robot: Robot,
    poses: int = 75,
    *,
    candidates: int = 10000,
    seed: int = 1,
    criterion: str = "workspace",
    tracker: Optional[Sequence[float]] = None,
    range_mm: Optional[Tuple[float, float]] = None,
    include: Optional[Union[ArrayLike, str, "os.PathLike[str]"]] = None,
    floor_mm: float = 0.0,
    footprint_mm: Optional[float] = None,
    noise_mm: float = 0.010,
    noise_per_m: float = 0.005,
) -> Plan:
    """The poses worth measuring: the CLI's ``robocal plan``.

    Chooses ``poses`` joint configurations of ``robot`` from ``candidates`` random ones (seeded
    by ``seed``, under the simulation's rules ``floor_mm`` and ``footprint_mm`` and, with
    ``range_mm=(min, max)``, the tracker's working range from ``tracker``). ``criterion``:
    ``"workspace"`` (default; I-optimality, the mean model error the parameters' uncertainty
    leaves over the workspace) or ``"d-optimal"`` (the parameters' joint confidence region).
    ``include``: poses measured anyway (an array (m, dof) in degrees or a joints CSV): part of
    the design, not among the returned poses. ``noise_mm`` (and, with ``tracker``,
    ``noise_per_m``) is the per-axis noise the standard deviations are predicted at.

    Returns a :class:`Plan`: ``poses`` (n, dof) in degrees, exactly as ``robocal plan --out``
    writes them for the same arguments, and the quality figures the CLI prints (``planned`` and
    ``random``: observability, log_det, predicted stds, workspace RMS). The GIL is released
    while planning.
    """
    p, notes = _robocal.plan_poses(
        robot,
        poses,
        candidates=candidates,
        seed=seed,
        criterion=criterion,
        tracker=tracker,
        range_mm=range_mm,
        include=include,
        floor_mm=floor_mm,
        footprint_mm=footprint_mm,
        noise_mm=noise_mm,
        noise_per_m=noise_per_m,
    )
    for n in notes:
        warnings.warn(n, RuntimeWarning, stacklevel=2)
    return p


from ._importing import Imported, import_measurements  # noqa: E402
from ._simulating import PerJoint, simulate, simulate_constraints  # noqa: E402
from ._iso9283 import iso9283_evaluate, iso9283_plan  # noqa: E402
from ._constraints import ConstraintPlan, calibrate_constraints, plan_constraints  # noqa: E402
