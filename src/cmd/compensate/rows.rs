//! The rows of `--joints` (desired joint vectors) or `--targets` (Cartesian targets), each read,
//! compensated, counted and written in turn: only the summary is kept, so files of any length
//! fit in memory. The commanded joints go into a [`CommandedWriter`] that the caller commits.

use super::super::io_plan::Outputs;
use super::conditions;
use super::summary::{Listing, Tally};
use anyhow::Context;
use robocal_core::compensation::commanded::{check_extra_columns, CommandedWriter};
use robocal_core::compensation::{read_targets, Compensation, Target};
use robocal_core::io::{MeasurementReader, Positions};
use robocal_core::{Compensator, Robot};
use std::path::Path;

/// A file's rows compensated: the commanded joints written (for the caller to commit) and
/// whether they were solved as full poses (else positions).
pub(super) struct Compensated {
    pub(super) full_pose: bool,
    pub(super) writer: CommandedWriter,
}

/// What every row is solved with, where it is written, and what is gathered.
pub(super) struct Rows<'a> {
    /// The nominal model: the desired joints' targets, and the joint units.
    pub(super) nominal: &'a Robot,
    /// The calibrated model, whose joints a target's start joints are.
    pub(super) calibrated: &'a Robot,
    pub(super) comp: &'a Compensator<'a>,
    /// The calibration models backlash: the output gets the approach directions.
    pub(super) from_below: bool,
    pub(super) outputs: &'a mut Outputs,
    /// The output file (`-`: standard output).
    pub(super) out: &'a Path,
    pub(super) tally: &'a mut Tally,
    pub(super) pb: &'a indicatif::ProgressBar,
}

impl Rows<'_> {
    /// The desired joint vectors of `path` (`--joints`), each solved for its nominal tool pose
    /// (`full_pose`) or position from its own joints; a row outside the joint limits is solved
    /// and listed in a warning.
    pub(super) fn compensate_desired_joints(
        &mut self,
        path: &Path,
        full_pose: bool,
    ) -> anyhow::Result<Compensated> {
        let joints = self.nominal.joint_space();
        let dof = self.nominal.dof();
        let context = || format!("--joints {}", path.display());
        let mut reader =
            MeasurementReader::open(path, joints, Positions::Optional).with_context(context)?;
        check_extra_columns(path, joints, reader.extra_columns())?;
        if reader.has_positions() {
            errln!(
                "note: {}: the x,y,z columns (measured positions) are not used or carried",
                path.display()
            )?;
        }
        let (mut w, added) = self.writer(true, full_pose, reader.extra_columns())?;
        let mut outside = Listing::default();
        let mut q = vec![0.0; dof];
        while let Some(r) = reader.next_row().with_context(context)? {
            self.nominal
                .check_joints(&r.q, &format!("{}:{}", path.display(), r.line))?;
            let o = self.nominal.joints_outside_limits(&r.q);
            if !o.is_empty() {
                let js: Vec<String> = o.iter().map(|i| format!("q{}", i + 1)).collect();
                outside.push(format!("line {} ({})", r.line, js.join(" ")));
            }
            let c = self.compensate_desired(&r.q, full_pose, &mut q);
            self.tally.add(self.nominal, r.line, &c, Some(&r.q));
            w.write(
                &c,
                Some(&r.q),
                &conditions::with_directions(&r.extra, added),
            )?;
            self.tally.tick(self.pb);
        }
        for warning in reader.finish().with_context(context)? {
            errln!("warning: {warning}")?;
        }
        if outside.count() > 0 {
            errln!(
                "warning: {}: {} desired pose(s) outside the joint limits; solved from the \
                 nearest pose within them: {}",
                path.display(),
                outside.count(),
                outside.text()
            )?;
        }
        Ok(Compensated {
            full_pose,
            writer: w,
        })
    }

    /// The output started: its header, with or without the desired joints, position-only or
    /// `full_pose`, with the input's `extra` columns and the approach directions they lack when
    /// the calibration models backlash; the count of columns added.
    fn writer(
        &mut self,
        desired_joints: bool,
        full_pose: bool,
        extra: &[String],
    ) -> anyhow::Result<(CommandedWriter, usize)> {
        let (columns, added) =
            conditions::direction_columns(extra, self.nominal.dof(), self.from_below);
        let w = CommandedWriter::to_output(
            self.outputs.open(self.out)?,
            self.nominal.joint_space(),
            desired_joints,
            full_pose,
            &columns,
        )?;
        Ok((w, added))
    }

    /// The compensation of the desired joints `desired`: the commanded joints (in `q`) that
    /// reach their nominal tool pose, or with `full_pose` false its position.
    fn compensate_desired(&self, desired: &[f64], full_pose: bool, q: &mut [f64]) -> Compensation {
        if full_pose {
            let (f, report) = self.comp.compensate_pose(desired, q);
            Compensation {
                desired_position: f.translation.vector,
                desired_orientation: Some(f.rotation),
                commanded: q.to_vec(),
                report,
            }
        } else {
            let (p, report) = self.comp.compensate(desired, q);
            Compensation {
                desired_position: p,
                desired_orientation: None,
                commanded: q.to_vec(),
                report,
            }
        }
    }

    /// The Cartesian targets of `path` (`--targets`), each solved for its pose, or its position
    /// with `position_only` or when the file has no orientations (said in a note).
    pub(super) fn compensate_targets(
        &mut self,
        path: &Path,
        position_only: bool,
    ) -> anyhow::Result<Compensated> {
        let joints = self.nominal.joint_space();
        let mut full_pose = !position_only;
        let set =
            read_targets(path, joints).with_context(|| format!("--targets {}", path.display()))?;
        check_extra_columns(path, joints, &set.extra_columns)?;
        if full_pose && !set.has_orientation {
            errln!(
                "note: {}: no a,b,c columns: the targets are positions, compensated position-only \
                 (orientation free, configuration not checked)",
                path.display()
            )?;
            full_pose = false;
        } else if position_only && set.has_orientation {
            errln!(
                "note: {}: --position-only: the a,b,c columns (orientations) are not used",
                path.display()
            )?;
        }
        let (mut w, added) = self.writer(false, full_pose, &set.extra_columns)?;
        let mut q = vec![0.0; self.nominal.dof()];
        for t in &set.rows {
            if let Some(s) = &t.seed {
                self.calibrated
                    .check_joints(s, &format!("{}:{}", path.display(), t.line))?;
            }
            let c = self.compensate_target(t, full_pose, &mut q);
            self.tally.add(self.nominal, t.line, &c, None);
            w.write(&c, None, &conditions::with_directions(&t.extra, added))?;
            self.tally.tick(self.pb);
        }
        Ok(Compensated {
            full_pose,
            writer: w,
        })
    }

    /// The compensation of the target `t`: the commanded joints (in `q`) that reach its pose
    /// (with `full_pose`, when it has an orientation), else its position.
    fn compensate_target(&self, t: &Target, full_pose: bool, q: &mut [f64]) -> Compensation {
        match t.frame().filter(|_| full_pose) {
            Some(f) => Compensation {
                desired_position: t.p,
                desired_orientation: Some(f.rotation),
                report: self.comp.reach_pose(&f, t.seed.as_deref(), q),
                commanded: q.to_vec(),
            },
            None => Compensation {
                desired_position: t.p,
                desired_orientation: None,
                report: self.comp.reach(&t.p, t.seed.as_deref(), q),
                commanded: q.to_vec(),
            },
        }
    }
}
