//! Forward kinematics under a measurement row's conditions (DESIGN.md, "Measurement CSV
//! additions (real cells)"): the arm's temperature and each joint's approach direction. The
//! families that read them ([`crate::model::family::backlash`], [`crate::model::family::thermal`])
//! see them through [`RigidPose::conditions`]; without those families, or with unknown
//! conditions, the passes here equal the plain ones.

use crate::frame::Frame;
use crate::model::family::{backlash, link, thermal, PoseFrames, RigidPose};
use crate::model::{Robot, MAX_JOINTS};
use nalgebra::Vector3;
use std::borrow::Cow;

pub use crate::model::Conditions;

impl Robot {
    /// The model as it stands at `c`'s temperature: itself, or with its lengths grown by the
    /// thermal family.
    fn at_temperature(&self, c: &Conditions) -> Cow<'_, Robot> {
        match thermal::link_scales(self, c.temperature_c) {
            Some(s) => Cow::Owned(thermal::scaled_links(self, &s)),
            None => Cow::Borrowed(self),
        }
    }

    /// [`Robot::pose_frames_target`] under conditions `c`: the lengths grown to its temperature
    /// (family `thermal`), the joints deflected knowing its approach directions (family
    /// `backlash`). `rigid.conditions` holds `c`.
    pub fn pose_frames_in(&self, q: &[f64], t: usize, c: &Conditions) -> PoseFrames {
        let mut ch = PoseFrames::identity();
        self.pose_frames_in_into(q, t, c, &mut ch);
        ch
    }

    /// Target `t`'s point (mm, ACS) under conditions `c` (see [`Robot::pose_frames_in`]).
    pub fn target_position_in(&self, q: &[f64], t: usize, c: &Conditions) -> Vector3<f64> {
        if c.is_unknown() {
            return self.target_position(q, t);
        }
        self.pose_frames_in(q, t, c).point
    }

    /// The model with conditions `c` folded in, for tools that take one fixed state of the cell
    /// (compensation at the cell's temperature, every joint approached from one side): the
    /// lengths grown to `c`'s temperature and the thermal family removed; each modelled
    /// backlash turned into the joint offset `phi_j - backlash_j * dir_j` of `c`'s direction and
    /// the backlash family removed. Unknown parts of `c` leave the model at its reference
    /// temperature, or at the middle of the play.
    pub fn at_conditions(&self, c: &Conditions) -> crate::error::Result<Robot> {
        let mut r = self.at_temperature(c).into_owned();
        r.set_family_values(thermal::KEY, None)?;
        for j in backlash::joints(self) {
            let b = self.get(crate::model::Param::new(backlash::ID, 0, j as u16));
            let phi = crate::model::Param::phi(j);
            r.set(phi, r.get(phi) - b * f64::from(c.dir[j]));
        }
        r.set_family_values(backlash::KEY, None)?;
        Ok(r)
    }

    /// [`Robot::target_screws`] under conditions `c`.
    pub fn target_screws_in(
        &self,
        q: &[f64],
        t: usize,
        c: &Conditions,
        jq: Option<&mut [Vector3<f64>]>,
        jp: Option<&mut [Vector3<f64>]>,
        jw: Option<&mut [Vector3<f64>]>,
    ) -> (Vector3<f64>, Frame) {
        let mut jp = jp;
        let out = super::with_scratch_frames(|pose| {
            self.pose_frames_in_into(q, t, c, pose);
            self.screws_at(pose, jq, jp.as_deref_mut(), jw)
        });
        if let Some(jp) = jp {
            self.scale_grown_columns(c, jp);
        }
        out
    }

    /// [`Robot::pose_frames_in`] written into `out` (see [`Robot::rigid_pose_frames_into`]).
    #[inline]
    pub(crate) fn pose_frames_in_into(
        &self,
        q: &[f64],
        t: usize,
        c: &Conditions,
        out: &mut PoseFrames,
    ) {
        if c.is_unknown() {
            return self.pose_frames_target_into(q, t, out);
        }
        let r = self.at_temperature(c);
        let r = r.as_ref();
        let mut rigid = r.rigid_for_families(q);
        rigid.conditions = *c;
        if r.deflects_joints() {
            let mut buf = [0.0; MAX_JOINTS];
            r.rigid_pose_frames_into(r.deflect_with(&rigid, q, &mut buf), t, out);
        } else {
            r.rigid_pose_frames_into(q, t, out);
        }
        out.rigid = rigid;
    }

    /// Scales the columns of the lengths thermal growth scales (each link's `d` and `a`) by the
    /// growth factor at `c`'s temperature: the columns of the families are
    /// taken at the grown lengths, while the parameters are the lengths at the reference (each
    /// link's by its own factor when the family has one coefficient per link).
    pub(crate) fn scale_grown_columns(&self, c: &Conditions, jp: &mut [Vector3<f64>]) {
        let Some(s) = thermal::link_scales(self, c.temperature_c) else {
            return;
        };
        let n = self.dof();
        for (id, span) in self.family_spans() {
            if *id == link::ID {
                // The link family's d (n columns) then a (n columns), after alpha.
                for (i, si) in s.iter().enumerate() {
                    jp[span.start + n + i] *= *si;
                    jp[span.start + 2 * n + i] *= *si;
                }
            }
        }
    }
}

/// Sets `rigid`'s conditions (for families that build passes themselves).
pub fn with_conditions(mut rigid: RigidPose, c: &Conditions) -> RigidPose {
    rigid.conditions = *c;
    rigid
}
