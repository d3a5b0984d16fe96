"""Type stubs of robocal's Python bindings (see the docstrings of the package for the details)."""

import os
from typing import Any, Dict, NamedTuple, Optional, Sequence, Tuple, Union

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
    compliance: Joints = "none",
    payload_kg: Optional[float] = None,
    harmonics: int = 0,
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
    """The CLI's ``robocal calibrate`` on arrays."""

def calibrate_files(
    robot: Robot,
    data: PathLike,
    validate: Optional[PathLike] = None,
    **options: Any,
) -> Result:
    """The CLI's ``robocal calibrate --data DATA [--validate VALIDATE]``."""

def evaluate(result: Result, q: ArrayLike, xyz: ArrayLike, **options: Any) -> Dict[str, Dict[str, Any]]:
    """The CLI's ``robocal evaluate --against model`` on arrays."""

def compensate(result: Result, q: ArrayLike, **options: Any) -> Dict[str, Any]:
    """The CLI's ``robocal compensate --joints`` on arrays."""
