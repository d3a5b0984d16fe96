//! The plan CSV (DESIGN.md, `robocal iso9283`): `cycle,pose,q1..qn,x_c,y_c,z_c,a_c,b_c,c_c`,
//! and the measured test data matched to it (the plan's rows with the attained x,y,z, and a,b,c
//! for 6-DoF data, optionally `time_s`). Every rejection names the file, the line and the
//! column.

use super::metrics::{PoseSamples, Sample};
use super::plan::{Plan, CYCLE_ORDER};
use crate::error::{Error, Result};
use crate::frame::{frame_vector, pose, Frame, TrackerFrame};
use crate::io::measurements::{read_measurements, Measurement, MeasurementSet, Positions};
use crate::io::row_extras::ExtrasLayout;
use crate::model::Robot;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The commanded-pose columns of a plan.
pub const POSE_COLUMNS: [&str; 6] = ["x_c", "y_c", "z_c", "a_c", "b_c", "c_c"];

/// How far (mm) a plan's joints may put the tool from its commanded position on the model the
/// plan was made for.
pub const PLAN_TOLERANCE_MM: f64 = 1e-3;

/// How far (deg, model joint values) a measured row's joints may differ from the plan's.
pub const JOINT_MATCH_DEG: f64 = 1e-6;

/// The plan as a CSV file.
pub fn plan_csv(plan: &Plan, robot: &Robot) -> Vec<u8> {
    let n = robot.dof();
    let mut out = String::from("cycle,pose");
    for i in 1..=n {
        out.push_str(&format!(",q{i}"));
    }
    for c in POSE_COLUMNS {
        out.push(',');
        out.push_str(c);
    }
    out.push('\n');
    for row in plan.rows() {
        out.push_str(&format!("{},{}", row.cycle, row.pose));
        for v in robot.joints_to_display(&plan.joints[row.pose - 1]) {
            out.push_str(&format!(",{v}"));
        }
        for v in plan.pose_vector_deg(row.pose) {
            out.push_str(&format!(",{v}"));
        }
        out.push('\n');
    }
    out.into_bytes()
}

/// A row of a plan file.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanFileRow {
    /// Line in the file.
    pub line: usize,
    /// Cycle (1-based).
    pub cycle: usize,
    /// Pose (1..5).
    pub pose: usize,
    /// The joints (rad, model values).
    pub q: Vec<f64>,
}

/// A plan read back from its CSV.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanFile {
    /// The file.
    pub path: PathBuf,
    /// The rows, in file order.
    pub rows: Vec<PlanFileRow>,
    /// The commanded poses P1..P5 (base frame).
    pub poses: Vec<Frame>,
    /// Number of cycles.
    pub cycles: usize,
}

impl PlanFile {
    /// The cube and the tool orientation (A, B, C in degrees, base frame) whose test poses the
    /// plan commands (P1 the centre, P2 at 80 % of the half diagonal towards (-,-,-)), so that
    /// another plan ([`super::make_plan`] with them given) commands the same poses: the test
    /// after calibration planned like the one before. Fails, naming the file, when the poses
    /// are not a cube's test poses at one orientation (within 1e-6 mm and 1e-6 degrees).
    pub fn cube(&self) -> Result<(super::Cube, [f64; 3])> {
        let c = self.poses[0].translation.vector;
        let p2 = self.poses[1].translation.vector;
        let h = (c.x - p2.x) / (1.0 - 2.0 * super::CORNER_FRACTION);
        let cube = super::Cube {
            centre: c,
            edge_mm: 2.0 * h,
        };
        let bad = |why: String| {
            Error::parse(
                &self.path,
                None,
                Some("x_c"),
                format!("{why}: not the test poses of a cube (robocal iso9283 plan)"),
            )
        };
        if h.is_nan() || h <= 0.0 {
            return Err(bad(format!(
                "P2 is not below P1 in x (P1 {c:?}, P2 {p2:?})"
            )));
        }
        for (k, (p, f)) in cube.test_points().iter().zip(&self.poses).enumerate() {
            let d = (p - f.translation.vector).norm();
            let turned = crate::compensation::rotation_angle(
                &(f.rotation.matrix() * self.poses[0].rotation.matrix().transpose()),
            );
            if d > 1e-6 || turned.to_degrees() > 1e-6 {
                return Err(bad(format!(
                    "P{} is {d:.3e} mm and {:.3e} deg from the cube's test pose",
                    k + 1,
                    turned.to_degrees()
                )));
            }
        }
        let v = frame_vector(&self.poses[0]);
        Ok((
            cube,
            [v[3].to_degrees(), v[4].to_degrees(), v[5].to_degrees()],
        ))
    }
}

