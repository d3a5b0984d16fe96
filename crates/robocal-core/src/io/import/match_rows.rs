//! Pairing tracker points with joint-log rows by point name or by order.

use super::points::PointRow;
use crate::error::{Error, Result};
use std::collections::HashMap;
use std::path::Path;

/// A joint-log row kept for matching by name or order.
#[derive(Debug, Clone, PartialEq)]
pub struct KeptRow {
    /// 1-based line.
    pub line: usize,
    /// Point name, if the log has a name column.
    pub name: Option<String>,
    /// Joint values (deg).
    pub q_deg: Vec<f64>,
}

/// For each point, the index of its joint row, and the joint rows left over.
pub type Pairing = (Vec<Option<usize>>, Vec<usize>);

/// Pairs the i-th point with the i-th joint row; the counts must agree.
pub fn by_order(points: &Path, joints: &Path, n_points: usize, n_joints: usize) -> Result<Pairing> {
    if n_points != n_joints {
        return Err(Error::parse(
            joints,
            None,
            None,
            format!(
                "pairing by order pairs rows in order, but {} has {n_points} points and this log \
                 {n_joints} rows; the counts must agree (or pair by name or time: the `match_by` setting)",
                points.display()
            ),
        ));
    }
    Ok(((0..n_points).map(Some).collect(), Vec::new()))
}

/// Pairs points with the joint rows of the same name. A name twice in the joint log is an
/// error; points may share a name (several targets at one pose).
pub fn by_name(
    points_path: &Path,
    joints_path: &Path,
    points: &[PointRow],
    joints: &[KeptRow],
) -> Result<Pairing> {
    let mut index: HashMap<&str, usize> = HashMap::with_capacity(joints.len());
    for (j, r) in joints.iter().enumerate() {
        let Some(name) = r.name.as_deref() else {
            return Err(Error::parse(
                joints_path,
                None,
                None,
                "pairing by name needs a point-name column (id, name or point; or the \
                 `name_column` setting)",
            ));
        };
        if let Some(&k) = index.get(name) {
            return Err(Error::parse(
                joints_path,
                Some(r.line),
                None,
                format!(
                    "point name `{name}` again (first on line {})",
                    joints[k].line
                ),
            ));
        }
        index.insert(name, j);
    }
    let mut used = vec![false; joints.len()];
    let mut pairs = Vec::with_capacity(points.len());
    for p in points {
        let Some(name) = p.name.as_deref() else {
            return Err(Error::parse(
                points_path,
                Some(p.line),
                None,
                "pairing by name: this point has no name (pair by order or time: the `match_by` \
                 setting)",
            ));
        };
        let j = index.get(name).copied();
        if let Some(j) = j {
            used[j] = true;
        }
        pairs.push(j);
    }
    let left = (0..joints.len()).filter(|j| !used[*j]).collect();
    Ok((pairs, left))
}
