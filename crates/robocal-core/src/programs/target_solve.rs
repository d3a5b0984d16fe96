//! The steps of compensating one program target (see [`super::compensate`]): its desired
//! joints on the nominal model, the commanded joints on the calibrated one, the values to write
//! and the joints the controller reaches with them, checked against the target.

use super::frames::Frames;
use super::seed::{branch_joints, Branch, BranchJoints};
use super::{pose_distance, Format, TargetKind};
use crate::compensation::{Compensator, DampedLeastSquares, IkReport, IkSolver};
use crate::frame::Frame;
use crate::model::Robot;

/// The values `v` of a target of kind `kind` as the controller stores their text.
pub(super) fn stored_values(format: Format, kind: TargetKind, v: &[f64]) -> Vec<f64> {
    v.iter()
        .enumerate()
        .map(|(k, x)| format.precision(kind, k).stored(*x))
        .collect()
}

/// The desired joints (the controller's reading, nominal model) of a target whose stored values
/// are `old_stored` (`program` its pose in the program's frames), the calibrated model's tool
/// frame to reach, and whether the joints are on the target's branch; `None` when the nominal
/// model cannot reach a Cartesian target.
pub(super) fn desired_and_target(
    kind: TargetKind,
    format: Format,
    fr: &Frames,
    comp: &Compensator<'_, DampedLeastSquares>,
    old_stored: &[f64],
    program: &Frame,
    branch: &Branch,
) -> Option<(Vec<f64>, Frame, bool)> {
    let nominal = comp.nominal();
    match kind {
        TargetKind::Joints => {
            let d = nominal
                .joint_space()
                .joints_from_axes(&format.axes_of(old_stored));
            let p = nominal.tool_pose(&d);
            Some((d, p, true))
        }
        TargetKind::Pose => {
            let xc = fr.to_model(program, nominal.tool_frame());
            let (d, ok) = match branch_joints(nominal, &comp.pose_solver, &xc, branch) {
                BranchJoints::Found(d) => (d, true),
                BranchJoints::Other(d) => (d, false),
                BranchJoints::Unreachable => return None,
            };
            Some((d, fr.to_model(program, comp.calibrated().tool_frame()), ok))
        }
    }
}

/// Solves the calibrated model for the commanded joints `q` that reach `target` (its position
/// only unless `full_pose`) from the desired joints; returns how the solve ended.
pub(super) fn solve_commanded(
    kind: TargetKind,
    full_pose: bool,
    comp: &Compensator<'_, DampedLeastSquares>,
    desired: &[f64],
    target: &Frame,
    q: &mut [f64],
) -> IkReport {
    let cal = comp.calibrated();
    match (kind, full_pose) {
        (TargetKind::Joints, true) => comp.compensate_pose(desired, q).1,
        (TargetKind::Joints, false) => comp.compensate(desired, q).1,
        (TargetKind::Pose, true) => {
            let r = comp.pose_solver.solve(cal, target, 0, desired, q);
            comp.check_configuration(comp.nominal(), desired, q, r)
        }
        (TargetKind::Pose, false) => comp
            .solver
            .solve(cal, &target.translation.vector, desired, q),
    }
}

/// The values to write for the commanded joints `q`, as the controller stores their text, where
/// `old` are the target's values and `old_stored` their stored numbers.
pub(super) fn values_to_write(
    kind: TargetKind,
    format: Format,
    fr: &Frames,
    nominal: &Robot,
    q: &[f64],
    old: &[f64],
    old_stored: &[f64],
) -> Vec<f64> {
    let exact: Vec<f64> = match kind {
        TargetKind::Joints => format.joint_values(&nominal.joint_space().axes_from_joints(q)),
        TargetKind::Pose => format.pose_values(
            &fr.from_model(&nominal.tool_pose(q), nominal.tool_frame()),
            old,
        ),
    };
    // A number that stays the same once stored keeps its text.
    exact
        .iter()
        .enumerate()
        .map(|(k, v)| {
            let p = format.precision(kind, k);
            if p.written(*v) == old_stored[k] {
                old[k]
            } else {
                p.write(*v).parse().unwrap_or(*v)
            }
        })
        .collect()
}

/// The joints the controller moves to for the written values `new_stored` (a Cartesian target
/// on the branch of the commanded joints `q`); `None` when its inverse kinematics fails.
pub(super) fn written_joints(
    kind: TargetKind,
    format: Format,
    fr: &Frames,
    comp: &Compensator<'_, DampedLeastSquares>,
    q: &[f64],
    new_stored: &[f64],
) -> Option<Vec<f64>> {
    let nominal = comp.nominal();
    match kind {
        TargetKind::Joints => Some(
            nominal
                .joint_space()
                .joints_from_axes(&format.axes_of(new_stored)),
        ),
        TargetKind::Pose => {
            // The controller's inverse kinematics of the written pose, on the commanded branch.
            let mut qw = vec![0.0; nominal.dof()];
            let x = fr.to_model(&format.pose_of(new_stored), nominal.tool_frame());
            let r = comp.pose_solver.solve(nominal, &x, 0, q, &mut qw);
            r.status.is_converged().then_some(qw)
        }
    }
}

/// The distance (mm) and angle (deg) of the calibrated model's tool frame `actual` from
/// `target`: the position only (angle 0) unless `full_pose`.
pub(super) fn verification(actual: &Frame, target: &Frame, full_pose: bool) -> (f64, f64) {
    if full_pose {
        pose_distance(actual, target)
    } else {
        (
            (actual.translation.vector - target.translation.vector).norm(),
            0.0,
        )
    }
}
