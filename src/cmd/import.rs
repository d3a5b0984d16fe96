//! `robocal import`: a tracker export and a joint log into a measurement CSV (the library's
//! [`robocal_core::io::import`] does the work; this wires flags to it and prints its report).

use super::common;
use super::io_plan::IoPlan;
use clap::Args;
use robocal_core::io::import::{
    import_files, write_import, AngleUnit, DwellSettings, ImportConfig, ImportLimits, JointsFormat,
    LengthUnit, MatchBy, PointsFormat,
};
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct ImportArgs {
    /// The tracker export.
    #[arg(long)]
    points: PathBuf,
    /// Its format: auto, csv, leica, sa, xyz or text.
    #[arg(long, default_value = "auto")]
    points_format: PointsFormat,
    /// The joint log.
    #[arg(long)]
    joints: PathBuf,
    /// Its format: auto, csv or rtde.
    #[arg(long, default_value = "auto")]
    joints_format: JointsFormat,
    /// How points are paired with joint values: name (equal point names), order (rows in
    /// order) or time (the robot at rest at the measurement's time).
    #[arg(long = "match")]
    match_by: MatchBy,
    /// With --match time: the tracker's clock minus the joint log's (s); found from the
    /// pattern of dwells when not given.
    #[arg(long, allow_hyphen_values = true)]
    time_offset: Option<f64>,
    /// The robot, to check the joint log against: its joint count, and each paired point's
    /// joint values against the robot's limits (a value outside them is an error naming the
    /// line and column; so is a log in radians read as degrees).
    #[arg(long)]
    robot: Option<String>,
    /// With --robot: the robot's limits are only nominal: paired joint values outside them are
    /// kept, each listed as a warning.
    #[arg(long, requires = "robot")]
    nominal_limits: bool,
    /// The export's length unit (mm, m, in), for files that do not say it.
    #[arg(long)]
    length_unit: Option<LengthUnit>,
    /// A CSV joint log's angle unit (deg, rad) [default: deg].
    #[arg(long)]
    angle_unit: Option<AngleUnit>,
    /// The joint log's joint columns in joint order (controller values, written as
    /// axis1..axisN), e.g. A1,A2,A3,A4,A5,A6.
    #[arg(long, value_delimiter = ',')]
    joint_columns: Option<Vec<String>>,
    /// The point-name column of both files [default: id, name or point].
    #[arg(long)]
    name_column: Option<String>,
    /// With --match time: the largest motion of any joint during a dwell (deg).
    #[arg(long, default_value_t = DwellSettings::default().still_deg)]
    still_deg: f64,
    /// With --match time: the shortest dwell (s).
    #[arg(long, default_value_t = DwellSettings::default().min_s)]
    dwell_min_s: f64,
    /// With --match time: how far outside a dwell a measurement may be (s).
    #[arg(long, default_value_t = 0.2)]
    time_tolerance: f64,
    /// The measurement CSV to write.
    #[arg(long)]
    out: PathBuf,
}

pub fn run(a: ImportArgs) -> anyhow::Result<()> {
    IoPlan::new()
        .input("--points", &a.points)
        .input("--joints", &a.joints)
        .robot_opt("--robot", a.robot.as_deref())
        .output("--out", &a.out, "the report goes to standard output")
        .check()?;
    let robot_limits = match &a.robot {
        Some(r) => Some(ImportLimits::new(&common::robot(r)?, a.nominal_limits)),
        None => None,
    };
    let config = ImportConfig {
        points_format: a.points_format,
        joints_format: a.joints_format,
        match_by: a.match_by,
        time_offset_s: a.time_offset,
        length_unit: a.length_unit,
        angle_unit: a.angle_unit,
        joint_columns: a.joint_columns,
        name_column: a.name_column,
        robot_limits,
        dwell: DwellSettings {
            still_deg: a.still_deg,
            min_s: a.dwell_min_s,
        },
        time_tolerance_s: a.time_tolerance,
    };
    let imported = import_files(&a.points, &a.joints, &config)?;
    write_import(&a.out, &imported)?;
    for line in imported.report.lines() {
        outln!("{}", super::flags::with_phrases(&line))?;
    }
    outln!(
        "wrote {} ({} rows)",
        a.out.display(),
        imported.report.matched
    )?;
    Ok(())
}
