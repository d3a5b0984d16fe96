//! The link-table family: `alpha{j}`, `d{j}`, `a{j}`, `phi{j}` of every joint (paper, Table I),
//! in MDH or DH (section II.B).
//!
//! Each parameter moves the tool by a screw of the chain: alpha turns about the x axis of the
//! frame the link's constant part starts from, a translates along that axis, d translates along
//! the joint axis and phi turns about it (for a revolute joint, phi's column is the joint's).

use super::{priority, FamilyId, ParameterFamily, PoseFrames};
use crate::model::{Convention, Param, Robot, Unit};
use nalgebra::Vector3;

/// This family's registry position.
pub const ID: FamilyId = FamilyId::new(0);
/// Template of the twist alpha.
pub const ALPHA: u8 = 0;
/// Template of the offset d.
pub const D: u8 = 1;
/// Template of the length a.
pub const A: u8 = 2;
/// Template of the joint offset phi.
pub const PHI: u8 = 3;

/// The parameter of template `t` at joint `i`.
pub const fn param(t: u8, i: usize) -> Param {
    Param::new(ID, t, i as u16)
}

/// The link-table family.
pub struct Link;

impl ParameterFamily for Link {
    fn key(&self) -> &'static str {
        "link"
    }

    fn templates(&self) -> &'static [&'static str] {
        &["alpha{j}", "d{j}", "a{j}", "phi{j}"]
    }

    fn unit(&self, p: Param) -> Unit {
        match p.template() as u8 {
            D | A => Unit::Mm,
            _ => Unit::Deg,
        }
    }

    fn params(&self, robot: &Robot, out: &mut Vec<Param>) {
        let n = robot.dof();
        for t in [ALPHA, D, A, PHI] {
            out.extend((0..n).map(|i| param(t, i)));
        }
    }

    fn get(&self, robot: &Robot, p: Param) -> f64 {
        let l = &robot.links[p.index()];
        match p.template() as u8 {
            ALPHA => l.alpha,
            D => l.d,
            A => l.a,
            _ => l.phi,
        }
    }

    fn set(&self, robot: &mut Robot, p: Param, value: f64) {
        let i = p.index();
        let l = &mut robot.links[i];
        match p.template() as u8 {
            ALPHA => l.alpha = value,
            D => l.d = value,
            A => l.a = value,
            _ => l.phi = value,
        }
        robot.refresh_link(i);
    }

    fn priority(&self, _robot: &Robot, p: Param) -> u32 {
        // Within a joint: alpha, a, (beta), phi, d.
        let rank = match p.template() as u8 {
            ALPHA => 0,
            A => 1,
            PHI => 3,
            _ => 4,
        };
        priority::JOINT + priority::JOINT_STRIDE * p.index() as u32 + rank
    }

    #[inline]
    fn columns(
        &self,
        robot: &Robot,
        pose: &PoseFrames,
        dp: &mut [Vector3<f64>],
        dw: Option<&mut [Vector3<f64>]>,
    ) {
        let n = robot.dof();
        let p = pose.point;
        let (alpha, rest) = dp.split_at_mut(n);
        let (d, rest) = rest.split_at_mut(n);
        let (a, phi) = rest.split_at_mut(n);
        for i in 0..n {
            let f = &pose.link[i];
            let x: Vector3<f64> = f.rotation.matrix().column(0).into();
            // alpha_i: rotation about the x axis of the link frame the constant part starts
            // from, through its origin (MDH: Rx comes first) or that origin moved by a (DH:
            // Tx(a) Rx).
            let o = match robot.convention() {
                Convention::Mdh => f.translation.vector,
                Convention::Dh => f.translation.vector + x * robot.links[i].a,
            };
            alpha[i] = x.cross(&(p - o));
            // a_i: translation along the x axis of the link frame.
            a[i] = x;
            let g = &pose.axis[i];
            let z: Vector3<f64> = g.rotation.matrix().column(2).into();
            // d_i: translation along the joint axis.
            d[i] = z;
            // phi_i: rotation about the joint axis.
            phi[i] = z.cross(&(p - g.translation.vector));
        }
        if let Some(dw) = dw {
            for i in 0..n {
                dw[i] = pose.link[i].rotation.matrix().column(0).into();
                dw[n + i] = Vector3::zeros();
                dw[2 * n + i] = Vector3::zeros();
                dw[3 * n + i] = pose.axis[i].rotation.matrix().column(2).into();
            }
        }
    }
}
