"""Type stubs of robocal's Python bindings (see the docstrings of the package for the details)."""

import os
import pathlib
from typing import Any, Dict, List, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

STATUS_CALIBRATED: str
STATUS_PARTIAL: str
STATUS_IMPLAUSIBLE: str

ArrayLike = npt.ArrayLike
FloatArray = npt.NDArray[np.float64]
PathLike = Union[str, os.PathLike]
Names = Union[str, Sequence[str]]
Joints = Union[str, Sequence[int]]
PerJoint = Union[float, Sequence[float]]
IntArray = npt.NDArray[np.int64]

class RobocalError(Exception):
    """Every error robocal raises; ``exit_code`` is the CLI's exit code for it."""

    exit_code: int

class UsageError(RobocalError):
    """A bad argument (exit code 2)."""

class InputError(RobocalError):
    """Bad input data: a wrong shape, dtype or value, a malformed file (exit code 3)."""

class FileError(RobocalError):
    """A file could not be read or written (exit code 4)."""

class NumericalError(RobocalError):
    """No convergence, too few points, an unidentifiable model (exit code 5)."""

class ImplausibleError(RobocalError):
    """A converged fit that fails the plausibility gate (exit code 6)."""

class Robot:
    """A robot model. Joint values in degrees (mm for a prismatic joint), lengths in mm."""

    @staticmethod
    def preset(name: str) -> Robot:
        """A built-in preset, e.g. "kuka-kr480-r3330"."""
    @staticmethod
    def presets() -> list[str]:
        """The names of the built-in presets."""
    @staticmethod
    def from_file(path: PathLike) -> Robot:
        """A TOML robot description."""
    @staticmethod
    def load(arg: str) -> Robot:
        """A preset name or a robot file, as the CLI's ``--robot``."""
    @staticmethod
    def from_toml(text: str, name: str = ...) -> Robot:
        """A robot from the text of a TOML robot description."""
    @property
    def name(self) -> str: ...
    @property
    def dof(self) -> int: ...
    @property
    def convention(self) -> str:
        """"mdh" or "dh"."""
    @property
    def joint_types(self) -> list[str]: ...
    @property
    def target_count(self) -> int: ...
    @property
    def limits(self) -> FloatArray:
        """(dof, 2): min, max per joint."""
    @property
    def parameter_names(self) -> list[str]:
        """Parameter names in model order: the columns of :meth:`jacobian`."""
    @property
    def parameters(self) -> Dict[str, float]: ...
    @property
    def units(self) -> Dict[str, str]: ...
    def get(self, name: str) -> float: ...
    def set(self, name: str, value: float) -> None: ...
    def copy(self) -> Robot: ...
    def fk(self, q: ArrayLike, target: int = 0) -> FloatArray:
        """(n, dof) -> (n, 3) tool positions in mm; (dof,) -> (3,)."""
    def fk_pose(self, q: ArrayLike, target: int = 0) -> FloatArray:
        """(n, dof) -> (n, 4, 4) tool frames; (dof,) -> (4, 4)."""
    def jacobian(self, q: ArrayLike, target: int = 0) -> FloatArray:
        """(n, dof) -> (n, 3, p): d position / d parameter, mm per mm or per degree."""
    def joint_jacobian(self, q: ArrayLike, target: int = 0) -> FloatArray:
        """(n, dof) -> (n, 3, dof): d position / d joint, mm per degree (or per mm)."""
    def within_limits(self, q: ArrayLike) -> Union[npt.NDArray[np.bool_], bool]: ...

class Parameter(NamedTuple):
    nominal: float
    calibrated: float
    unit: str
    fixed: bool
    std: Optional[float]

