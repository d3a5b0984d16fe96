//! Robot models: a serial chain of revolute and prismatic joints described by a modified (Craig)
//! or standard Denavit–Hartenberg parameter table, joint limits, a base frame and a tool (paper,
//! section II.B), and the controller's axis map.
//!
//! Every geometric quantity that calibration may change is a [`Param`], addressable by its
//! DESIGN.md name (`alpha1`, `d3`, `base_z`, `tool_c`, ...). Values are stored in millimetres and
//! radians; [`Param::unit`] tells how a value is shown at the interfaces (mm or degrees).
//!
//! The per-joint constant part of each link transform is cached, so forward kinematics costs one
//! `sin_cos` per joint; every mutation goes through [`Robot::set`] which keeps the cache valid.

mod conditions;
pub mod controller;
pub mod description;
pub mod family;
mod joints;
mod params;
pub mod presets;
pub mod robot_file;
mod robot_params;
mod targets;
pub mod urdf;

pub use conditions::Conditions;
pub use controller::{Controller, Coupling};
pub use family::{FamilyId, ParameterFamily, PoseFrames, RigidPose};
pub use joints::{JointSpace, JointType};
pub use params::{Param, Unit};

use crate::error::{Error, Result};
use crate::frame::{self, Frame};
use nalgebra::{Matrix3, Vector3};

/// Largest number of joints a chain may have (forward kinematics keeps its frames on the stack).
pub const MAX_JOINTS: usize = 16;

/// The Denavit–Hartenberg convention of a parameter table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Convention {
    /// Modified DH (Craig), the paper's Table I:
    /// `T(i-1 -> i) = Rx(alpha_i) Tx(a_i) Ry(beta_i) Rz(q_i + phi_i) Tz(d_i)`.
    Mdh,
    /// Standard DH: `T(i-1 -> i) = Rz(q_i + phi_i) Tz(d_i) Tx(a_i) Rx(alpha_i) Ry(beta_i)`.
    Dh,
}

impl Convention {
    /// `"mdh"` or `"dh"`.
    pub fn as_str(self) -> &'static str {
        match self {
            Convention::Mdh => "mdh",
            Convention::Dh => "dh",
        }
    }
}

/// The geometric parameters of one link (mm and radians).
///
/// `beta` is Hayati's tilt about the link's y axis, the parameter MDH lacks between parallel axes;
/// it is zero and not part of the parameter list unless enabled with [`Robot::enable_beta`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Link {
    /// Twist angle alpha_i (rad).
    pub alpha: f64,
    /// Offset d_i along the joint axis (mm).
    pub d: f64,
    /// Length a_i along the common normal (mm).
    pub a: f64,
    /// Joint angle offset phi_i (rad), added to the joint value.
    pub phi: f64,
    /// Hayati tilt beta_i (rad); zero unless enabled.
    pub beta: f64,
}

/// The range a joint may move in (model joint values, internal units: radians for a revolute
/// joint, mm for a prismatic one).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointLimit {
    /// Lower bound (rad or mm).
    pub min: f64,
    /// Upper bound (rad or mm).
    pub max: f64,
}

impl JointLimit {
    /// Whether `q` (rad or mm) lies within the limit (inclusive).
    pub fn contains(&self, q: f64) -> bool {
        q >= self.min && q <= self.max
    }
}

