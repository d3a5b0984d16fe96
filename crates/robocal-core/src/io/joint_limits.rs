//! Rows of a joint or measurement file whose joint values lie outside the robot's limits,
//! gathered row by row (files of any length) so that a command can refuse them (naming the first
//! with its file, line, joint, value and limits, and how many rows there are) or warn about them
//! listing the lines.

use crate::error::Error;
use crate::model::{JointLimit, JointSpace, Robot};
use crate::ranges::LIMIT_TOLERANCE_DEG;
use std::path::{Path, PathBuf};

/// Rows described one by one in messages; the rest are counted.
pub const LISTED: usize = 20;

/// One row's first joint value outside its limit (display units: degrees, or mm for a prismatic
/// joint).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LimitViolation {
    /// 1-based line of the row.
    pub line: usize,
    /// 0-based joint.
    pub joint: usize,
    /// The joint value (deg, or mm for a prismatic joint).
    pub value_deg: f64,
    /// The joint's limits (deg, or mm for a prismatic joint).
    pub min_deg: f64,
    /// See `min_deg`.
    pub max_deg: f64,
    /// The unit of the three values above (`deg` or `mm`).
    pub unit: &'static str,
    /// How many joints of the row are outside their limits.
    pub joints_outside: usize,
}

impl LimitViolation {
    fn describe(&self) -> String {
        let more = match self.joints_outside {
            1 => String::new(),
            n => format!("; {} more joint(s) outside", n - 1),
        };
        format!(
            "line {} (q{} = {} {}, limits {}..{}{more})",
            self.line,
            self.joint + 1,
            crate::ranges::fmt_value(self.value_deg),
            self.unit,
            crate::ranges::fmt_value(self.min_deg),
            crate::ranges::fmt_value(self.max_deg)
        )
    }
}

/// The rows of one file outside the limits of one robot.
#[derive(Debug, Clone, PartialEq)]
pub struct OutsideLimits {
    path: PathBuf,
    robot: String,
    limits: Vec<JointLimit>,
    joints: JointSpace,
    lines: Vec<usize>,
    listed: Vec<LimitViolation>,
}

impl OutsideLimits {
    /// An empty record for the rows of `path` against the limits of `robot`.
    pub fn new(robot: &Robot, path: &Path) -> OutsideLimits {
        OutsideLimits {
            path: path.to_owned(),
            robot: robot.name().to_owned(),
            limits: robot.limits().to_vec(),
            joints: robot.joint_space().clone(),
            lines: Vec::new(),
            listed: Vec::new(),
        }
    }

    /// Checks the joint values `q` (rad, or mm for a prismatic joint) of the row on `line`. A
    /// value beyond a limit by less than [`LIMIT_TOLERANCE_DEG`] (or as many mm: rounding in
    /// files) counts as within it.
    pub fn check(&mut self, line: usize, q: &[f64]) {
        let mut first = None;
        let mut n = 0;
        for (j, (v, l)) in q.iter().zip(&self.limits).enumerate() {
            let tol = self.joints.to_internal(j, LIMIT_TOLERANCE_DEG);
            if *v < l.min - tol || *v > l.max + tol {
                n += 1;
                first.get_or_insert((j, *v, *l));
            }
        }
        let Some((joint, v, l)) = first else { return };
        self.lines.push(line);
        if self.listed.len() < LISTED {
            let shown = |x: f64| rounded(self.joints.to_display(joint, x));
            self.listed.push(LimitViolation {
                line,
                joint,
                value_deg: shown(v),
                min_deg: shown(l.min),
                max_deg: shown(l.max),
                unit: self.joints.unit(joint).as_str(),
                joints_outside: n,
            });
        }
    }

    /// Whether every row checked was within the limits.
    pub fn is_empty(&self) -> bool {
        self.lines.is_empty()
    }

    /// The number of rows outside the limits.
    pub fn count(&self) -> usize {
        self.lines.len()
    }

    /// The lines of the rows outside the limits, in file order.
    pub fn lines(&self) -> &[usize] {
        &self.lines
    }