class Result:
    """A calibration result: the CLI's result JSON."""

    library_seconds: Optional[float]
    def __init__(self, text: str, library_seconds: Optional[float] = None) -> None: ...
    @classmethod
    def from_json(cls, text: str) -> Result: ...
    @classmethod
    def read(cls, path: PathLike) -> Result: ...
    def to_json(self) -> str: ...
    def write(self, path: PathLike) -> None: ...
    @property
    def data(self) -> Dict[str, Any]: ...
    @property
    def status(self) -> str: ...
    @property
    def parameters(self) -> Dict[str, Parameter]: ...
    @property
    def stds(self) -> Dict[str, Optional[float]]: ...
    @property
    def tracker_frame(self) -> Dict[str, float]: ...
    @property
    def errors(self) -> Dict[str, Any]: ...
    @property
    def identifiability(self) -> Optional[Dict[str, Any]]: ...
    @property
    def constraint(self) -> Optional[Dict[str, Any]]: ...
    @property
    def prediction(self) -> Optional[Dict[str, Any]]: ...
    def evaluate(
        self, q: ArrayLike, xyz: ArrayLike, *, nominal: Optional[Robot] = None, nominal_limits: bool = False
    ) -> Dict[str, Dict[str, Any]]:
        """Errors under the nominal and calibrated models: {"nominal": S, "calibrated": S}."""
    def compensate(
        self,
        q: ArrayLike,
        *,
        nominal: Optional[Robot] = None,
        tolerance_mm: float = 1e-6,
        max_iterations: int = 500,
        payload_kg: Optional[float] = None,
        accept_implausible: bool = False,
        position_only: bool = False,
        tolerance_deg: float = 1e-6,
    ) -> Dict[str, Any]:
        """Compensated joints (eq. 12-14), full pose unless position_only: commanded,
        desired_position, status, residual_mm, residual_deg, iterations."""
    def robots(self, nominal: Optional[Robot] = None) -> Tuple[Robot, Robot]: ...
    def calibrated_robot(self, nominal: Optional[Robot] = None) -> Robot: ...
    def nominal_robot(self) -> Robot: ...

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
    tracker_sigma: Optional[Union[Tuple[float, float], str]] = None,
    orientation_weight: Optional[float] = None,
    validate_refit_frame: bool = False,
    nominal_limits: bool = False,
    keep_partial: bool = False,
    accept_implausible: bool = False,
) -> Result:
    """The CLI's ``robocal calibrate`` on arrays."""

def calibrate_files(
    robot: Robot,
    data: PathLike,
    validate: Optional[PathLike] = None,
    *,
    distances: Optional[PathLike] = None,
    accept_unknown_scale: bool = False,
    **options: Any,
) -> Result:
    """The CLI's ``robocal calibrate --data DATA [--validate VALIDATE]``; a constraint file with
    ``[--distances DISTANCES] [--accept-unknown-scale]``."""

def calibrate_constraints(
    robot: Robot,
    q: ArrayLike,
    constraint: Sequence[str],
    *,
    radius_mm: Optional[ArrayLike] = None,
    distances: Optional[Sequence[Tuple[str, str, float]]] = None,
    accept_unknown_scale: bool = False,
    accept_implausible: bool = False,
    nominal_limits: bool = False,
    rank_tol: Optional[float] = None,
) -> Result:
    """The array form of ``calibrate_files`` on constraint data: joints (n, dof) in degrees, one
    ``constraint`` label per row, ``radius_mm`` per row (NaN: unknown), ``distances`` as
    ``(from, to, mm)``."""

class ConstraintPlan(NamedTuple):
    """A constraint plan: ``robocal plan --constraint``'s file and figures."""

    q: FloatArray
    constraint: List[str]
    radius_mm: Optional[FloatArray]
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
    features_file: Optional[PathLike] = None,
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
    out: Optional[PathLike] = None,
) -> ConstraintPlan:
    """The CLI's ``robocal plan --constraint KIND`` (or ``--features-file``)."""

def simulate_constraints(
    robot: Robot,
    out: PathLike,
    constraint: str = "point",
    *,
    truth: Union[str, PathLike, Robot] = "random",
    features: int = 4,
    per_feature: int = 20,
    noise_mm: float = 0.010,
    radius_mm: float = 25.0,
    unknown_radius: bool = False,
    tilt_deg: float = 60.0,
    span_mm: float = 300.0,
    seed: int = 1,
    distances_out: Optional[PathLike] = None,
) -> str:
    """The CLI's ``robocal simulate --constraint point|sphere|plane``."""

def evaluate(result: Result, q: ArrayLike, xyz: ArrayLike, **options: Any) -> Dict[str, Dict[str, Any]]:
    """The CLI's ``robocal evaluate --against model`` on arrays."""

def compensate(result: Result, q: ArrayLike, **options: Any) -> Dict[str, Any]:
    """The CLI's ``robocal compensate --joints`` on arrays."""


