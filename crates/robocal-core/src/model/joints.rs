//! Joint types and the one place where joint values change units.
//!
//! A revolute joint's value is an angle: radians inside, degrees at every interface. A prismatic
//! joint's value is a length: millimetres everywhere, never converted (DESIGN.md, "Robot file
//! additions"). [`JointSpace`] holds each joint's type and the controller's axis map, and is
//! what every reader and writer of joint values goes through.

use super::controller::Controller;
use super::params::Unit;
use crate::error::{Error, Result};

/// How a joint moves.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum JointType {
    /// A rotation about the joint axis: the value (rad) adds to the row's phi.
    #[default]
    Revolute,
    /// A translation along the joint axis: the value (mm) adds to the row's d; phi is then a
    /// constant.
    Prismatic,
}

impl JointType {
    /// `"revolute"` or `"prismatic"`.
    pub fn as_str(self) -> &'static str {
        match self {
            JointType::Revolute => "revolute",
            JointType::Prismatic => "prismatic",
        }
    }

    /// Parses [`JointType::as_str`].
    pub fn parse(s: &str) -> Option<JointType> {
        match s {
            "revolute" => Some(JointType::Revolute),
            "prismatic" => Some(JointType::Prismatic),
            _ => None,
        }
    }

    /// The unit of the joint's value at the interfaces: degrees or mm.
    pub fn unit(self) -> Unit {
        match self {
            JointType::Revolute => Unit::Deg,
            JointType::Prismatic => Unit::Mm,
        }
    }
}

/// A robot's joints as the interfaces see them: each joint's type (and so its unit) and the
/// controller's axis map (see [`Controller`]; `None`: the identity, the robot has no
/// `[controller]`).
///
/// Conversions: "display" values are degrees (revolute) or mm (prismatic), what files and
/// command lines hold; "internal" values are radians or mm, what the kinematics use.
#[derive(Debug, Clone, PartialEq)]
pub struct JointSpace {
    types: Vec<JointType>,
    controller: Option<Controller>,
    /// Whether any joint is prismatic (kept for the kinematics' fast all-revolute path).
    prismatic: bool,
}

impl JointSpace {
    /// `n` revolute joints without a controller map.
    pub fn revolute(n: usize) -> JointSpace {
        JointSpace {
            types: vec![JointType::Revolute; n],
            controller: None,
            prismatic: false,
        }
    }

    /// Joints of the given types with an optional controller map (which must have as many
    /// joints).
    pub fn new(types: Vec<JointType>, controller: Option<Controller>) -> Result<JointSpace> {
        if let Some(c) = &controller {
            if c.dof() != types.len() {
                return Err(Error::invalid(
                    "controller",
                    format!(
                        "the map has {} axes, the robot {} joints",
                        c.dof(),
                        types.len()
                    ),
                ));
            }
        }
        let prismatic = types.contains(&JointType::Prismatic);
        Ok(JointSpace {
            types,
            controller,
            prismatic,
        })
    }

    /// Number of joints.
    pub fn dof(&self) -> usize {
        self.types.len()
    }

    /// Every joint's type.
    pub fn types(&self) -> &[JointType] {
        &self.types
    }

    /// Joint `i`'s type (0-based).
    pub fn joint_type(&self, i: usize) -> JointType {
        self.types[i]
    }

    /// Whether any joint is prismatic.
    #[inline]
    pub fn any_prismatic(&self) -> bool {
        self.prismatic
    }

    /// Joint `i`'s display unit (degrees or mm).
    pub fn unit(&self, i: usize) -> Unit {
        self.types[i].unit()
    }

    /// The controller's axis map, if the robot has one.
    pub fn controller(&self) -> Option<&Controller> {
        self.controller.as_ref()
    }

    /// Joint `i`'s value from display units (deg or mm) to internal units (rad or mm).
    #[inline]
    pub fn to_internal(&self, i: usize, v: f64) -> f64 {
        self.types[i].unit().to_internal(v)
    }

    /// Joint `i`'s value from internal units (rad or mm) to display units (deg or mm).
    #[inline]
    pub fn to_display(&self, i: usize, v: f64) -> f64 {
        self.types[i].unit().from_internal(v)
    }

    /// A joint vector from display units to internal units.
    pub fn joints_from_display(&self, v: &[f64]) -> Vec<f64> {
        v.iter()
            .enumerate()
            .map(|(i, x)| self.to_internal(i, *x))
            .collect()
    }

    /// A joint vector from internal units to display units.
    pub fn joints_to_display(&self, q: &[f64]) -> Vec<f64> {
        q.iter()
            .enumerate()
            .map(|(i, x)| self.to_display(i, *x))
            .collect()
    }

    /// Model joint values (internal units) from controller axis values (display units), through
    /// the controller map (the identity without one).
    ///
    /// Panics if `axis` does not have [`JointSpace::dof`] entries.
    pub fn joints_from_axes(&self, axis: &[f64]) -> Vec<f64> {
        assert_eq!(axis.len(), self.dof(), "axis vector length");
        match &self.controller {
            Some(c) => self.joints_from_display(&c.to_model(axis)),
            None => self.joints_from_display(axis),
        }
    }

    /// Controller axis values (display units) from model joint values (internal units): the
    /// inverse of [`JointSpace::joints_from_axes`].
    ///
    /// Panics if `q` does not have [`JointSpace::dof`] entries.
    pub fn axes_from_joints(&self, q: &[f64]) -> Vec<f64> {
        assert_eq!(q.len(), self.dof(), "joint vector length");
        let d = self.joints_to_display(q);
        match &self.controller {
            Some(c) => c.to_controller(&d),
            None => d,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prismatic_values_are_never_converted() {
        let s = JointSpace::new(vec![JointType::Prismatic, JointType::Revolute], None).unwrap();
        let q = s.joints_from_display(&[1500.0, 90.0]);
        assert_eq!(q[0], 1500.0);
        assert!((q[1] - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        assert_eq!(s.joints_to_display(&q), vec![1500.0, 90.0]);
        assert_eq!(s.axes_from_joints(&q), vec![1500.0, 90.0]);
        assert_eq!(s.unit(0), Unit::Mm);
        assert_eq!(s.unit(1), Unit::Deg);
    }

    #[test]
    fn axes_go_through_the_controller() {
        let c = Controller::new(vec![1.0, -1.0], vec![100.0, 10.0], vec![]).unwrap();
        let s = JointSpace::new(vec![JointType::Prismatic, JointType::Revolute], Some(c)).unwrap();
        let q = s.joints_from_axes(&[5.0, 30.0]);
        assert_eq!(q[0], 105.0);
        assert!((q[1] - (-20f64).to_radians()).abs() < 1e-15);
        let a = s.axes_from_joints(&q);
        assert!(
            (a[0] - 5.0).abs() < 1e-12 && (a[1] - 30.0).abs() < 1e-12,
            "{a:?}"
        );
        let e = JointSpace::new(vec![JointType::Revolute], Some(Controller::identity(2)))
            .unwrap_err()
            .to_string();
        assert!(e.contains("2 axes") && e.contains("1 joints"), "{e}");
    }
}
