//! `robocal import`: tracker exports and joint logs, as trackers and controllers write them,
//! into a measurement CSV (DESIGN.md, "`robocal import`").
//!
//! Points: [`leica`], [`sa`], [`xyz`], [`text`], [`csv_points`] (auto-detected by [`detect`]),
//! read into a [`PointTable`] in mm. Joint logs: [`joints_csv`], [`rtde`], read row by row
//! ([`joints`]). Pairing: by name or order ([`match_rows`]), or by time: the log's dwells
//! ([`dwells`]) and the clock offset ([`time_match`]). [`import_files`] does it all and returns
//! the CSV text with an [`ImportReport`] of what was read, matched and left out; nothing is
//! written until the caller writes it ([`write_import`], atomic).

pub mod csv_points;
pub mod detect;
pub mod dwells;
pub mod headed;
pub mod joints;
pub mod joints_csv;
pub mod leica;
mod limits;
pub mod lines;
pub mod match_rows;
pub mod points;
mod report;
pub mod rtde;
pub mod sa;
pub mod text;
pub mod time_match;
pub mod timestamp;
pub mod units;
mod write;
pub mod xyz;

pub use dwells::{Dwell, DwellSettings};
pub use limits::ImportLimits;
pub use points::{PointRow, PointTable};
pub use report::ImportReport;
pub use units::{AngleUnit, LengthUnit};

use crate::error::{Error, Result};
use joints::JointLayout;
use lines::LineReader;
use match_rows::KeptRow;
use std::fmt;
use std::io::{BufRead, BufReader};
use std::path::Path;

/// A tracker export's format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PointsFormat {
    /// Detected from the first line ([`detect::points_format`]).
    Auto,
    /// A CSV with a header ([`csv_points`]).
    Csv,
    /// Leica tracker software CSV ([`leica`]).
    Leica,
    /// SpatialAnalyzer ASCII ([`sa`]).
    Sa,
    /// Semicolon `NAME;X;Y;Z` ([`xyz`]).
    Xyz,
    /// Headerless `x y z` ([`text`]).
    Text,
}

/// A joint log's format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointsFormat {
    /// Detected from the header ([`detect::joints_format`]).
    Auto,
    /// A CSV with a header ([`joints_csv`]).
    Csv,
    /// UR's RTDE recorder ([`rtde`]).
    Rtde,
}

/// How points are paired with joint values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MatchBy {
    /// Equal point names.
    Name,
    /// Rows in order (the counts must agree).
    Order,
    /// The robot at rest at the measurement's time.
    Time,
}

macro_rules! names {
    ($t:ty, $($v:ident => $s:literal),*) => {
        impl fmt::Display for $t {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(match self { $(Self::$v => $s),* })
            }
        }
        impl std::str::FromStr for $t {
            type Err = String;
            fn from_str(s: &str) -> std::result::Result<Self, String> {
                match s {
                    $($s => Ok(Self::$v),)*
                    _ => Err(format!("unknown value `{s}` (one of: {})", [$($s),*].join(", "))),
                }
            }
        }
    };
}
names!(PointsFormat, Auto => "auto", Csv => "csv", Leica => "leica", Sa => "sa", Xyz => "xyz", Text => "text");
names!(JointsFormat, Auto => "auto", Csv => "csv", Rtde => "rtde");
names!(MatchBy, Name => "name", Order => "order", Time => "time");

/// What to read and how to pair it.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportConfig {
    /// The tracker export's format.
    pub points_format: PointsFormat,
    /// The joint log's format.
    pub joints_format: JointsFormat,
    /// How points and joints are paired.
    pub match_by: MatchBy,
    /// Tracker clock minus joint-log clock (s), when known (matching by time).
    pub time_offset_s: Option<f64>,
    /// The export's length unit, when the file does not say it (or to confirm it).
    pub length_unit: Option<LengthUnit>,
    /// The joint log's angle unit (CSV logs; degrees by default).
    pub angle_unit: Option<AngleUnit>,
    /// The joint log's joint columns, in joint order (controller values).
    pub joint_columns: Option<Vec<String>>,
    /// The point-name column (points and joints).
    pub name_column: Option<String>,
    /// The robot's joint limits, to check the log's joint count and the paired joint values
    /// against (see [`ImportLimits`]).
    pub robot_limits: Option<ImportLimits>,
    /// How dwells are found (matching by time).
    pub dwell: DwellSettings,
    /// How far outside a dwell a measurement time may be (s).
    pub time_tolerance_s: f64,
}

