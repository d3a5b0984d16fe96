//! `robocal compensate --program FILE --out FILE`: a robot program (KUKA KRL, ABB RAPID,
//! URScript) with every target replaced by its compensated value, the rest kept byte for byte
//! ([`robocal_core::programs`]); the changed targets listed, and written as CSV with `--changes`.

use crate::exit;
use robocal_core::io::atomic::{commit_all, AtomicFile};
use robocal_core::programs::census::{MotionOutcome, MotionReport};
use robocal_core::programs::frames::KrlConfig;
use robocal_core::programs::{
    compensate_program, Change, CompensatedProgram, Format, ProgramSettings, Source, TargetKind,
};
use robocal_core::{Compensator, DampedLeastSquares};
use std::io::Write;
use std::path::Path;

/// What a program run needs beside the compensator.
pub(super) struct ProgramRun<'a> {
    pub program: &'a Path,
    pub format: Format,
    pub out: &'a Path,
    pub changes: Option<&'a Path>,
    pub keep_going: bool,
    pub full_pose: bool,
    pub params: &'a Path,
    pub config: Option<&'a Path>,
}

/// The `.dat` beside a KRL `.src` (same stem; `.dat` or `.DAT`), when it exists.
pub(super) fn dat_beside(program: &Path) -> Option<std::path::PathBuf> {
    let ext = program.extension()?.to_str()?;
    if !ext.eq_ignore_ascii_case("src") {
        return None;
    }
    ["dat", "DAT"]
        .iter()
        .map(|e| program.with_extension(e))
        .find(|p| p.is_file())
}

/// The `.dat` written beside an output `.src`.
pub(super) fn dat_path(out: &Path) -> std::path::PathBuf {
    out.with_extension("dat")
}

fn read_text(flag: &str, path: &Path) -> anyhow::Result<String> {
    let bytes = std::fs::read(path)
        .map_err(|e| anyhow::anyhow!(e).context(format!("{flag} {}", path.display())))?;
    String::from_utf8(bytes).map_err(|e| {
        exit::input(format!(
            "{flag} {}: not UTF-8 text (byte {}); save it as UTF-8 (or ASCII)",
            path.display(),
            e.utf8_error().valid_up_to()
        ))
    })
}

/// The header of the `--changes` CSV (README, "Robot programs").
pub(super) const CHANGES_HEADER: &str = "name,line,kind,status,applied,correction_mm,\
    correction_deg,verified_mm,verified_deg,old,new,reason,file";

/// Targets listed one by one before the rest are counted.
const LISTED: usize = 50;

pub(super) fn run(
    r: &ProgramRun<'_>,
    comp: &Compensator<'_, DampedLeastSquares>,
    outputs: &mut super::super::io_plan::Outputs,
) -> anyhow::Result<()> {
    if r.config.is_some() && r.format != Format::Krl {
        return Err(exit::usage(
            "--config (a KUKA $config.dat) applies to a KRL program (.src)".to_owned(),
        ));
    }
    let mut sources = vec![Source {
        path: r.program.to_owned(),
        text: read_text("--program", r.program)?,
    }];
    if let Some(dat) = dat_beside(r.program) {
        let text = read_text("--program", &dat)?;
        sources.push(Source { path: dat, text });
    }
    let config = match r.config {
        Some(p) => Some(KrlConfig::parse(p, &read_text("--config", p)?)?),
        None => None,
    };
    let settings = ProgramSettings {
        full_pose: r.full_pose,
        ..ProgramSettings::default()
    };
    let pb = crate::progress::spinner("compensating the program's targets");
    let res = compensate_program(&sources, r.format, config.as_ref(), comp, &settings);
    pb.finish_and_clear();
    let res = res?;
    // Each line named with its file when there are two (a KRL .src and its .dat).
    let names: Vec<String> = sources
        .iter()
        .map(|s| {
            s.path.file_name().map_or_else(
                || s.path.display().to_string(),
                |n| n.to_string_lossy().into(),
            )
        })
        .collect();
    let at = Lines(&names);
    let failed: Vec<&Change> = res.changes.iter().filter(|c| !c.applied).collect();
    let motions: Vec<&MotionReport> = res.unchanged_motions().collect();
    if (!failed.is_empty() || !motions.is_empty()) && !r.keep_going {
        let mut lines: Vec<String> = failed.iter().map(|c| describe(c, at)).collect();
        lines.extend(motions.iter().map(|m| describe_motion(m, at)));
        return Err(exit::numerical(format!(
            "{} of {} target(s) and {} of {} motion(s) of {} cannot be compensated; nothing \
             written (give --keep-going to leave them unchanged and write the rest):\n  {}",
            failed.len(),
            res.changes.len(),
            motions.len(),
            res.motions.len(),
            r.program.display(),
            lines.join("\n  ")
        )));
    }
    let mut files = vec![write(outputs, r.out, res.texts[0].as_bytes())?];
    if let Some(dat) = res.texts.get(1) {
        files.push(write(outputs, &dat_path(r.out), dat.as_bytes())?);
    }
    if let Some(p) = r.changes {
        files.push(write(outputs, p, changes_csv(&res, at).as_bytes())?);
    }
    commit_all(files)?;
    print_listing(r, &res, &settings, at)?;
    Ok(())
}