/// A serial robot: parameter table, joint types, limits, base frame, tool and controller map.
///
/// Joints are revolute unless made prismatic with [`Robot::set_joint_types`]: a prismatic joint's
/// value (mm) adds to its row's d, its phi is a constant (DESIGN.md, "Robot file additions").
///
/// The tool point is `pose(B) * T1 * ... * Tn * pose(T0 + T)` applied to the origin, where `B` is
/// the base frame vector, `T0` the nominal tool vector (paper eq. 7) and `T` its correction (the
/// paper's column T). All three are stored in mm and radians.
#[derive(Debug, Clone, PartialEq)]
pub struct Robot {
    name: String,
    convention: Convention,
    links: Vec<Link>,
    beta_enabled: Vec<bool>,
    limits: Vec<JointLimit>,
    joints: JointSpace,
    base: [f64; 6],
    tool0: [f64; 6],
    tool: [f64; 6],
    /// Targets 2..k (further reflectors on the flange), see [`Robot::set_target_tools`].
    targets: Vec<targets::TargetTool>,
    /// The direction of gravity in the base frame (a unit vector; DESIGN.md robot file key
    /// `gravity`, default `[0, 0, -1]`: floor mounted).
    gravity: Vector3<f64>,
    /// Values of the parameter families that are not part of the link table, by family key.
    family_store: std::collections::BTreeMap<String, Vec<f64>>,
    // Caches derived from the above (kept valid by every mutator).
    link_const: Vec<Frame>,
    /// Per link without a Hayati tilt, `(sin alpha, cos alpha, a)`: its constant part is then
    /// applied by column operations ([`Robot::apply_link_constant`]).
    link_rx: Vec<Option<[f64; 3]>>,
    base_frame: Frame,
    tool_frame: Frame,
    /// The Euler axes of the base's angles and of the tool's (`T0 + T`), [`frame::euler_axes`]:
    /// the base and tool families' angular columns at every point of a Jacobian pass.
    base_axes: [Vector3<f64>; 3],
    tool_axes: [Vector3<f64>; 3],
    /// Every parameter, in model order (ascending `Param` order).
    param_list: Vec<Param>,
    /// Per family with parameters on this robot: its id and its range in `param_list`.
    family_spans: Vec<(FamilyId, std::ops::Range<usize>)>,
    /// Whether some family deflects the joints.
    deflects: bool,
}

impl Robot {
    /// Builds a robot with revolute joints (see [`Robot::set_joint_types`] for prismatic ones)
    /// and no controller map. Angles in radians, lengths in mm. Checks that every value is
    /// finite, that limits are ordered, and that the chain has 1..=[`MAX_JOINTS`] joints.
    pub fn new(
        name: impl Into<String>,
        convention: Convention,
        links: Vec<Link>,
        limits: Vec<JointLimit>,
        base: [f64; 6],
        tool0: [f64; 6],
    ) -> Result<Self> {
        let n = links.len();
        if n == 0 || n > MAX_JOINTS {
            return Err(Error::invalid(
                "joints",
                format!("a robot needs 1 to {MAX_JOINTS} joints, got {n}"),
            ));
        }
        if limits.len() != n {
            return Err(Error::invalid(
                "limits",
                format!("{} joint limits for {n} joints", limits.len()),
            ));
        }
        for (i, l) in links.iter().enumerate() {
            for (field, v) in [
                ("alpha", l.alpha),
                ("d", l.d),
                ("a", l.a),
                ("phi", l.phi),
                ("beta", l.beta),
            ] {
                if !v.is_finite() {
                    return Err(Error::invalid(
                        format!("{field}{}", i + 1),
                        "not a finite number",
                    ));
                }
            }
        }
        let joints = JointSpace::revolute(n);
        check_limits(&limits, &joints)?;
        for (what, v) in [("base", &base), ("tool", &tool0)] {
            if v.iter().any(|x| !x.is_finite()) {
                return Err(Error::invalid(what, "not a finite number"));
            }
        }
        let mut r = Robot {
            name: name.into(),
            convention,
            beta_enabled: vec![false; n],
            links,
            limits,
            joints,
            base,
            tool0,
            tool: [0.0; 6],
            targets: Vec::new(),
            gravity: Vector3::new(0.0, 0.0, -1.0),
            family_store: Default::default(),
            link_const: Vec::new(),
            link_rx: Vec::new(),
            base_frame: Frame::identity(),
            tool_frame: Frame::identity(),
            base_axes: [Vector3::zeros(); 3],
            tool_axes: [Vector3::zeros(); 3],
            param_list: Vec::new(),
            family_spans: Vec::new(),
            deflects: false,
        };
        r.refresh();
        Ok(r)
    }

    fn refresh(&mut self) {
        self.link_const = self.links.iter().map(link_constant).collect();
        self.link_rx = self.links.iter().map(link_rx).collect();
        self.refresh_base();
        self.refresh_tool();
        self.refresh_params();
    }

    /// Recomputes the base frame and its Euler axes after B changed.
    fn refresh_base(&mut self) {
        self.base_frame = frame::pose(&self.base);
        self.base_axes = frame::euler_axes(self.base[3], self.base[4]);
    }

