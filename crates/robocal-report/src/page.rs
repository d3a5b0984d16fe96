//! What every section of the page sees ([`Page`]), and the point sets the per-point views
//! draw. Its own module so that the sections depend on it and the list of sections
//! ([`crate::sections`]) depends on them, with no import running back.

use crate::data::ReportData;
use crate::histogram::HistogramFigure;

/// What every section sees: the report's data and the figures made once for the whole report.
pub struct Page<'a> {
    /// Everything the report shows.
    pub data: &'a ReportData,
    /// The error histogram (also written as a file of its own).
    pub histogram: &'a HistogramFigure,
}

/// The point set whose details the per-axis, per-joint and map views show, and the others with
/// details: calibration first (the points the histogram shows), then the rest.
pub(crate) fn detailed_sets(data: &ReportData) -> Vec<&crate::data::PointSet> {
    data.point_sets
        .iter()
        .filter(|s| !s.details.is_empty() && s.details.len() == s.points.len())
        .collect()
}