/// Where a line is: with one file its number, with a KRL `.src` and its `.dat` the file too.
#[derive(Clone, Copy)]
struct Lines<'a>(&'a [String]);

impl<'a> Lines<'a> {
    /// `line 12`, or `kr480_cell.dat line 12`.
    fn at(self, file: usize, line: usize) -> String {
        match self.0.get(file) {
            Some(f) if self.0.len() > 1 => format!("{f} line {line}"),
            _ => format!("line {line}"),
        }
    }

    /// The file's name for the `file` column.
    fn file(self, file: usize) -> &'a str {
        self.0.get(file).map_or("", String::as_str)
    }
}

/// One line of a motion left unchanged.
fn describe_motion(m: &MotionReport, at: Lines<'_>) -> String {
    let why = match &m.outcome {
        MotionOutcome::Unchanged(w) => w.as_str(),
        MotionOutcome::Compensated => "compensated",
    };
    format!(
        "motion {} ({}): {why}",
        m.motion.statement,
        at.at(m.motion.file, m.motion.line)
    )
}

fn write(
    outputs: &mut super::super::io_plan::Outputs,
    path: &Path,
    bytes: &[u8],
) -> anyhow::Result<AtomicFile> {
    let mut f = outputs.open(path)?;
    f.write_all(bytes)
        .map_err(|e| anyhow::anyhow!(e).context(path.display().to_string()))?;
    Ok(f)
}

/// One line of a target that could not be compensated.
fn describe(c: &Change, at: Lines<'_>) -> String {
    let why = match c.status {
        robocal_core::compensation::IkStatus::Converged => format!(
            "the written value misses the target by {:.4} mm, {:.4} deg after rounding",
            c.verified_mm, c.verified_deg
        ),
        _ if c.skipped.is_some() => c.skipped.clone().unwrap_or_default(),
        s => s.to_string(),
    };
    format!("{} ({}): {why}", c.name, at.at(c.file, c.line))
}

fn kind(k: TargetKind) -> &'static str {
    match k {
        TargetKind::Joints => "joints",
        TargetKind::Pose => "pose",
    }
}

/// A CSV field: quoted when it holds a comma, quote or line break.
fn field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_owned()
    }
}