    /// Recomputes link `i`'s constant part after one of its parameters changed.
    fn refresh_link(&mut self, i: usize) {
        self.link_const[i] = link_constant(&self.links[i]);
        self.link_rx[i] = link_rx(&self.links[i]);
    }

    /// Recomputes the tool frame and its Euler axes after T0 or T changed.
    fn refresh_tool(&mut self) {
        let mut t = self.tool0;
        for (k, v) in t.iter_mut().enumerate() {
            *v += self.tool[k];
        }
        self.tool_frame = frame::pose(&t);
        self.tool_axes = frame::euler_axes(t[3], t[4]);
    }

    /// Rebuilds the parameter list after the set of parameters changed (a tilt enabled, a
    /// family's values stored).
    fn refresh_params(&mut self) {
        let mut list = Vec::with_capacity(5 * self.dof() + 12);
        let mut spans = Vec::new();
        let mut deflects = false;
        for (k, fam) in family::all().iter().enumerate() {
            let start = list.len();
            fam.params(self, &mut list);
            if list.len() > start {
                spans.push((FamilyId::new(k), start..list.len()));
            }
            deflects |= fam.deflects_joints(self);
        }
        debug_assert!(list.windows(2).all(|w| w[0] < w[1]), "model order");
        self.param_list = list;
        self.family_spans = spans;
        self.deflects = deflects;
    }
    /// The robot's name (preset name or the `name` of its file).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Renames the robot.
    pub fn set_name(&mut self, name: impl Into<String>) {
        self.name = name.into();
    }

    /// The parameter-table convention.
    pub fn convention(&self) -> Convention {
        self.convention
    }

    /// Number of joints.
    pub fn dof(&self) -> usize {
        self.links.len()
    }