fn column(set: &MeasurementSet, name: &str) -> Result<usize> {
    set.extra_columns
        .iter()
        .position(|c| c == name)
        .ok_or_else(|| Error::parse(&set.path, Some(1), Some(name), "missing column"))
}

fn integer(set: &MeasurementSet, row: &Measurement, k: usize, name: &str) -> Result<usize> {
    let s = row.extra[k].trim();
    s.parse::<usize>().ok().filter(|v| *v >= 1).ok_or_else(|| {
        Error::parse(
            &set.path,
            Some(row.line),
            Some(name),
            format!("`{s}` is not a positive integer"),
        )
    })
}

fn number(set: &MeasurementSet, row: &Measurement, k: usize, name: &str) -> Result<f64> {
    let s = row.extra[k].trim();
    s.parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| {
            Error::parse(
                &set.path,
                Some(row.line),
                Some(name),
                format!("`{s}` is not a finite number"),
            )
        })
}

fn pose_number(set: &MeasurementSet, row: &Measurement, k: usize) -> Result<usize> {
    let p = integer(set, row, k, "pose")?;
    if p > 5 {
        return Err(Error::parse(
            &set.path,
            Some(row.line),
            Some("pose"),
            format!("{p} is not a pose of the test (1..5 for P1..P5)"),
        ));
    }
    Ok(p)
}

