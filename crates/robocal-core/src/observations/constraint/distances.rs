//! Known distances between named fixed points or sphere centres (`--distances FILE`): a CSV with
//! the columns `from,to,distance_mm` (other columns are ignored), e.g. the spacing of an
//! artefact's nests measured on a CMM, or a ballbar's length. They give constraint data the
//! length scale it otherwise lacks.

use super::{ConstraintData, ConstraintKind};
use crate::error::{Error, Result};
use crate::io::columns::{csv_error, csv_reader, next_record};
use std::io::Read;
use std::path::Path;

/// A known distance between two features (points or sphere centres).
#[derive(Debug, Clone, PartialEq)]
pub struct KnownDistance {
    /// Index of the first feature in [`ConstraintData::features`].
    pub from: usize,
    /// Index of the second.
    pub to: usize,
    /// The distance (mm, positive).
    pub distance_mm: f64,
    /// 1-based line in the distances file (0 when not from a file).
    pub line: usize,
}

/// Reads a distances file for the features of `data` (see the module docs).
pub fn read_distances(path: &Path, data: &ConstraintData) -> Result<Vec<KnownDistance>> {
    let file = crate::io::input::open_input(path)?;
    parse_distances(std::io::BufReader::new(file), path, data)
}

/// Parses distances CSV text; `path` is used in messages. Unknown names, a name of a plane,
/// a distance from a feature to itself, a pair given twice and a distance that is not a
/// positive length are errors naming the line and the column.
pub fn parse_distances<R: Read>(
    reader: R,
    path: &Path,
    data: &ConstraintData,
) -> Result<Vec<KnownDistance>> {
    let perr =
        |line: usize, field: &str, msg: String| Error::parse(path, Some(line), Some(field), msg);
    let mut rdr = csv_reader(reader);
    let headers: Vec<String> = rdr
        .headers()
        .map_err(|e| csv_error(path, e, None::<&crate::io::csv_lines::LineCounted<R>>))?
        .iter()
        .map(|h| h.trim_start_matches('\u{feff}').to_ascii_lowercase())
        .collect();
    let col = |name: &str| -> Result<usize> {
        headers.iter().position(|h| h == name).ok_or_else(|| {
            perr(
                1,
                name,
                format!(
                    "missing column (a distances file has the columns from,to,distance_mm; \
                     header is `{}`)",
                    headers.join(",")
                ),
            )
        })
    };
    let (cf, ct, cd) = (col("from")?, col("to")?, col("distance_mm")?);
    let mut record = csv::StringRecord::new();
    let mut out: Vec<KnownDistance> = Vec::new();
    while let Some(line) = next_record(&mut rdr, &mut record, path)? {
        let feature = |k: usize, field: &str| -> Result<usize> {
            let name = record[k].trim();
            if name.is_empty() {
                return Err(perr(line, field, "empty cell".into()));
            }
            let Some(i) = data.feature_named(name) else {
                let known: Vec<String> = data
                    .features
                    .iter()
                    .filter(|f| f.kind != ConstraintKind::Plane)
                    .map(|f| f.name.clone())
                    .collect();
                return Err(perr(
                    line,
                    field,
                    format!(
                        "`{name}` is not a point or sphere of the measurements (known: {})",
                        if known.is_empty() {
                            "none".to_string()
                        } else {
                            known.join(", ")
                        }
                    ),
                ));
            };
            if data.features[i].kind == ConstraintKind::Plane {
                return Err(perr(
                    line,
                    field,
                    format!("`{name}` is a plane: distances are between points or sphere centres"),
                ));
            }
            Ok(i)
        };
        let from = feature(cf, "from")?;
        let to = feature(ct, "to")?;
        if from == to {
            return Err(perr(
                line,
                "to",
                format!("a distance from `{}` to itself", data.features[from].name),
            ));
        }
        let s = record[cd].trim();
        let d: f64 = s
            .parse()
            .map_err(|_| perr(line, "distance_mm", format!("`{s}` is not a number")))?;
        if !(d > 0.0 && d.is_finite()) {
            return Err(perr(
                line,
                "distance_mm",
                format!("{s} is not a positive length (mm)"),
            ));
        }
        crate::ranges::LENGTH
            .check(d)
            .map_err(|m| perr(line, "distance_mm", m))?;
        let key = (from.min(to), from.max(to));
        if let Some(o) = out
            .iter()
            .find(|o| (o.from.min(o.to), o.from.max(o.to)) == key)
        {
            return Err(perr(
                line,
                "from",
                format!(
                    "the distance between `{}` and `{}` is given twice (also on line {})",
                    data.features[from].name, data.features[to].name, o.line
                ),
            ));
        }
        out.push(KnownDistance {
            from,
            to,
            distance_mm: d,
            line,
        });
    }
    if out.is_empty() {
        return Err(Error::parse(
            path,
            None,
            None,
            "no data rows after the header".to_string(),
        ));
    }
    Ok(out)
}