    /// An upper bound of the chain's reach (mm): `sum(|a_i| + |d_i|)` plus the length of the
    /// nominal tool translation, at least 1 mm. The scale for "how large is this robot": the
    /// plausibility gate's limits and the simulator's default footprint are fractions of it
    /// (4968 mm for the KR 480 R3330 preset, 1224 mm for the UR5 example).
    pub fn reach_mm(&self) -> f64 {
        let links: f64 = self.links.iter().map(|l| l.a.abs() + l.d.abs()).sum();
        let t = &self.tool0;
        let tool = (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt();
        (links + tool).max(1.0)
    }

    /// The link parameters (mm, rad).
    pub fn links(&self) -> &[Link] {
        &self.links
    }

    /// The joint limits (rad).
    pub fn limits(&self) -> &[JointLimit] {
        &self.limits
    }

    /// Replaces the joint limits (internal units: rad or mm).
    pub fn set_limits(&mut self, limits: Vec<JointLimit>) -> Result<()> {
        if limits.len() != self.dof() {
            return Err(Error::invalid(
                "limits",
                format!("{} joint limits for {} joints", limits.len(), self.dof()),
            ));
        }
        check_limits(&limits, &self.joints)?;
        self.limits = limits;
        Ok(())
    }

    /// The joints' types and the controller map: what converts joint values at the interfaces.
    pub fn joint_space(&self) -> &JointSpace {
        &self.joints
    }

    /// Every joint's type.
    pub fn joint_types(&self) -> &[JointType] {
        self.joints.types()
    }

    /// Joint `i`'s type (0-based).
    pub fn joint_type(&self, i: usize) -> JointType {
        self.joints.joint_type(i)
    }

    /// Joint `i`'s display unit: degrees (revolute) or mm (prismatic).
    pub fn joint_unit(&self, i: usize) -> Unit {
        self.joints.unit(i)
    }

    /// Sets the joint types (one per joint). The limits keep their numbers, now read in the new
    /// types' internal units; the controller map is kept (its offsets are display values).
    pub fn set_joint_types(&mut self, types: Vec<JointType>) -> Result<()> {
        if types.len() != self.dof() {
            return Err(Error::invalid(
                "joint types",
                format!("{} types for {} joints", types.len(), self.dof()),
            ));
        }
        self.joints = JointSpace::new(types, self.joints.controller().cloned())?;
        Ok(())
    }

    /// The controller's axis map, if the robot has one (else axis values are joint values).
    pub fn controller(&self) -> Option<&Controller> {
        self.joints.controller()
    }

    /// Sets (or, with `None`, removes) the controller's axis map.
    pub fn set_controller(&mut self, controller: Option<Controller>) -> Result<()> {
        self.joints = JointSpace::new(self.joints.types().to_vec(), controller)?;
        Ok(())
    }

    /// A joint vector from display units (degrees, or mm for a prismatic joint) to internal
    /// units (rad or mm).
    pub fn joints_from_display(&self, v: &[f64]) -> Vec<f64> {
        self.joints.joints_from_display(v)
    }

    /// A joint vector from internal units to display units (degrees, or mm for a prismatic
    /// joint).
    pub fn joints_to_display(&self, q: &[f64]) -> Vec<f64> {
        self.joints.joints_to_display(q)
    }

    /// The base frame vector B (mm, rad).
    pub fn base(&self) -> &[f64; 6] {
        &self.base
    }

    /// The nominal tool vector T0 (mm, rad).
    pub fn tool0(&self) -> &[f64; 6] {
        &self.tool0
    }

    /// The tool correction T (mm, rad).
    pub fn tool_correction(&self) -> &[f64; 6] {
        &self.tool
    }

    /// The direction of gravity in the base frame (unit vector; default `[0, 0, -1]`).
    pub fn gravity(&self) -> Vector3<f64> {
        self.gravity
    }

    /// Sets the direction of gravity in the base frame: any finite, non-zero vector, stored
    /// normalized (a robot file's `gravity`). Wall and ceiling mounted robots need it for the
    /// joint compliance family.
    pub fn set_gravity(&mut self, g: [f64; 3]) -> Result<()> {
        let v = Vector3::from(g);
        let n = v.norm();
        if !n.is_finite() || n < 1e-9 {
            return Err(Error::invalid(
                "gravity",
                format!("{g:?} is not a direction: give a non-zero vector such as [0, 0, -1]"),
            ));
        }
        self.gravity = v / n;
        self.refresh_params();
        Ok(())
    }

    /// The base frame `pose(B)`.
    pub fn base_frame(&self) -> &Frame {
        &self.base_frame
    }

    /// The Euler axes of the base's angles ([`frame::euler_axes`]), kept with the base frame:
    /// the base family's angular columns turn about them.
    #[inline]
    pub(crate) fn base_euler_axes(&self) -> &[Vector3<f64>; 3] {
        // Every mutator of the base refreshes them (`refresh_base`); a debug build checks.
        debug_assert_eq!(
            self.base_axes,
            frame::euler_axes(self.base[3], self.base[4]),
            "the base's kept Euler axes"
        );
        &self.base_axes
    }

    /// The tool frame relative to the flange, `pose(T0 + T)`.
    pub fn tool_frame(&self) -> &Frame {
        &self.tool_frame
    }

    /// `f = f * C_i` with `C_i` link `i`'s constant part (`link_constant`). Without a
    /// tilt, `C_i = Rx(alpha) Tx(a)` is applied to the columns of `f` (a dozen products instead
    /// of a full 3 x 3 product: forward kinematics is the identification's inner loop); the
    /// result is the same up to the rounding of the skipped zero terms, which is none.
    #[inline(always)]
    pub(crate) fn apply_link_constant(&self, i: usize, f: &mut Frame) {
        match self.link_rx[i] {
            Some([sa, ca, a]) => {
                let m = f.rotation.matrix();
                let (c0, c1, c2) = (m.column(0), m.column(1), m.column(2));
                f.translation.vector += c0 * a;
                let n1 = c1 * ca + c2 * sa;
                let n2 = c1 * (-sa) + c2 * ca;
                f.rotation = nalgebra::Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[
                    c0.into(),
                    n1,
                    n2,
                ]));
            }
            None => *f *= self.link_const[i],
        }
    }

    /// Whether the Hayati tilt of joint `i` (0-based) is a parameter.
    pub fn beta_enabled(&self, i: usize) -> bool {
        self.beta_enabled[i]
    }

    /// Makes the Hayati tilt `beta_{i+1}` a model parameter (it then appears in [`Robot::params`]
    /// and can be identified). Use it for a joint whose axis is nominally parallel to the previous
    /// one, where the tilt cannot be expressed by alpha/a/d/phi.
    pub fn enable_beta(&mut self, i: usize) -> Result<()> {
        if i >= self.dof() {
            return Err(Error::invalid(
                "beta",
                format!("joint {} does not exist (robot has {})", i + 1, self.dof()),
            ));
        }
        self.beta_enabled[i] = true;
        self.refresh_params();
        Ok(())
    }

    /// Enables beta on every joint whose axis is nominally parallel to the previous joint's axis
    /// (|alpha| below 1 degree for MDH; the previous link's |alpha| for DH). Returns the joints
    /// (0-based) it enabled.
    pub fn enable_beta_for_parallel_axes(&mut self) -> Vec<usize> {
        let mut out = Vec::new();
        for i in 1..self.dof() {
            let alpha = match self.convention {
                Convention::Mdh => self.links[i].alpha,
                Convention::Dh => self.links[i - 1].alpha,
            };
            if alpha.sin().abs() < 1f64.to_radians().sin() {
                let idx = match self.convention {
                    Convention::Mdh => i,
                    Convention::Dh => i - 1,
                };
                if !self.beta_enabled[idx] {
                    self.beta_enabled[idx] = true;
                    out.push(idx);
                }
            }
        }
        self.refresh_params();
        out
    }

    /// Checks a joint vector (rad or mm): length and finiteness. `context` names its origin in errors.
    pub fn check_joints(&self, q: &[f64], context: &str) -> Result<()> {
        if q.len() != self.dof() {
            return Err(Error::JointCount {
                context: context.to_owned(),
                expected: self.dof(),
                got: q.len(),
            });
        }
        if let Some(i) = q.iter().position(|v| !v.is_finite()) {
            return Err(Error::invalid(
                format!("{context}: q{}", i + 1),
                "not a finite number",
            ));
        }
        Ok(())
    }

    /// The joints (0-based) whose value in `q` (rad or mm) lies outside the limits.
    pub fn joints_outside_limits(&self, q: &[f64]) -> Vec<usize> {
        q.iter()
            .zip(&self.limits)
            .enumerate()
            .filter(|(_, (v, l))| !l.contains(**v))
            .map(|(i, _)| i)
            .collect()
    }
}