class Simulation:
    """A simulated measurement session (:func:`simulate`): the rows ``robocal simulate --out``
    writes, with the values as written (joints to 1e-9 degree, readings to 1e-6 mm)."""

    @property
    def q(self) -> FloatArray:
        """(n, dof) joint values of every row, degrees (mm for a prismatic joint)."""
    @property
    def xyz(self) -> FloatArray:
        """(n, 3) tracker readings of every row, mm in the tracker frame."""
    @property
    def exact(self) -> FloatArray:
        """(n, 3) readings without noise or outliers, full precision."""
    @property
    def sets(self) -> Optional[List[str]]:
        """Each row's set: "plane", "calibration", "validation" (None for measured joints)."""
    @property
    def ids(self) -> Optional[List[str]]:
        """Each row's id: P1.., C1.., V1.. (None for measured joints)."""
    @property
    def target(self) -> Optional[IntArray]:
        """(n,) each row's target (1-based), with ``all_targets``."""
    @property
    def abc(self) -> Optional[FloatArray]:
        """(n, 3) measured orientations A, B, C (deg, tracker frame), with
        ``orientation_sigma_deg``."""
    @property
    def columns(self) -> Dict[str, List[str]]:
        """The CSV's further columns by name (id, set, target, a, b, c, a joints file's own)."""
    @property
    def calibration(self) -> Tuple[FloatArray, FloatArray]:
        """(q, xyz) of the calibration rows."""
    @property
    def validation(self) -> Tuple[FloatArray, FloatArray]:
        """(q, xyz) of the validation rows (empty without ``validation``)."""
    @property
    def plane(self) -> Tuple[FloatArray, FloatArray]:
        """(q, xyz) of the paper's three plane points (empty with ``plane=False``)."""
    @property
    def plane_z_mm(self) -> Optional[float]: ...
    @property
    def truth(self) -> Robot:
        """The robot that really moved."""
    @property
    def nominal(self) -> Robot: ...
    @property
    def tracker_frame(self) -> Dict[str, float]:
        """The tracker's pose in the base frame: x, y, z (mm), a, b, c (deg)."""
    @property
    def seed(self) -> int: ...
    @property
    def outlier_rows(self) -> IntArray:
        """Rows (0-based) given a gross outlier."""
    @property
    def outlier_displacements(self) -> FloatArray:
        """(k, 3) the outliers' displacements, mm."""
    @property
    def deflection_mm(self) -> Optional[npt.NDArray[np.float64]]:
        """(n,) how far gravity moved each tool point, with ``compliance``."""
    @property
    def warnings(self) -> List[str]: ...
    def to_csv(self) -> str:
        """The measurement CSV, as ``robocal simulate --out`` writes it."""
    def write(self, path: PathLike, validation_path: Optional[PathLike] = None) -> pathlib.Path:
        """Writes the CLI's files (CSV, PATH.truth.json, validation CSV); returns the truth
        file's path."""
    def __len__(self) -> int: ...

class PlanQuality:
    """How well a set of poses identifies the parameters."""

    observability: float
    log_det: float
    std: List[float]
    workspace_rms_mm: float

class Plan:
    """A pose plan (:func:`plan`): what ``robocal plan`` writes and prints."""

    @property
    def poses(self) -> FloatArray:
        """(n, dof) the chosen poses in degrees, as ``robocal plan --out`` writes them."""
    @property
    def parameters(self) -> List[str]:
        """The identifiable parameters (the order of ``PlanQuality.std``)."""
    @property
    def units(self) -> List[str]: ...
    @property
    def planned(self) -> PlanQuality: ...
    @property
    def random(self) -> PlanQuality:
        """As many random poses under the same rules, for comparison."""
    @property
    def stds(self) -> Dict[str, Tuple[float, float]]:
        """Predicted standard deviations {name: (planned, random)}."""
    @property
    def criterion(self) -> str: ...
    @property
    def criterion_values(self) -> Tuple[float, float]:
        """The criterion after the greedy selection and after the exchange passes."""
    @property
    def exchanges(self) -> Tuple[int, int]:
        """Exchange passes run and poses they replaced."""
    @property
    def included(self) -> int: ...
    @property
    def candidates(self) -> int: ...
    @property
    def seed(self) -> int: ...
    @property
    def noise(self) -> Tuple[float, float]:
        """(noise_mm, noise_per_m) the standard deviations are predicted at."""
    def to_csv(self) -> str: ...
    def write(self, path: PathLike) -> None:
        """Writes the poses as ``robocal plan --out`` does."""
    def __len__(self) -> int: ...