impl ImportConfig {
    /// Defaults (auto-detected formats, the default dwell settings, 0.2 s tolerance) and the
    /// pairing.
    pub fn new(match_by: MatchBy) -> Self {
        ImportConfig {
            points_format: PointsFormat::Auto,
            joints_format: JointsFormat::Auto,
            match_by,
            time_offset_s: None,
            length_unit: None,
            angle_unit: None,
            joint_columns: None,
            name_column: None,
            robot_limits: None,
            dwell: DwellSettings::default(),
            time_tolerance_s: 0.2,
        }
    }

    /// Checks the settings together.
    pub fn check(&self) -> Result<()> {
        self.dwell.check()?;
        if !(self.time_tolerance_s.is_finite() && self.time_tolerance_s >= 0.0) {
            return Err(Error::invalid(
                "time_tolerance_s",
                format!("{} must be a number >= 0", self.time_tolerance_s),
            ));
        }
        if let Some(o) = self.time_offset_s {
            if !o.is_finite() {
                return Err(Error::invalid(
                    "time_offset_s",
                    format!("{o} is not a number"),
                ));
            }
            if self.match_by != MatchBy::Time {
                return Err(Error::invalid(
                    "time_offset_s",
                    "a clock offset is only used when matching by time",
                ));
            }
        }
        if let Some(c) = &self.joint_columns {
            if c.is_empty() || c.iter().any(|n| n.trim().is_empty()) {
                return Err(Error::invalid("joint_columns", "empty column name"));
            }
        }
        Ok(())
    }
}

/// The result of an import: the measurement CSV's text and what was done.
#[derive(Debug, Clone)]
pub struct Imported {
    /// The measurement CSV.
    pub csv: Vec<u8>,
    /// What was read, matched and left out.
    pub report: ImportReport,
}

/// The first non-empty line of a text.
fn first_line(bytes: &[u8]) -> String {
    let s = String::from_utf8_lossy(&bytes[..bytes.len().min(1 << 16)]);
    let s = s.strip_prefix('\u{feff}').unwrap_or(&s);
    s.lines()
        .find(|l| !l.trim().is_empty())
        .unwrap_or("")
        .to_owned()
}

/// Reads a tracker export from `reader` (`path` names it in errors); the format is detected
/// from its first line when `config.points_format` is `Auto`.
pub fn parse_points<R: BufRead>(
    mut reader: R,
    path: &Path,
    config: &ImportConfig,
) -> Result<PointTable> {
    let format = match config.points_format {
        PointsFormat::Auto => {
            let buf = reader.fill_buf().map_err(|e| Error::Io {
                path: path.to_owned(),
                source: e,
            })?;
            detect::points_format(&first_line(buf))
        }
        f => f,
    };
    let mut lines = LineReader::new(reader, path);
    match format {
        PointsFormat::Leica => leica::read(&mut lines, config),
        PointsFormat::Sa => sa::read(&mut lines, config),
        PointsFormat::Xyz => xyz::read(&mut lines, config),
        PointsFormat::Text => text::read(&mut lines, config),
        PointsFormat::Csv | PointsFormat::Auto => csv_points::read(&mut lines, config),
    }
}

/// What was read from a joint log.
pub struct JointsRead {
    /// How it was read.
    pub layout: JointLayout,
    /// Data rows.
    pub rows: usize,
    /// The rows (matching by name or order).
    pub kept: Vec<KeptRow>,
    /// The dwells (matching by time).
    pub dwells: Vec<Dwell>,
}