    /// The file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The first rows, described (`line 7 (q2 = 1000080 deg, limits -130..20)`), and a count of
    /// the rest.
    pub fn describe(&self) -> String {
        let mut s = self
            .listed
            .iter()
            .map(LimitViolation::describe)
            .collect::<Vec<_>>()
            .join(", ");
        if self.count() > self.listed.len() {
            s.push_str(&format!(
                ", ... ({} more)",
                self.count() - self.listed.len()
            ));
        }
        s
    }

    /// The rows as an error naming the file, the line, the joint, its value and limits of the
    /// first, and how many rows there are; `None` when there are none.
    pub fn to_error(&self) -> Option<Error> {
        let v = self.listed.first()?;
        let rows = match self.count() {
            1 => "it is the only row of this file outside the limits".to_owned(),
            n => format!(
                "{n} rows of this file are outside the limits: {}",
                self.describe()
            ),
        };
        Some(Error::parse(
            &self.path,
            Some(v.line),
            Some(&format!("q{}", v.joint + 1)),
            format!(
                "{} {u} is outside the joint limits of robot `{}` (q{}: {}..{} {u}); {rows}",
                crate::ranges::fmt_value(v.value_deg),
                self.robot,
                v.joint + 1,
                crate::ranges::fmt_value(v.min_deg),
                crate::ranges::fmt_value(v.max_deg),
                u = v.unit,
            ),
        ))
    }

    /// The rows as a warning: `FILE: N row(s) with joint values outside the limits of robot
    /// `NAME`: line 7 (...), ...`; `None` when there are none.
    pub fn to_warning(&self) -> Option<String> {
        (!self.is_empty()).then(|| {
            format!(
                "{}: {} row(s) with joint values outside the limits of robot `{}`: {}",
                self.path.display(),
                self.count(),
                self.robot,
                self.describe()
            )
        })
    }
}

/// A display value to the 9 decimals files hold (`1000080`, not `1000080.0000000001`).
fn rounded(v: f64) -> f64 {
    (v * 1e9).round() / 1e9
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets::preset;

    #[test]
    fn gathers_rows_outside_the_limits() {
        let robot = preset("kuka-kr480-r3330").unwrap();
        let mut o = OutsideLimits::new(&robot, Path::new("d.csv"));
        let deg = |v: [f64; 6]| v.map(f64::to_radians);
        o.check(2, &deg([0.0, -90.0, 90.0, 0.0, 45.0, 0.0]));
        // At a limit, and beyond it by file rounding only: within.
        o.check(3, &deg([185.0, -130.0 - 5e-10, 144.0, 0.0, 0.0, 0.0]));
        assert!(o.is_empty() && o.to_error().is_none() && o.to_warning().is_none());
        o.check(4, &deg([0.0, 1_000_080.0, 0.0, 0.0, 200.0, 0.0]));
        let e = o.to_error().unwrap().to_string();
        assert_eq!(
            e,
            "d.csv:4: field `q2`: 1000080 deg is outside the joint limits of robot \
             `kuka-kr480-r3330` (q2: -130..20 deg); it is the only row of this file outside the \
             limits"
        );
        for line in 5..30 {
            o.check(line, &deg([-186.0, 0.0, 0.0, 0.0, 0.0, 0.0]));
        }
        assert_eq!(o.count(), 26);
        assert_eq!(o.lines()[..3], [4, 5, 6]);
        let e = o.to_error().unwrap().to_string();
        assert!(
            e.contains(
                "26 rows of this file are outside the limits: line 4 (q2 = 1000080 deg, \
                        limits -130..20; 1 more joint(s) outside), line 5 (q1 = -186 deg, limits \
                        -185..185), "
            ),
            "{e}"
        );
        assert!(e.ends_with(", ... (6 more)"), "{e}");
        let w = o.to_warning().unwrap();
        assert!(w.starts_with("d.csv: 26 row(s) with joint values outside the limits"));
    }
}
