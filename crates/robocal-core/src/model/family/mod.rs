//! Parameter families: the open seam through which a model grows new kinds of parameters.
//!
//! A family contributes named, unit-carrying parameters (FIGAROH-style name templates: `d{j}` is
//! `d1 .. dn`, `base_{axis}` is `base_x .. base_c`), reads and writes their values on a [`Robot`],
//! ranks them for the identifiability analysis, and gives, per pose, each parameter's Jacobian
//! column as a *screw at the tool*: the tool point's velocity `dp` (mm per internal unit) and the
//! tool frame's angular velocity `dw` (rad per internal unit) under a unit change of the parameter.
//! Measurement kinds turn those screws into rows (a point uses `dp`, a second reflector
//! `dp + dw x r`, a 6-DoF pose both), so families and kinds are independent.
//!
//! Families whose parameters act through the joints (joint compliance, transmission errors) add a
//! joint deflection `dq(q, theta)` to the joint values in forward kinematics
//! ([`ParameterFamily::add_joint_deflection`]); their columns are the joint screws weighted by
//! `d(dq)/d(theta)` ([`PoseFrames::joint_screw`]).
//!
//! Adding a family is adding one file here that implements [`ParameterFamily`] and one line in
//! the registry ([`all`]); no `match` elsewhere changes. Values of families that are not part of
//! the link table live in the robot's family store ([`Robot::family_values`]).
//!
//! The geometric families of the paper's 36-parameter model (section II.B):
//! [`link`] (alpha, d, a, phi), [`beta`] (Hayati tilts), [`base`] (frame B) and [`tool`] (T);
//! beyond geometry, acting through the joints: [`compliance`] (joint compliance under gravity),
//! [`transmission`] (harmonics of the joints' transmission errors) and [`backlash`] (gear play
//! against the approach direction); and [`thermal`] (lengths growing with the temperature). The
//! last two read the row's conditions ([`RigidPose::conditions`]).

pub mod backlash;
pub mod base;
pub mod beta;
pub mod compliance;
pub mod link;
pub mod plausible;
pub mod reflector;
pub mod thermal;
pub mod tool;
pub mod transmission;

#[cfg(test)]
mod seam_tests;

use crate::frame::Frame;
use crate::model::{JointType, Param, Robot, Unit, MAX_JOINTS};
use nalgebra::Vector3;

/// Names a family: its position in the registry ([`all`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct FamilyId(u8);

impl FamilyId {
    /// The family at registry position `k`.
    pub const fn new(k: usize) -> FamilyId {
        FamilyId(k as u8)
    }

    /// Its registry position.
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// Priority classes for the identifiability analysis (lower is kept first when two parameters
/// have the same effect). The paper's choice: the base frame first, then the tool (which absorbs
/// the last joint's d and phi), then the joints in order; families beyond geometry after the
/// geometry. The tool orientation has no effect on points (it is fixed whatever its class); with
/// 6-DoF data it absorbs phi_n as the tool position absorbs d_n.
pub mod priority {
    /// The base frame vector B.
    pub const BASE: u32 = 0;
    /// The tool position `tool_x..z`.
    pub const TOOL_POSITION: u32 = 100;
    /// Joint `i`'s geometric parameters: `JOINT + JOINT_STRIDE * i + rank within the joint`.
    pub const JOINT: u32 = 1_000;
    /// Spacing between two joints' classes.
    pub const JOINT_STRIDE: u32 = 100;
    /// Parameters that act through the joints (compliance, transmission errors).
    pub const NON_GEOMETRIC: u32 = 100_000;
    /// The tool orientation (invisible to point measurements).
    pub const TOOL_ORIENTATION: u32 = 500;
}

/// One family of model parameters (see the module docs). Implementations are unit structs
/// registered in [`all`].
pub trait ParameterFamily: Sync {
    /// A short key naming the family in files and tables (`link`, `beta`, `base`, `tool`).
    fn key(&self) -> &'static str;

    /// The family's symbol in tables of frame-vector parameters (the paper's `B` and `T`).
    fn symbol(&self) -> &'static str {
        self.key()
    }