/// Reads a joint log from `reader`: keeps its rows, or (matching by time) finds its dwells.
pub fn parse_joints<R: BufRead>(
    mut reader: R,
    path: &Path,
    config: &ImportConfig,
) -> Result<JointsRead> {
    let buf = reader.fill_buf().map_err(|e| Error::Io {
        path: path.to_owned(),
        source: e,
    })?;
    let first = first_line(buf);
    let format = match config.joints_format {
        JointsFormat::Auto => detect::joints_format(&first),
        f => f,
    };
    let mut lines = LineReader::new(reader, path);
    let mut layout = if format != JointsFormat::Rtde && joints_csv::is_headerless(&first) {
        joints_csv::headerless(path, &first, config)?
    } else {
        let (hline, header) = joints::header_line(&mut lines)?;
        match format {
            JointsFormat::Rtde => rtde::layout(path, hline, &header, config)?,
            _ => joints_csv::layout(path, hline, &header, config)?,
        }
    };
    let hline = layout.dialect.header_line.unwrap_or(1);
    if let Some(dof) = config.robot_limits.as_ref().map(ImportLimits::dof) {
        if layout.joint_fields.len() != dof {
            return Err(joints::dof_mismatch(
                path,
                hline,
                layout.joint_fields.len(),
                dof,
            ));
        }
    }
    let mut kept = Vec::new();
    let mut dwells = None;
    let read = if config.match_by == MatchBy::Time {
        if layout.time.is_none() {
            return Err(Error::parse(
                path,
                layout.dialect.header_line,
                None,
                format!(
                    "pairing by time needs a time column ({}) in the joint log{}",
                    joints_csv::TIME_COLUMNS.join(", "),
                    if layout.dialect.header_line.is_none() {
                        " (it has no header)"
                    } else {
                        ""
                    }
                ),
            ));
        }
        let mut finder = dwells::DwellFinder::new(config.dwell);
        let r = joints::for_each_row(&mut lines, &layout, |row| {
            finder.push(row.line, row.time_s.unwrap_or(0.0), row.q_deg);
            Ok(())
        })?;
        dwells = Some(finder.finish());
        r
    } else {
        joints::for_each_row(&mut lines, &layout, |row| {
            kept.push(KeptRow {
                line: row.line,
                name: row.name.map(str::to_owned),
                q_deg: row.q_deg.to_vec(),
            });
            Ok(())
        })?
    };
    if !read.decimal_comma {
        layout.dialect.decimal = '.';
    }
    Ok(JointsRead {
        layout,
        rows: read.rows,
        kept,
        dwells: dwells.unwrap_or_default(),
    })
}

fn open(path: &Path) -> Result<BufReader<std::fs::File>> {
    Ok(BufReader::with_capacity(
        1 << 16,
        crate::io::input::open_input(path)?,
    ))
}

/// Reads both files and pairs them (see the module documentation).
pub fn import_files(points: &Path, joints: &Path, config: &ImportConfig) -> Result<Imported> {
    config.check()?;
    let table = parse_points(open(points)?, points, config)?;
    let log = parse_joints(open(joints)?, joints, config)?;
    import_tables(table, log, config)
}

