//! `robocal fk`: forward kinematics.

use super::common;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct FkArgs {
    /// A preset name, a TOML robot file or a URDF [with --params, default: the robot embedded in the
    /// result; when given, it must agree with that one].
    #[arg(long)]
    robot: Option<String>,
    /// Joint values q1,...,qn: model joint values in degrees (mm for a prismatic joint).
    #[arg(long, allow_hyphen_values = true)]
    joints: String,
    /// Use the calibrated model of a result file (`robocal calibrate --out`).
    #[arg(long)]
    params: Option<PathBuf>,
    /// Print JSON: {"x":..,"y":..,"z":..} in mm.
    #[arg(long)]
    json: bool,
}

/// Everything `fk` needs, checked before any work: the model (nominal or calibrated) and the
/// joint values (count, numbers, ranges).
struct Settings {
    model: common::Model,
    q: Vec<f64>,
    json: bool,
}

impl TryFrom<&FkArgs> for Settings {
    type Error = anyhow::Error;

    fn try_from(a: &FkArgs) -> anyhow::Result<Settings> {
        let model = common::model(a.robot.as_deref(), a.params.as_deref())?;
        if let (Some((_, res)), Some(p)) = (&model.calibrated, &a.params) {
            common::warn_not_calibrated(res, p)?;
        }
        let q = common::joints_arg(&a.joints, model.active())?;
        Ok(Settings {
            model,
            q,
            json: a.json,
        })
    }
}

pub fn run(a: FkArgs) -> anyhow::Result<()> {
    let Settings { model, q, json } = Settings::try_from(&a)?;
    let r = model.active();
    let pose = r.tool_pose(&q);
    let p = pose.translation.vector;
    if json {
        outln!("{}", serde_json::json!({ "x": p.x, "y": p.y, "z": p.z }))?;
    } else {
        let v = robocal_core::frame::vec_rad_to_deg(&robocal_core::frame_vector(&pose));
        outln!(
            "tool position (mm, base frame): x = {:.4}  y = {:.4}  z = {:.4}",
            p.x,
            p.y,
            p.z
        )?;
        outln!(
            "tool orientation (deg, A B C):     A = {:.4}  B = {:.4}  C = {:.4}",
            v[3],
            v[4],
            v[5]
        )?;
        let out = r.joints_outside_limits(&q);
        if !out.is_empty() {
            errln!(
                "warning: joint(s) {} outside the robot's limits",
                out.iter()
                    .map(|i| format!("q{}", i + 1))
                    .collect::<Vec<_>>()
                    .join(", ")
            )?;
        }
    }
    Ok(())
}