fn values(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// The `--changes` CSV: one row per target, in file order.
fn changes_csv(res: &CompensatedProgram, at: Lines<'_>) -> String {
    let mut s = String::from(CHANGES_HEADER);
    s.push('\n');
    for c in &res.changes {
        let num = |v: f64| {
            if v.is_finite() {
                format!("{v:.6}")
            } else {
                String::new()
            }
        };
        let (cm, cd) = if c.applied {
            (num(c.correction_mm), num(c.correction_deg))
        } else {
            (String::new(), String::new())
        };
        let status = if let Some(why) = &c.skipped {
            if why.starts_with("frame unknown") {
                "frame_unknown".to_owned()
            } else {
                "skipped".to_owned()
            }
        } else {
            c.status.to_string()
        };
        s += &format!(
            "{},{},{},{status},{},{cm},{cd},{},{},{},{},{},{}\n",
            field(&c.name),
            c.line,
            kind(c.kind),
            c.applied,
            num(c.verified_mm),
            num(c.verified_deg),
            values(&c.old),
            values(&c.new),
            field(c.skipped.as_deref().unwrap_or("")),
            field(at.file(c.file))
        );
    }
    for m in res.unchanged_motions() {
        let why = match &m.outcome {
            MotionOutcome::Unchanged(w) => w.as_str(),
            MotionOutcome::Compensated => "",
        };
        s += &format!(
            "{},{},motion,unchanged,false,,,,,,,{},{}\n",
            field(&m.motion.statement),
            m.motion.line,
            field(why),
            field(at.file(m.motion.file))
        );
    }
    s
}

fn print_listing(
    r: &ProgramRun<'_>,
    res: &CompensatedProgram,
    s: &ProgramSettings,
    at: Lines<'_>,
) -> anyhow::Result<()> {
    let n = res.changes.len();
    let applied = res.changes.iter().filter(|c| c.applied).count();
    let poses = res
        .changes
        .iter()
        .filter(|c| c.kind == TargetKind::Pose)
        .count();
    outln!(
        "{}: {n} target(s) ({} joint, {poses} Cartesian), {}; solved on the calibrated model of {}",
        r.program.display(),
        n - poses,
        if r.full_pose {
            "full pose"
        } else {
            "position only"
        },
        r.params.display()
    )?;
    // With a .src and its .dat: `line` is `FILE:LINE`.
    let two = at.0.len() > 1;
    let line_of = |file: usize, line: usize| {
        if two {
            format!("{}:{line}", at.file(file))
        } else {
            line.to_string()
        }
    };
    let width = res
        .changes
        .iter()
        .take(LISTED)
        .map(|c| line_of(c.file, c.line).len())
        .max()
        .unwrap_or(0)
        .max(6);
    if n > 0 {
        outln!(
            "  {:<16} {:>width$}  {:<6}  {:>11}  {:>11}  status",
            "target",
            if two { "file:line" } else { "line" },
            "kind",
            "corr. mm",
            "corr. deg"
        )?;
    }
    for c in res.changes.iter().take(LISTED) {
        let (cm, cd) = if c.applied {
            (
                format!("{:.4}", c.correction_mm),
                format!("{:.4}", c.correction_deg),
            )
        } else {
            ("-".to_owned(), "-".to_owned())
        };
        outln!(
            "  {:<16} {:>width$}  {:<6}  {cm:>11}  {cd:>11}  {}{}",
            c.name,
            line_of(c.file, c.line),
            kind(c.kind),
            c.status,
            if c.applied { "" } else { " (left unchanged)" }
        )?;
    }
    if n > LISTED {
        outln!("  ... and {} more (see --changes)", n - LISTED)?;
    }
    let max = |f: fn(&Change) -> f64| {
        res.changes
            .iter()
            .filter(|c| c.applied)
            .map(f)
            .fold(0.0, f64::max)
    };
    outln!(
        "  motions: {} in the program, {} compensated, {} left unchanged",
        res.motions.len(),
        res.motions.len() - res.unchanged_motions().count(),
        res.unchanged_motions().count()
    )?;
    outln!(
        "  {applied} compensated, {} left unchanged; largest correction {:.4} mm, {:.4} deg; \
         checked by forward kinematics on the calibrated model after rounding: within {:.4} mm, \
         {:.4} deg (limit {} mm, {} deg)",
        n - applied,
        max(|c| c.correction_mm),
        max(|c| c.correction_deg),
        max(|c| c.verified_mm),
        max(|c| c.verified_deg),
        s.verify_mm,
        s.verify_deg
    )?;
    for c in res.changes.iter().filter(|c| !c.applied) {
        errln!(
            "warning: {}: {}; left unchanged (--keep-going)",
            r.program.display(),
            describe(c, at)
        )?;
    }
    for m in res.unchanged_motions() {
        outln!("  unchanged: {}", describe_motion(m, at))?;
        errln!(
            "warning: {}: {}; left unchanged (--keep-going)",
            r.program.display(),
            describe_motion(m, at)
        )?;
    }
    let shown = super::super::io_plan::shown;
    let dat = (res.texts.len() > 1).then(|| dat_path(r.out));
    let mut wrote = vec![shown(r.out)];
    wrote.extend(dat.as_deref().map(shown));
    wrote.extend(r.changes.map(shown));
    outln!("wrote {}", wrote.join(" and "))?;
    Ok(())
}