    /// The name templates, indexed by [`Param::template`]: `{j}` stands for the 1-based joint,
    /// `{axis}` for a frame-vector component `x, y, z, a, b, c`.
    fn templates(&self) -> &'static [&'static str];

    /// A parameter's display unit.
    fn unit(&self, p: Param) -> Unit;

    /// This robot's parameters of the family, appended to `out` in model order (ascending
    /// [`Param`] order).
    fn params(&self, robot: &Robot, out: &mut Vec<Param>);

    /// A parameter's value in internal units (mm or rad).
    fn get(&self, robot: &Robot, p: Param) -> f64;

    /// Sets a parameter in internal units. The family keeps the robot's caches valid.
    fn set(&self, robot: &mut Robot, p: Param, value: f64);

    /// The parameter's priority class for the identifiability analysis (see [`priority`]).
    fn priority(&self, robot: &Robot, p: Param) -> u32;

    /// The parameter's plausible range on `robot` (see [`plausible`]): the identifiability
    /// analysis, the plausibility gate and the bounds of the fit all read it. The default is the
    /// range of its unit ([`plausible::Plausible::of_unit`]).
    fn plausible(&self, robot: &Robot, p: Param) -> plausible::Plausible {
        plausible::Plausible::of_unit(robot, self.unit(p))
    }

    /// The Jacobian columns of this family's parameters (in [`ParameterFamily::params`] order) at
    /// one pose: `dp[k]`, the tool point's velocity, and, when `dw` is given, the tool frame's
    /// angular velocity per unit change of parameter k. Both in the base frame (ACS).
    fn columns(
        &self,
        robot: &Robot,
        pose: &PoseFrames,
        dp: &mut [Vector3<f64>],
        dw: Option<&mut [Vector3<f64>]>,
    );

    /// Makes `p` a parameter of `robot` when the family's parameters are optional and `p` can
    /// be one (a Hayati tilt of an existing joint); otherwise does nothing. Files that carry
    /// such a parameter (a result, a truth file) enable it this way before setting it.
    fn enable(&self, _robot: &mut Robot, _p: Param) -> crate::error::Result<()> {
        Ok(())
    }

    /// Whether this family moves the joints of this robot (see
    /// [`ParameterFamily::add_joint_deflection`]). Geometric families do not.
    fn deflects_joints(&self, _robot: &Robot) -> bool {
        false
    }

    /// Whether this family's deflection (and its columns) read the rigid pass's joint axes and
    /// tool point ([`RigidPose::axes`], [`RigidPose::point`]), not only the commanded joints:
    /// without such a family the forward kinematics skips that pass.
    fn deflection_reads_axes(&self, _robot: &Robot) -> bool {
        true
    }

    /// Whether this family is beyond this robot's geometry: it moves the joints
    /// ([`ParameterFamily::deflects_joints`]) or depends on the conditions of a measurement (a
    /// temperature). [`Robot::geometric`] drops such families.
    fn beyond_geometry(&self, robot: &Robot) -> bool {
        self.deflects_joints(robot)
    }

    /// Adds the family's joint deflection `dq(q, theta)` at the commanded joint values to `dq`
    /// (internal units). `rigid` holds the forward pass at the commanded joints without any
    /// deflection (`rigid.commanded` are the joint values). Forward kinematics evaluates the
    /// chain at `q + dq`.
    fn add_joint_deflection(&self, _robot: &Robot, _rigid: &RigidPose, _dq: &mut [f64]) {}
}

/// Every family, in model order (the order of [`Robot::params`]).
pub fn all() -> &'static [&'static dyn ParameterFamily] {
    &REGISTRY
}

/// The family named by `id`.
pub fn get(id: FamilyId) -> &'static dyn ParameterFamily {
    REGISTRY[id.index()]
}

/// The family with key `key`, if any.
pub fn by_key(key: &str) -> Option<(FamilyId, &'static dyn ParameterFamily)> {
    REGISTRY
        .iter()
        .enumerate()
        .find(|(_, f)| f.key() == key)
        .map(|(k, f)| (FamilyId::new(k), *f))
}

// The registry: a family's `ID` constant is its position here.
#[cfg(not(test))]
static REGISTRY: [&dyn ParameterFamily; 9] = [
    &link::Link,
    &beta::Beta,
    &base::Base,
    &tool::Tool,
    &reflector::Reflector,
    &compliance::Compliance,
    &transmission::Transmission,
    &backlash::Backlash,
    &thermal::Thermal,
];

// Tests add a family written only against the trait, which proves the seam (`seam_tests`).
#[cfg(test)]
static REGISTRY: [&dyn ParameterFamily; 10] = [
    &link::Link,
    &beta::Beta,
    &base::Base,
    &tool::Tool,
    &reflector::Reflector,
    &compliance::Compliance,
    &transmission::Transmission,
    &backlash::Backlash,
    &thermal::Thermal,
    &seam_tests::JointOffsets,
];

/// Frame-vector component names, the `{axis}` placeholder's values.
pub const AXES: [&str; 6] = ["x", "y", "z", "a", "b", "c"];

/// The unit of frame-vector component `index` (`x, y, z` in mm, `a, b, c` in degrees): the
/// unit of every `{axis}` template.
pub fn axis_unit(index: usize) -> Unit {
    if index < 3 {
        Unit::Mm
    } else {
        Unit::Deg
    }
}

/// A template's name at `index`: `{j}` becomes `index + 1`, `{axis}` the component name.
pub fn instantiate(template: &str, index: usize) -> String {
    if template.contains("{j}") {
        template.replace("{j}", &(index + 1).to_string())
    } else if template.contains("{axis}") {
        template.replace("{axis}", AXES.get(index).copied().unwrap_or("?"))
    } else {
        template.to_owned()
    }
}