/// Reads a plan CSV for `robot`, checking that it is whole (every cycle visits P1..P5 once, the
/// same commanded pose for a pose in every cycle, the same joints too) and made for this robot:
/// the joints reach the commanded pose on `robot` or, for a compensated plan, on `calibrated`
/// (within [`PLAN_TOLERANCE_MM`]).
pub fn read_plan(path: &Path, robot: &Robot, calibrated: Option<&Robot>) -> Result<PlanFile> {
    let set = read_measurements(path, robot.joint_space(), Positions::Ignored)?;
    if let Some(c) = set.extra_columns.iter().find(|c| {
        c.len() > 1 && (c.starts_with('q') || c.starts_with("axis")) && {
            let digits = c.trim_start_matches("axis").trim_start_matches('q');
            !digits.is_empty() && digits.chars().all(|d| d.is_ascii_digit())
        }
    }) {
        return Err(Error::parse(
            path,
            Some(1),
            Some(c),
            format!(
                "a joint column beyond the {} joints of robot `{}`: a plan for another robot",
                robot.dof(),
                robot.name()
            ),
        ));
    }
    let (kc, kp) = (column(&set, "cycle")?, column(&set, "pose")?);
    let kx = POSE_COLUMNS
        .iter()
        .map(|c| column(&set, c))
        .collect::<Result<Vec<_>>>()?;
    let mut poses: [Option<(usize, Frame, Vec<f64>)>; 5] = Default::default();
    let mut seen: BTreeMap<(usize, usize), usize> = BTreeMap::new();
    let mut rows = Vec::with_capacity(set.rows.len());
    for r in &set.rows {
        let cycle = integer(&set, r, kc, "cycle")?;
        let p = pose_number(&set, r, kp)?;
        if let Some(first) = seen.insert((cycle, p), r.line) {
            return Err(Error::parse(
                path,
                Some(r.line),
                Some("pose"),
                format!("cycle {cycle} visits P{p} again (first on line {first})"),
            ));
        }
        let mut v = [0.0; 6];
        for (j, k) in kx.iter().enumerate() {
            v[j] = number(&set, r, *k, POSE_COLUMNS[j])?;
        }
        for a in &mut v[3..] {
            *a = a.to_radians();
        }
        let f = pose(&v);
        match &poses[p - 1] {
            None => {
                check_reaches(path, r, p, &f, robot, calibrated)?;
                poses[p - 1] = Some((r.line, f, r.q.clone()));
            }
            Some((line, f0, q0)) => {
                let moved = (f.translation.vector - f0.translation.vector).norm();
                let turned = crate::compensation::rotation_angle(
                    &(f.rotation.matrix() * f0.rotation.matrix().transpose()),
                );
                if moved > 1e-6 || turned.to_degrees() > 1e-6 {
                    return Err(Error::parse(
                        path,
                        Some(r.line),
                        Some("x_c"),
                        format!("the commanded pose of P{p} differs from line {line}'s"),
                    ));
                }
                let dq = max_joint_difference_deg(robot, &r.q, q0);
                if dq > JOINT_MATCH_DEG {
                    return Err(Error::parse(
                        path,
                        Some(r.line),
                        Some("q1"),
                        format!("the joints of P{p} differ from line {line}'s by {dq:.3e}"),
                    ));
                }
            }
        }
        rows.push(PlanFileRow {
            line: r.line,
            cycle,
            pose: p,
            q: r.q.clone(),
        });
    }
    let cycles = seen.keys().map(|k| k.0).max().unwrap_or(0);
    for (k, p) in poses.iter().enumerate() {
        if p.is_none() {
            return Err(Error::parse(
                path,
                None,
                Some("pose"),
                format!("no row for P{}: not an ISO 9283 plan", k + 1),
            ));
        }
    }
    for c in 1..=cycles {
        for p in CYCLE_ORDER {
            if !seen.contains_key(&(c, p)) {
                return Err(Error::parse(
                    path,
                    None,
                    Some("cycle"),
                    format!("cycle {c} has no row for P{p}"),
                ));
            }
        }
    }
    Ok(PlanFile {
        path: path.to_owned(),
        rows,
        poses: poses.into_iter().map(|p| p.expect("checked").1).collect(),
        cycles,
    })
}

