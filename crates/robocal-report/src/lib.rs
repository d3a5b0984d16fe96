//! robocal-report: a calibration run as one self-contained HTML page and a standalone SVG
//! histogram.
//!
//! The page shows what Samak et al. (2019) report for their experiment and what a calibration
//! engineer checks besides: the error statistics before calibration, after calibration and after
//! compensation (the paper's Tables II, IV and V, with the paper's figures beside ours when
//! given), the histogram of the displacement error before and after calibration (the paper's
//! Fig. 2, also written as `histogram.svg`), the error of each point against its reach, the
//! calibrated parameters with their standard deviations, the fixed parameters with the reason,
//! identifiability and solver summaries, and the run's settings.
//!
//! The caller fills a [`ReportData`] (plain, serde-friendly structs; nothing here computes a
//! calibration) and calls [`write_report`]:
//!
//! ```no_run
//! use robocal_report::{write_report, HistogramSeries, ReportData};
//! let data = ReportData {
//!     title: "My robot".into(),
//!     histogram: vec![
//!         HistogramSeries::new("Before calibration", vec![1.2, 1.6, 2.0]),
//!         HistogramSeries::new("After calibration", vec![0.1, 0.2, 0.15]),
//!     ],
//!     ..ReportData::default()
//! };
//! let files = write_report(std::path::Path::new("robocal-report"), &data)?;
//! println!("report: {}", files.html.display());
//! # Ok::<(), robocal_core::Error>(())
//! ```
//!
//! The HTML has no scripts, web fonts or network references; it uses the system font stack and
//! prints on A4. All caller-supplied text is escaped.
#![warn(missing_docs)]

pub mod bins;
mod build;
mod components;
pub mod data;
mod demo;
pub mod escape;
mod example;
pub mod histogram;
mod histogram_section;
mod html;
mod identification;
pub mod iso9283;
mod iso_results;
mod joints;
mod map;
mod markup;
mod numfmt;
mod orientation;
mod page;
mod plot;
mod points_table;
mod prediction;
mod result_details;
pub mod run;
pub mod scatter;
mod sections;
mod serde_nan;
mod summary;
mod svgplot;
mod tables;
mod values;

pub use build::{before_after_histogram, paper, paper_tables};
pub use data::{
    CorrelatedPair, ErrorRow, ErrorTable, FixedParam, HistogramSeries, Identifiability, Note,
    NoteLevel, PaperStats, ParamRow, PointDetail, PointError, PointSet, ReachKind, ReportData,
    Setting, SolverSummary,
};
pub use histogram::{histogram_svg, HistogramFigure};
pub use iso_results::{IsoPoseRow, IsoTest};
pub use numfmt::number_list;
pub use run::RunData;
pub use scatter::{scatter_svg, ScatterFigure};

use robocal_core::{Error, Result};
use std::path::{Path, PathBuf};

/// File name of the HTML report inside the output directory.
pub const HTML_FILE: &str = "report.html";
/// File name of the standalone histogram inside the output directory.
pub const HISTOGRAM_FILE: &str = "histogram.svg";
/// Title of the histogram figure.
pub const HISTOGRAM_TITLE: &str = "Displacement error before and after calibration";

/// How a report names a file: its name alone, never the directories of the machine that made
/// the report (a report is handed on; `/home/me/cell/data.csv` shows as `data.csv`).
pub fn file_name(path: impl AsRef<Path>) -> String {
    let p = path.as_ref();
    p.file_name().map_or_else(
        || p.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

/// The rendered report, in memory.
#[derive(Debug, Clone)]
pub struct Rendered {
    /// The HTML page.
    pub html: String,
    /// The histogram as a standalone SVG document (also inlined in the page).
    pub histogram_svg: String,
}

/// Where [`write_report`] put the files.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReportFiles {
    /// `DIR/report.html`.
    pub html: PathBuf,
    /// `DIR/histogram.svg`.
    pub histogram_svg: PathBuf,
}

/// Renders the report without writing anything.
pub fn render(data: &ReportData) -> Result<Rendered> {
    let hist = histogram_svg(&data.histogram, HISTOGRAM_TITLE)?;
    let html = html::render(&page::Page {
        data,
        histogram: &hist,
    })?;
    Ok(Rendered {
        html,
        histogram_svg: format!("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n{}", hist.svg),
    })
}

/// Writes `report.html` and `histogram.svg` into `dir`, creating it if needed. Both files are
/// replaced together or not at all (temporary files renamed once both are complete).
pub fn write_report(dir: &Path, data: &ReportData) -> Result<ReportFiles> {
    let r = render(data)?;
    if dir.exists() && !dir.is_dir() {
        return Err(Error::Io {
            path: dir.to_owned(),
            source: std::io::Error::other("exists and is not a directory"),
        });
    }
    std::fs::create_dir_all(dir).map_err(|e| Error::Io {
        path: dir.to_owned(),
        source: e,
    })?;
    let files = ReportFiles {
        html: dir.join(HTML_FILE),
        histogram_svg: dir.join(HISTOGRAM_FILE),
    };
    robocal_core::io::write_all_atomic(&[
        (files.html.as_path(), r.html.as_bytes()),
        (files.histogram_svg.as_path(), r.histogram_svg.as_bytes()),
    ])?;
    Ok(files)
}

#[cfg(test)]
mod tests;