/// The index `name` instantiates `template` at, if it does (the inverse of [`instantiate`]):
/// `{j}` matches a decimal number of at least 1 without sign, `{axis}` one of [`AXES`].
pub fn match_template(template: &str, name: &str) -> Option<usize> {
    let (placeholder, parse): (&str, fn(&str) -> Option<usize>) = if template.contains("{j}") {
        ("{j}", |s| {
            if s.is_empty() || !s.bytes().all(|b| b.is_ascii_digit()) {
                return None;
            }
            s.parse::<usize>().ok().filter(|i| *i >= 1).map(|i| i - 1)
        })
    } else if template.contains("{axis}") {
        ("{axis}", |s| AXES.iter().position(|a| *a == s))
    } else {
        return (template == name).then_some(0);
    };
    let (pre, post) = template.split_once(placeholder)?;
    let mid = name.strip_prefix(pre)?.strip_suffix(post)?;
    parse(mid)
}

/// The frames of one forward pass, from which every family's columns are cross products.
///
/// A pass written in place over an earlier one (`Robot::pose_frames_target_into`, the
/// per-thread buffer of the Jacobian passes, which robots of any size share) writes the first
/// [`Robot::dof`] axis and link frames, the flange, the point, the target and `rigid.conditions`;
/// the frames past `dof`, and the rest of `rigid` on a robot whose families do not deflect the
/// joints, keep whatever an earlier pass left. Nothing reads them: every reader stops at `dof`,
/// and only the families that deflect the joints read `rigid`.
pub struct PoseFrames {
    /// `axis[i]`: joint i's axis frame, z along the axis, origin on it (MDH: `F_{i-1} Rx Tx Ry`;
    /// DH: `F_{i-1}`).
    pub axis: [Frame; MAX_JOINTS],
    /// `link[i]`: the frame from which link i's constant part is applied (MDH: `F_{i-1}`;
    /// DH: `F_{i-1} Rz Tz`).
    pub link: [Frame; MAX_JOINTS],
    /// The flange frame `F_n`.
    pub flange: Frame,
    /// The tool point (mm, ACS): the point of target [`PoseFrames::target`].
    pub point: Vector3<f64>,
    /// Which target's point `point` is (0-based; 0 is the tool of the paper, see
    /// [`Robot::target_count`]). Families of one target's tool give zero columns for another's.
    pub target: usize,
    /// The forward pass at the commanded joints without deflection, filled when some family
    /// deflects the joints (the frames above are then at the deflected joints; otherwise only
    /// its `conditions` are written); families that deflect the joints compute `d(dq)/d(theta)`
    /// from it.
    pub rigid: RigidPose,
}

/// The forward pass at the commanded joints without any family's deflection: what a family that
/// deflects the joints computes its deflection from ([`ParameterFamily::add_joint_deflection`]).
#[derive(Clone, Copy)]
pub struct RigidPose {
    /// The commanded joint values (internal units).
    pub commanded: [f64; MAX_JOINTS],
    /// Each joint's axis: its unit direction and the origin of its axis frame (ACS).
    pub axes: [(Vector3<f64>, Vector3<f64>); MAX_JOINTS],
    /// The tool point (mm, ACS).
    pub point: Vector3<f64>,
    /// The measurement row's conditions (temperature, approach directions), when known.
    pub conditions: crate::model::Conditions,
}

impl Default for RigidPose {
    fn default() -> Self {
        RigidPose {
            commanded: [0.0; MAX_JOINTS],
            axes: [(Vector3::zeros(), Vector3::zeros()); MAX_JOINTS],
            point: Vector3::zeros(),
            conditions: crate::model::Conditions::UNKNOWN,
        }
    }
}

impl PoseFrames {
    /// Every frame the identity, the point at the origin: a pass not made yet.
    pub fn identity() -> PoseFrames {
        PoseFrames {
            axis: [Frame::identity(); MAX_JOINTS],
            link: [Frame::identity(); MAX_JOINTS],
            flange: Frame::identity(),
            point: Vector3::zeros(),
            target: 0,
            rigid: RigidPose::default(),
        }
    }

    /// Joint `i`'s screw at the tool: the tool point's velocity and the tool frame's angular
    /// velocity per unit of the joint value (a revolute joint turns about its axis, a prismatic
    /// one translates along it).
    #[inline]
    pub fn joint_screw(&self, robot: &Robot, i: usize) -> (Vector3<f64>, Vector3<f64>) {
        let f = &self.axis[i];
        let z: Vector3<f64> = f.rotation.matrix().column(2).into();
        match robot.joint_type(i) {
            JointType::Revolute => (z.cross(&(self.point - f.translation.vector)), z),
            JointType::Prismatic => (z, Vector3::zeros()),
        }
    }

    /// Rotation about the unit axis `u` through the point `o`, as a screw at the tool.
    #[inline]
    pub fn rotation_screw(&self, u: Vector3<f64>, o: Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
        (u.cross(&(self.point - o)), u)
    }
}

/// Writes `dw[k] = w` when the angular columns are asked for.
#[inline]
pub(crate) fn put(dw: &mut Option<&mut [Vector3<f64>]>, k: usize, w: Vector3<f64>) {
    if let Some(dw) = dw.as_deref_mut() {
        dw[k] = w;
    }
}
