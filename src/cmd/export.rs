//! `robocal export`: the calibrated robot of a result as a URDF or a robocal robot file.

use super::common;
use super::io_plan::IoPlan;
use crate::exit;
use clap::{Args, ValueEnum};
use robocal_core::io::export::{self, ExportFormat};
use robocal_core::Robot;
use std::io::Write;
use std::path::PathBuf;

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
enum FormatArg {
    /// A URDF (ROS, MoveIt): one link per DH frame, base and tool as fixed joints.
    Urdf,
    /// A robocal robot file (TOML), for `--robot`.
    Toml,
}

#[derive(Args, Debug)]
pub struct ExportArgs {
    /// The calibration result (`robocal calibrate --out`); its embedded robot is the nominal one.
    result: PathBuf,
    /// The file format.
    #[arg(long, value_enum)]
    format: FormatArg,
    /// The file to write (written whole or not at all; never the result itself).
    #[arg(long, value_name = "FILE")]
    out: PathBuf,
    /// Export the geometry only when the calibration also identified parameters that act
    /// through the joints (joint compliance, transmission errors), which neither format holds;
    /// without it such a result is refused (exit code 2).
    #[arg(long)]
    geometry_only: bool,
}

/// Everything `export` needs, checked before any work.
struct Settings {
    calibrated: Robot,
    format: ExportFormat,
    notes: Vec<String>,
    out: PathBuf,
}

impl TryFrom<&ExportArgs> for Settings {
    type Error = anyhow::Error;

    fn try_from(a: &ExportArgs) -> anyhow::Result<Settings> {
        let mut outputs = IoPlan::new();
        outputs
            .input("RESULT", &a.result)
            .output(
                "--out",
                &a.out,
                "the export is a file that other tools read",
            )
            .check()?;
        let (_, calibrated, res) = common::nominal_and_result(None, &a.result, "RESULT")?;
        if let Some(why) = res.not_calibrated() {
            return Err(exit::input(format!(
                "{} is not a calibration ({}): its parameters are not a robot to export",
                a.result.display(),
                match why {
                    robocal_core::io::result::NotCalibrated::Partial(w) => format!("partial: {w}"),
                    robocal_core::io::result::NotCalibrated::Implausible(w) => {
                        format!("implausible: {w}")
                    }
                }
            )));
        }
        let format = match a.format {
            FormatArg::Urdf => ExportFormat::Urdf,
            FormatArg::Toml => ExportFormat::Toml,
        };
        let dropped: Vec<String> = export::non_geometric(&calibrated)
            .iter()
            .map(|p| {
                format!(
                    "{} = {} {}",
                    p.name(),
                    calibrated.get_display(*p),
                    p.unit().as_str()
                )
            })
            .collect();
        if !dropped.is_empty() && !a.geometry_only {
            return Err(exit::usage(format!(
                "{}: the calibration identified parameters that act through the joints ({}); \
                 neither a URDF nor a robot file holds them: give --geometry-only to export the \
                 geometry without them",
                a.result.display(),
                dropped.join(", ")
            )));
        }
        let tf = &res.tracker_frame;
        let mut notes = vec![
            format!(
                "The calibrated robot `{}` of {}, exported by robocal {}.",
                calibrated.name(),
                a.result.display(),
                env!("CARGO_PKG_VERSION")
            ),
            "Its geometry reproduces the calibrated forward kinematics; tool corrections are \
             folded into the tool vectors."
                .into(),
            format!(
                "The tracker frame belongs to the measurement, not to the robot, and is not part \
                 of this file: tracker_frame = [{}, {}, {}, {}, {}, {}] (mm, deg), the pose of \
                 the tracker's frame in the base frame.",
                tf.x, tf.y, tf.z, tf.a, tf.b, tf.c
            ),
        ];
        if let Some(c) =
            robocal_core::io::result_constraint::ConstraintSection::of(&res, &a.result)?
        {
            notes.pop();
            notes.extend(constraint_notes(&c));
        }
        if format == ExportFormat::Urdf {
            notes.push(
                "Joint values are robocal's model joint values (rad; m for a prismatic joint). \
                 Links: base_link, frame0, link_1..link_n, flange, tcp (the tool point): read \
                 it again with tcp as the tip link."
                    .into(),
            );
            if calibrated.controller().is_some() {
                notes.push(
                    "The robot's controller axis map ([controller] of its robot file) is not \
                     part of a URDF."
                        .into(),
                );
            }
        }
        if !dropped.is_empty() {
            notes.push(format!(
                "Left out (they act through the joints; export of the geometry only): {}",
                dropped.join(", ")
            ));
        }
        Ok(Settings {
            calibrated,
            format,
            notes,
            out: a.out.clone(),
        })
    }
}

/// The notes of a constraint calibration: its frame, its features and what its data cannot see.
fn constraint_notes(c: &robocal_core::io::result_constraint::ConstraintSection) -> Vec<String> {
    let mut notes = vec![format!(
        "Calibrated from constraint data (no tracker): {}.",
        c.frame
    )];
    for f in &c.features {
        let [x, y, z] = f.position_mm;
        notes.push(format!(
            "Feature {} at ({x:.4}, {y:.4}, {z:.4}) mm in the base frame{}{} ({} rows, residual \
             RMS {:.4} mm).",
            f.label(),
            f.radius_mm
                .map_or(String::new(), |r| format!(", radius {r:.4} mm")),
            f.normal.map_or(String::new(), |[a, b, c]| format!(
                ", normal ({a:.6}, {b:.6}, {c:.6})"
            )),
            f.rows,
            f.residual_rms_mm
        ));
    }
    notes.push(match (&c.scale.from, &c.scale.held) {
        (Some(from), _) => format!("Scale from {from}."),
        (None, Some(held)) => format!(
            "Scale NOT determined by the data: {held} held at its nominal value (accepted \
             explicitly)."
        ),
        (None, None) => "Scale: not recorded.".into(),
    });
    for u in &c.unseen {
        notes.push(format!("Not identifiable from these data: {u}."));
    }
    notes
}

pub fn run(a: ExportArgs) -> anyhow::Result<()> {
    let s = Settings::try_from(&a)?;
    let robot = export::geometric_nominal(&s.calibrated)?;
    let text = export::export(&robot, s.format, &s.notes)?;
    if s.notes.iter().any(|n| n.starts_with("Left out")) {
        errln!(
            "warning: exported the geometry only: {}",
            s.notes.last().map_or("", String::as_str)
        )?;
    }
    let mut f = robocal_core::io::AtomicFile::create(&s.out)?;
    f.write_all(text.as_bytes())
        .map_err(|e| anyhow::anyhow!("{}: {e}", s.out.display()))?;
    f.commit()?;
    outln!(
        "wrote {} ({}, {} joints)",
        s.out.display(),
        match s.format {
            ExportFormat::Urdf => "URDF",
            ExportFormat::Toml => "robocal robot file",
        },
        robot.dof()
    )?;
    Ok(())
}