fn max_joint_difference_deg(robot: &Robot, a: &[f64], b: &[f64]) -> f64 {
    let (a, b) = (robot.joints_to_display(a), robot.joints_to_display(b));
    a.iter()
        .zip(&b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

fn check_reaches(
    path: &Path,
    r: &Measurement,
    p: usize,
    f: &Frame,
    robot: &Robot,
    calibrated: Option<&Robot>,
) -> Result<()> {
    let off = |m: &Robot| (m.tool_position(&r.q) - f.translation.vector).norm();
    let nominal_off = off(robot);
    if nominal_off <= PLAN_TOLERANCE_MM || calibrated.is_some_and(|c| off(c) <= PLAN_TOLERANCE_MM) {
        return Ok(());
    }
    Err(Error::parse(
        path,
        Some(r.line),
        Some("q1"),
        format!(
            "the joints of P{p} put the tool of robot `{}` {nominal_off:.3} mm from the commanded \
             position{}: a plan for another robot",
            robot.name(),
            if calibrated.is_some() {
                " (and not on its calibrated model either)"
            } else {
                ""
            }
        ),
    ))
}

/// Reads the measured test data and matches them to the plan: each row must carry `cycle` and
/// `pose` of a plan row and its joints (within [`JOINT_MATCH_DEG`]); every row of the plan must
/// be measured once. Points (and 6-DoF orientations) are mapped to the base frame by `frame`.
/// Returns the samples of P1..P5.
pub fn read_test_data(
    path: &Path,
    plan: &PlanFile,
    robot: &Robot,
    frame: &TrackerFrame,
) -> Result<Vec<PoseSamples>> {
    let set = read_measurements(path, robot.joint_space(), Positions::Required)?;
    let (kc, kp) = (column(&set, "cycle")?, column(&set, "pose")?);
    let kt = set.extra_columns.iter().position(|c| c == "time_s");
    let layout = ExtrasLayout::of(&set)?;
    let planned: BTreeMap<(usize, usize), &PlanFileRow> =
        plan.rows.iter().map(|r| ((r.cycle, r.pose), r)).collect();
    let mut seen: BTreeMap<(usize, usize), usize> = BTreeMap::new();
    let mut samples: Vec<Vec<Sample>> = vec![Vec::new(); 5];
    let rf = *frame.pose().rotation.matrix();
    for r in &set.rows {
        let cycle = integer(&set, r, kc, "cycle")?;
        let p = pose_number(&set, r, kp)?;
        let Some(pr) = planned.get(&(cycle, p)) else {
            return Err(Error::parse(
                path,
                Some(r.line),
                Some("cycle"),
                format!(
                    "cycle {cycle}, P{p} is not in the plan {} ({} cycles): the rows do not \
                     match the plan",
                    plan.path.display(),
                    plan.cycles
                ),
            ));
        };
        let dq = max_joint_difference_deg(robot, &r.q, &pr.q);
        if dq > JOINT_MATCH_DEG {
            return Err(Error::parse(
                path,
                Some(r.line),
                Some("q1"),
                format!(
                    "the joints differ from the plan's (line {} of {}) by {dq:.3e}: the rows do \
                     not match the plan",
                    pr.line,
                    plan.path.display()
                ),
            ));
        }
        if let Some(first) = seen.insert((cycle, p), r.line) {
            return Err(Error::parse(
                path,
                Some(r.line),
                Some("pose"),
                format!("cycle {cycle}, P{p} measured again (first on line {first})"),
            ));
        }
        let extras = layout.read(&set, r)?;
        let time_s = match kt {
            Some(k) => Some(number(&set, r, k, "time_s")?),
            None => None,
        };
        samples[p - 1].push(Sample {
            cycle,
            position: frame.to_base(&r.p.expect("positions required")),
            rotation: extras.rotation.map(|m| rf * m),
            time_s,
        });
    }
    for (k, s) in samples.iter().enumerate() {
        if s.is_empty() {
            return Err(Error::parse(
                path,
                None,
                Some("pose"),
                format!("P{} was never measured", k + 1),
            ));
        }
    }
    let missing_cycles: Vec<usize> = (1..=plan.cycles)
        .filter(|c| !seen.keys().any(|k| k.0 == *c))
        .collect();
    if !missing_cycles.is_empty() {
        return Err(Error::parse(
            path,
            None,
            Some("cycle"),
            format!(
                "cycle(s) {} of the plan's {} not measured",
                list(&missing_cycles),
                plan.cycles
            ),
        ));
    }
    let missing: Vec<String> = plan
        .rows
        .iter()
        .filter(|r| !seen.contains_key(&(r.cycle, r.pose)))
        .map(|r| format!("cycle {} P{}", r.cycle, r.pose))
        .collect();
    if !missing.is_empty() {
        return Err(Error::parse(
            path,
            None,
            Some("pose"),
            format!(
                "{} planned row(s) not measured: {}",
                missing.len(),
                missing.join(", ")
            ),
        ));
    }
    Ok(samples
        .into_iter()
        .enumerate()
        .map(|(k, s)| PoseSamples {
            pose: k + 1,
            commanded: plan.poses[k],
            samples: s,
        })
        .collect())
}

fn list(v: &[usize]) -> String {
    let shown: Vec<String> = v.iter().take(10).map(|c| c.to_string()).collect();
    let more = if v.len() > 10 { ", ..." } else { "" };
    format!("{}{more}", shown.join(", "))
}
