"""``robocal.simulate`` and ``robocal.simulate_constraints``: the virtual cell (the CLI's
``robocal simulate``, with a tracker or with constraints instead)."""

from __future__ import annotations

import os
import warnings
from typing import Any, Optional, Sequence, Union

from . import _robocal
from ._robocal import Robot, Simulation

ArrayLike = Any

PerJoint = Union[float, Sequence[float]]


def simulate(
    robot: Robot,
    truth: Union[str, "os.PathLike[str]", Robot] = "random",
    poses: Optional[int] = None,
    *,
    joints: Optional[Union[ArrayLike, str, "os.PathLike[str]"]] = None,
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
    """Measures a virtual robot with a virtual laser tracker: the CLI's ``robocal simulate``.

    ``robot`` is the nominal robot (what the controller believes); ``truth`` the robot that
    really moves: ``"random"`` (``robot`` with seeded random geometric errors of
    ``length_error_mm`` (default 0.5) and ``angle_error_deg`` (default 0.03), and with
    ``tilt_parallel_axes`` a Hayati tilt of every nominally parallel axis), a preset name, a
    robot file, an earlier session's truth file (``*.truth.json``: its tracker frame too) or a
    :class:`Robot`. Either ``poses`` random calibration poses (with the paper's three plane
    points unless ``plane=False``, at height ``plane_z_mm``, and ``validation`` validation
    poses) or ``joints``: the joint values to measure, an array (n, dof) in degrees or a joints
    CSV (e.g. :attr:`Plan.poses`, or commanded joints in the verification phase).

    Every other option is the CLI flag of the same name (README, "simulate"): ``seed`` (same
    seed, same numbers), ``tracker`` (x, y, z, A, B, C in mm and degrees; the tracker's pose in
    the base frame), the noise ``noise_mm + noise_per_m * distance`` per axis, the pose rules
    ``floor_mm`` and ``footprint_mm``, gravity deflection (``compliance`` in rad/(N m), and
    ``link_masses_kg``, one value or one per joint, ``payload_kg``), gross outliers
    (``outlier_fraction`` of the readings displaced by ``outlier_min_mm``..``outlier_max_mm``),
    ``all_targets`` (every reflector of the robot file's ``tools``, a ``target`` per row),
    ``orientation_sigma_deg`` (6-DoF readings: ``abc``), and the real cell's effects:
    ``repeatability_deg`` (a random error per joint and move, 1-sigma deg; ``"default"`` for the
    class default), ``backlash_deg`` (half the gear play per joint, deg; ``"auto"`` for the
    class default; writes ``dir1..dirN``), ``thermal="auto"`` (the arm warming up over the
    session, shaped by ``thermal_rise_c``, ``thermal_start_s`` and ``seconds_per_pose``, and
    with ``thermal_link_gain`` (one value or one per link) the links growing unevenly; writes
    ``temperature_c`` and ``time_s``) and ``station`` (a fresh tracker set-up, 1, 2, ..).

    Returns a :class:`Simulation` whose arrays hold the values ``robocal simulate --out`` writes
    for the same arguments (joint values to 1e-9 degree, readings to 1e-6 mm), so calibrating
    them gives the CLI's result; :meth:`Simulation.write` writes the CLI's very files. The
    settings are checked by the library as the CLI's flags are, with the same messages: a count
    outside its limits or an argument given where it does not apply raises :class:`UsageError`,
    a value outside its plausible range or a bad array :class:`InputError`. The GIL is released
    while the session runs.
    """
    sim = _robocal.simulate_session(
        robot,
        truth,
        poses,
        joints=joints,
        seed=seed,
        validation=validation,
        plane=plane,
        plane_z_mm=plane_z_mm,
        tracker=tracker,
        noise_mm=noise_mm,
        noise_per_m=noise_per_m,
        length_error_mm=length_error_mm,
        angle_error_deg=angle_error_deg,
        tilt_parallel_axes=tilt_parallel_axes,
        floor_mm=floor_mm,
        footprint_mm=footprint_mm,
        compliance=compliance,
        link_masses_kg=link_masses_kg,
        payload_kg=payload_kg,
        outlier_fraction=outlier_fraction,
        outlier_min_mm=outlier_min_mm,
        outlier_max_mm=outlier_max_mm,
        all_targets=all_targets,
        orientation_sigma_deg=orientation_sigma_deg,
        repeatability_deg=repeatability_deg,
        backlash_deg=backlash_deg,
        thermal=thermal,
        thermal_rise_c=thermal_rise_c,
        thermal_start_s=thermal_start_s,
        seconds_per_pose=seconds_per_pose,
        thermal_link_gain=thermal_link_gain,
        station=station,
    )
    for w in sim.warnings:
        warnings.warn(w, RuntimeWarning, stacklevel=2)
    return sim


def simulate_constraints(
    robot: Robot,
    out: Union[str, os.PathLike],
    constraint: str = "point",
    *,
    truth: Union[str, "os.PathLike[str]", Robot] = "random",
    features: int = 4,
    per_feature: int = 20,
    noise_mm: float = 0.010,
    radius_mm: float = 25.0,
    unknown_radius: bool = False,
    tilt_deg: float = 60.0,
    span_mm: float = 300.0,
    seed: int = 1,
    distances_out: Optional[Union[str, os.PathLike]] = None,
) -> str:
    """Constraint data without a tracker: the CLI's ``robocal simulate --constraint
    point|sphere|plane`` (the same files for the same settings). The true robot brings its tool
    point to ``features`` fixed points, onto spheres (``radius_mm``; ``unknown_radius`` leaves
    ``radius_mm`` empty in the file) or onto planes, in ``per_feature`` configurations each;
    writes the measurement CSV to ``out``, the truth file beside it (returned: its path) and,
    with ``distances_out``, the true distances between the points or sphere centres.
    """
    return os.fspath(
        _robocal.simulate_constraints(
            robot,
            os.fspath(out),
            truth,
            constraint,
            features,
            per_feature,
            noise_mm,
            radius_mm,
            unknown_radius,
            tilt_deg,
            span_mm,
            seed,
            None if distances_out is None else os.fspath(distances_out),
        )
    )
