//! `robocal robot show`.

use super::common;
use clap::{Args, Subcommand};
use std::path::PathBuf;

#[derive(Subcommand, Debug)]
// Each command's arguments are built only when it runs (or for help, completions, man).
#[command(defer = true)]
pub enum RobotCmd {
    /// Print a robot's parameter table (the layout of the paper's Table I), tool and limits.
    Show(ShowArgs),
    /// List the built-in presets.
    List,
}

#[derive(Args, Debug)]
pub struct ShowArgs {
    /// A preset name (see `robocal robot list`), a TOML robot file or a URDF.
    robot: String,
    /// Show the calibrated parameters of a result file instead of the nominal ones.
    #[arg(long)]
    params: Option<PathBuf>,
}

/// Everything `robot show` needs, checked before any work: the model, nominal or calibrated.
struct ShowSettings {
    model: common::Model,
}

impl TryFrom<&ShowArgs> for ShowSettings {
    type Error = anyhow::Error;

    fn try_from(a: &ShowArgs) -> anyhow::Result<ShowSettings> {
        let model = common::model(Some(&a.robot), a.params.as_deref())?;
        if let (Some((_, res)), Some(p)) = (&model.calibrated, &a.params) {
            common::warn_not_calibrated(res, p)?;
        }
        Ok(ShowSettings { model })
    }
}

pub fn run(c: RobotCmd) -> anyhow::Result<()> {
    match c {
        RobotCmd::List => {
            for p in robocal_core::PRESETS {
                outln!("{p}")?;
            }
            Ok(())
        }
        RobotCmd::Show(a) => {
            let ShowSettings { model: m } = ShowSettings::try_from(&a)?;
            let r = m.active();
            let label = match &m.calibrated {
                Some((_, res)) if res.partial_reason().is_some() => {
                    "PARTIAL parameters (the solver did not converge; not a calibration)"
                }
                Some((_, res)) if res.implausible_reason().is_some() => {
                    "IMPLAUSIBLE parameters (the fit failed the plausibility gate; not a \
                     calibration)"
                }
                Some(_) => "calibrated parameters",
                None => "parameters",
            };
            outln!(
                "{} ({} joints, {}), {label}:",
                r.name(),
                r.dof(),
                match r.convention() {
                    robocal_core::Convention::Mdh => "modified DH (Craig)",
                    robocal_core::Convention::Dh => "standard DH",
                }
            )?;
            out!("{}", crate::tables::parameter_table(r, 4))?;
            let t0 = robocal_core::frame::vec_rad_to_deg(r.tool0());
            outln!(
                "T0 (nominal tool, mm/deg): [{}]",
                t0.iter()
                    .map(|v| format!("{v}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            )?;
            outln!("Joint limits (model joint values):")?;
            for (i, l) in r.limits().iter().enumerate() {
                let u = r.joint_unit(i);
                let r6 = |v: f64| (u.from_internal(v) * 1e6).round() / 1e6;
                outln!(
                    "  q{}: {} .. {} {} ({})",
                    i + 1,
                    r6(l.min),
                    r6(l.max),
                    u.as_str(),
                    r.joint_type(i).as_str()
                )?;
            }
            if let Some(c) = r.controller() {
                outln!("Controller axes (axis1..axis{}):", r.dof())?;
                for line in crate::tables::controller_map(c, r) {
                    outln!("  {line}")?;
                }
            }
            Ok(())
        }
    }
}