def simulate(
    robot: Robot,
    truth: Union[str, PathLike, Robot] = "random",
    poses: Optional[int] = None,
    *,
    joints: Optional[Union[ArrayLike, PathLike]] = None,
    seed: int = 1,
    validation: int = 0,
    plane: bool = True,
    plane_z_mm: Optional[float] = None,
    tracker: Optional[Sequence[float]] = None,
    noise_mm: float = 0.010,
    noise_per_m: float = 0.005,
    length_error_mm: Optional[float] = None,
    angle_error_deg: Optional[float] = None,
    tilt_parallel_axes: bool = False,
    floor_mm: float = 0.0,
    footprint_mm: Optional[float] = None,
    compliance: Optional[PerJoint] = None,
    link_masses_kg: Optional[PerJoint] = None,
    payload_kg: Optional[float] = None,
    outlier_fraction: Optional[float] = None,
    outlier_min_mm: Optional[float] = None,
    outlier_max_mm: Optional[float] = None,
    all_targets: bool = False,
    orientation_sigma_deg: Optional[float] = None,
    repeatability_deg: Optional[Union[str, PerJoint]] = None,
    backlash_deg: Optional[Union[str, PerJoint]] = None,
    thermal: Optional[str] = None,
    thermal_rise_c: Optional[float] = None,
    thermal_start_s: Optional[float] = None,
    seconds_per_pose: Optional[float] = None,
    thermal_link_gain: Optional[PerJoint] = None,
    station: int = 0,
) -> Simulation:
    """The CLI's ``robocal simulate``: random poses (``poses``, ``validation``, the plane
    points) or ``joints`` measured on ``truth`` by a virtual tracker."""

def plan(
    robot: Robot,
    poses: int = 75,
    *,
    candidates: int = 10000,
    seed: int = 1,
    criterion: str = "workspace",
    tracker: Optional[Sequence[float]] = None,
    range_mm: Optional[Tuple[float, float]] = None,
    include: Optional[Union[ArrayLike, PathLike]] = None,
    floor_mm: float = 0.0,
    footprint_mm: Optional[float] = None,
    noise_mm: float = 0.010,
    noise_per_m: float = 0.005,
) -> Plan:
    """The CLI's ``robocal plan``: the poses worth measuring, and their predicted quality."""


class Imported(NamedTuple):
    csv: str
    report: Sequence[str]

def import_measurements(
    points: Union[str, PathLike],
    joints: Union[str, PathLike],
    match_by: str,
    out: Optional[Union[str, PathLike]] = None,
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
) -> Imported: ...

class Iso9283Plan:
    """An ISO 9283 test plan (:func:`iso9283_plan`): what ``robocal iso9283 plan`` writes."""

    @property
    def edge_mm(self) -> float:
        """The cube's edge (mm)."""
    @property
    def centre(self) -> Tuple[float, float, float]:
        """The cube's centre (mm, base frame): P1."""
    @property
    def poses(self) -> FloatArray:
        """(5, 6) the commanded poses P1..P5: x, y, z (mm), A, B, C (deg), base frame."""
    @property
    def joints(self) -> FloatArray:
        """(5, dof) the joints sent to the robot (deg): compensated with a result."""
    @property
    def nominal_joints(self) -> FloatArray:
        """(5, dof) the joints that reach P1..P5 on the nominal model (deg)."""
    @property
    def compensated(self) -> bool: ...
    @property
    def cycles(self) -> int: ...
    def to_csv(self) -> str: ...
    def write(self, path: PathLike) -> None:
        """Writes the plan CSV as ``robocal iso9283 plan --out`` does."""
    def program(self, program_format: str, dwell_s: float = 2.0) -> str:
        """The plan as a KRL, RAPID or URScript program (``--program``)."""

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
) -> Iso9283Plan: ...
def iso9283_evaluate(
    plan: PathLike,
    data: PathLike,
    result: Optional[Result] = None,
    *,
    robot: Optional[Robot] = None,
    frame: Optional[str] = None,
    spec: Optional[str] = None,
    tracker_mpe: Optional[str] = None,
) -> Dict[str, Any]: ...