/// Checks that every limit is finite and ordered; messages give values in display units.
fn check_limits(limits: &[JointLimit], joints: &JointSpace) -> Result<()> {
    for (i, l) in limits.iter().enumerate() {
        if !l.min.is_finite() || !l.max.is_finite() {
            return Err(Error::invalid(
                format!("limits of joint {}", i + 1),
                "not a finite number",
            ));
        }
        if l.min > l.max {
            let u = joints.unit(i);
            return Err(Error::invalid(
                format!("limits of joint {}", i + 1),
                format!(
                    "min {:.4} {u} is greater than max {:.4} {u}",
                    u.from_internal(l.min),
                    u.from_internal(l.max),
                    u = u.as_str()
                ),
            ));
        }
    }
    Ok(())
}

/// The constant part of a link transform (see `link_constant`).
///
/// Both conventions give the same frame: `Rx(alpha) Tx(a) Ry(beta)` (MDH) and
/// `Tx(a) Rx(alpha) Ry(beta)` (DH) are equal because Rx leaves the x translation unchanged; the
/// conventions differ in whether it stands before or after the joint rotation.
/// `(sin alpha, cos alpha, a)` of a link without a tilt, as [`link_constant`]'s matrix holds
/// them.
fn link_rx(l: &Link) -> Option<[f64; 3]> {
    (l.beta == 0.0).then(|| {
        let c = link_constant(l);
        let m = c.rotation.matrix();
        [m[(2, 1)], m[(1, 1)], l.a]
    })
}

fn link_constant(l: &Link) -> Frame {
    frame::frame(
        frame::rot_x(l.alpha) * frame::rot_y(l.beta),
        Vector3::new(l.a, 0.0, 0.0),
    )
}

/// Rotation matrix helper used by kinematics: `m * Rz(c, s)` computed by columns.
#[inline]
pub(crate) fn mul_rot_z(m: &Matrix3<f64>, s: f64, c: f64) -> Matrix3<f64> {
    let c0 = m.column(0);
    let c1 = m.column(1);
    Matrix3::from_columns(&[c0 * c + c1 * s, c1 * c - c0 * s, m.column(2).into()])
}