/// Pairs a read export with a read joint log and makes the CSV.
pub fn import_tables(
    table: PointTable,
    log: JointsRead,
    config: &ImportConfig,
) -> Result<Imported> {
    let joints_path = log.layout.path.clone();
    let ((pairs, left), offset) = pair_rows(&table, &log, config)?;
    let q_of = |j: usize| -> &[f64] {
        if config.match_by == MatchBy::Time {
            &log.dwells[j].q_deg
        } else {
            &log.kept[j].q_deg
        }
    };
    let matched: Vec<(usize, &[f64])> = pairs
        .iter()
        .enumerate()
        .filter_map(|(i, j)| j.map(|j| (i, q_of(j))))
        .collect();
    if matched.is_empty() {
        return Err(Error::parse(
            &table.path,
            None,
            None,
            format!(
                "no point was paired with the joint log {} (pairing by {})",
                joints_path.display(),
                config.match_by
            ),
        ));
    }
    let warnings = match &config.robot_limits {
        Some(lim) => limits::check(lim, &log.layout, &paired_rows(&pairs, &log, config))?,
        None => Vec::new(),
    };
    let (csv, columns, left_out) = write::csv(
        &table,
        &matched,
        log.layout.kind,
        log.layout.joint_fields.len(),
    )
    .map_err(|e| Error::Io {
        path: table.path.clone(),
        source: e,
    })?;
    let report = report::build(report::Parts {
        table: &table,
        log: &log,
        config,
        pairs: &pairs,
        left: &left,
        offset,
        columns,
        left_out,
        joints_path: &joints_path,
        warnings,
    });
    Ok(Imported { csv, report })
}

/// Each point's joint row (or dwell, pairing by time) with the rows or dwells left over, and,
/// pairing by time, the clock offset found and whether it was searched for.
fn pair_rows(
    table: &PointTable,
    log: &JointsRead,
    config: &ImportConfig,
) -> Result<(match_rows::Pairing, Option<(f64, bool)>)> {
    let joints_path = &log.layout.path;
    Ok(match config.match_by {
        MatchBy::Order => (
            match_rows::by_order(&table.path, joints_path, table.rows.len(), log.kept.len())?,
            None,
        ),
        MatchBy::Name => (
            match_rows::by_name(&table.path, joints_path, &table.rows, &log.kept)?,
            None,
        ),
        MatchBy::Time => {
            let m = pair_by_time(table, log, config)?;
            (
                (m.dwell_of, m.unmatched_dwells),
                Some((m.offset_s, m.found)),
            )
        }
    })
}

/// The points paired with the joint log's dwells by their time stamps.
fn pair_by_time(
    table: &PointTable,
    log: &JointsRead,
    config: &ImportConfig,
) -> Result<time_match::TimeMatch> {
    let joints_path = &log.layout.path;
    if log.dwells.is_empty() {
        return Err(Error::parse(
            joints_path,
            None,
            None,
            format!(
                "no dwells in the joint log's {} rows (no run of {} s or more with every \
                 joint within {} deg); check the `dwell.min_s` setting and the \
                 `dwell.still_deg` setting",
                log.rows, config.dwell.min_s, config.dwell.still_deg
            ),
        ));
    }
    let mut times = Vec::with_capacity(table.rows.len());
    for r in &table.rows {
        let t = r.time_s.ok_or_else(|| {
            Error::parse(
                &table.path,
                Some(r.line),
                None,
                "pairing by time: this point has no time stamp",
            )
        })?;
        times.push((r.line, t));
    }
    time_match::match_times(
        &table.path,
        &times,
        &log.dwells,
        config.time_offset_s,
        config.time_tolerance_s,
    )
}

/// The paired joint rows (or dwells), named as the limits' warnings name them.
fn paired_rows<'a>(
    pairs: &[Option<usize>],
    log: &'a JointsRead,
    config: &ImportConfig,
) -> Vec<limits::PairedRow<'a>> {
    pairs
        .iter()
        .filter_map(|j| *j)
        .map(|j| {
            if config.match_by == MatchBy::Time {
                let d = &log.dwells[j];
                limits::PairedRow {
                    line: d.first_line,
                    label: format!("dwell of lines {}-{}", d.first_line, d.last_line),
                    q: &d.q_deg,
                }
            } else {
                let r = &log.kept[j];
                limits::PairedRow {
                    line: r.line,
                    label: format!("line {}", r.line),
                    q: &r.q_deg,
                }
            }
        })
        .collect()
}

/// Writes an import's CSV atomically (nothing is written if it fails).
pub fn write_import(out: &Path, imported: &Imported) -> Result<()> {
    crate::io::atomic::write_atomic(out, &imported.csv)
}
