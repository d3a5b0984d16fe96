//! Pairing tracker points with the joint log's dwells by time. The clock offset (tracker clock
//! minus joint-log clock) is given, or found: every (point, dwell) pair of a sample of points
//! votes for the offset that would put the point at the dwell's middle; the most voted offsets
//! are each scored by how many points they put inside a dwell, and the best is refined to the
//! median of its pairs' offsets. A second offset (more than a dwell away) that pairs as many
//! points makes the clock offset ambiguous: an error that names `--time-offset`.
//!
//! The offset found is the one that puts measurements at the middles of their dwells: a tracker
//! that always measures at the same time within a dwell shifts it by a constant, and the pairs
//! are the same.

use super::dwells::Dwell;
use crate::error::{Error, Result};
use std::collections::HashMap;
use std::path::Path;

/// Points sampled for the vote.
const VOTERS: usize = 200;
/// Candidate offsets scored in full.
const CANDIDATES: usize = 12;

/// How points were paired with dwells.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeMatch {
    /// Tracker clock minus joint-log clock (s).
    pub offset_s: f64,
    /// Whether the offset was found (else given).
    pub found: bool,
    /// For each point, the index of its dwell.
    pub dwell_of: Vec<Option<usize>>,
    /// Dwells no point was paired with.
    pub unmatched_dwells: Vec<usize>,
}

/// Where a time falls: the dwells whose span, widened by `tol`, holds it (at most two are
/// reported).
fn dwells_at(starts: &[f64], dwells: &[Dwell], t: f64, tol: f64) -> (Option<usize>, Option<usize>) {
    let i = starts.partition_point(|s| *s - tol <= t);
    let mut hit = (None, None);
    for j in (i.saturating_sub(3)..i).rev() {
        if dwells[j].end_s + tol >= t {
            if hit.0.is_none() {
                hit.0 = Some(j);
            } else {
                hit.1 = Some(j);
            }
        }
    }
    hit
}

/// Number of points an offset puts inside exactly one dwell.
fn score(times: &[f64], starts: &[f64], dwells: &[Dwell], offset: f64, tol: f64) -> usize {
    times
        .iter()
        .filter(|t| matches!(dwells_at(starts, dwells, *t - offset, tol), (Some(_), None)))
        .count()
}

/// The median of the pairs' offsets (point time minus dwell middle) under `offset`.
fn refine(times: &[f64], starts: &[f64], dwells: &[Dwell], offset: f64, tol: f64) -> f64 {
    let mut d: Vec<f64> = times
        .iter()
        .filter_map(|t| match dwells_at(starts, dwells, *t - offset, tol) {
            (Some(j), None) => Some(*t - dwells[j].mid_s()),
            _ => None,
        })
        .collect();
    if d.is_empty() {
        return offset;
    }
    d.sort_by(f64::total_cmp);
    let n = d.len();
    if n % 2 == 1 {
        d[n / 2]
    } else {
        0.5 * (d[n / 2 - 1] + d[n / 2])
    }
}

/// Pairs points (their lines and times, tracker clock) with dwells. `tol` widens each dwell
/// (s); `offset` is the clock offset if known. `path` names the points file in errors.
pub fn match_times(
    path: &Path,
    points: &[(usize, f64)],
    dwells: &[Dwell],
    offset: Option<f64>,
    tol: f64,
) -> Result<TimeMatch> {
    let starts: Vec<f64> = dwells.iter().map(|d| d.start_s).collect();
    let times: Vec<f64> = points.iter().map(|p| p.1).collect();
    let (offset, found) = match offset {
        Some(o) => (o, false),
        None => (find_offset(path, &times, &starts, dwells, tol)?, true),
    };
    let mut dwell_of = Vec::with_capacity(points.len());
    let mut used = vec![false; dwells.len()];
    for (line, t) in points {
        match dwells_at(&starts, dwells, t - offset, tol) {
            (Some(a), Some(b)) => {
                let (a, b) = (a.min(b), a.max(b));
                return Err(Error::parse(
                    path,
                    Some(*line),
                    None,
                    format!(
                        "the point at {:.3} s (joint-log clock) is within {tol} s of two dwells, \
                         {:.3}..{:.3} s (lines {}-{}) and {:.3}..{:.3} s (lines {}-{}); give a \
                         smaller `time_tolerance_s` setting",
                        t - offset,
                        dwells[a].start_s,
                        dwells[a].end_s,
                        dwells[a].first_line,
                        dwells[a].last_line,
                        dwells[b].start_s,
                        dwells[b].end_s,
                        dwells[b].first_line,
                        dwells[b].last_line
                    ),
                ));
            }
            (Some(a), None) => {
                used[a] = true;
                dwell_of.push(Some(a));
            }
            _ => dwell_of.push(None),
        }
    }
    let unmatched_dwells = (0..dwells.len()).filter(|j| !used[*j]).collect();
    Ok(TimeMatch {
        offset_s: offset,
        found,
        dwell_of,
        unmatched_dwells,
    })
}

fn find_offset(
    path: &Path,
    times: &[f64],
    starts: &[f64],
    dwells: &[Dwell],
    tol: f64,
) -> Result<f64> {
    let mut durations: Vec<f64> = dwells.iter().map(|d| d.end_s - d.start_s).collect();
    durations.sort_by(f64::total_cmp);
    let width = durations[durations.len() / 2] + 2.0 * tol;
    let step = times.len().div_ceil(VOTERS).max(1);
    let mut votes: HashMap<i64, Vec<f64>> = HashMap::new();
    // The last point votes too: with evenly spaced dwells, shifting the pairs by whole dwells
    // then loses the first or the last voter, and the true offset has the most votes.
    let last = (times.len() - 1) % step != 0;
    let voters = times
        .iter()
        .step_by(step)
        .chain(times.last().filter(|_| last));
    for t in voters {
        for d in dwells {
            let o = t - d.mid_s();
            votes.entry((o / width).floor() as i64).or_default().push(o);
        }
    }
    // Windows of two neighbouring bins, most votes first.
    let mut windows: Vec<(usize, i64)> = votes
        .keys()
        .map(|k| (votes[k].len() + votes.get(&(k + 1)).map_or(0, Vec::len), *k))
        .collect();
    windows.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
    let mut scored: Vec<(usize, f64)> = Vec::new();
    for &(_, k) in windows.iter().take(CANDIDATES) {
        let mut v: Vec<f64> = votes[&k].clone();
        v.extend(votes.get(&(k + 1)).into_iter().flatten());
        v.sort_by(f64::total_cmp);
        let mut o = v[v.len() / 2];
        for _ in 0..3 {
            o = refine(times, starts, dwells, o, tol);
        }
        scored.push((score(times, starts, dwells, o, tol), o));
    }
    scored.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.total_cmp(&b.1)));
    let (best, o) = scored[0];
    let need = times.len().div_ceil(2).max(2).min(times.len());
    if best < need {
        return Err(Error::parse(
            path,
            None,
            None,
            format!(
                "no clock offset puts more than {best} of the {} points inside the joint log's \
                 {} dwells; give the offset (tracker clock minus joint-log clock) with \
                 the `time_offset_s` setting",
                times.len(),
                dwells.len()
            ),
        ));
    }
    if let Some((_, other)) = scored[1..]
        .iter()
        .find(|(s, other)| *s == best && (other - o).abs() > width)
    {
        return Err(Error::parse(
            path,
            None,
            None,
            format!(
                "the clock offset is ambiguous: {o:.3} s and {other:.3} s both pair {best} of \
                 the {} points with dwells; give it with the `time_offset_s` setting",
                times.len()
            ),
        ));
    }
    Ok(o)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dwell(start: f64, end: f64) -> Dwell {
        Dwell {
            start_s: start,
            end_s: end,
            first_line: 0,
            last_line: 0,
            q_deg: vec![],
        }
    }

    #[test]
    fn offset_found_and_missed_and_extra_listed() {
        // Irregular dwells; points at their middles, 3 h later on the tracker's clock; point 3
        // missed (no measurement), and one dwell (index 7) extra.
        let mut dwells = Vec::new();
        let mut t = 100.0;
        for k in 0..20 {
            let dur = 1.0 + (k * 7 % 5) as f64 * 0.3;
            dwells.push(dwell(t, t + dur));
            t += dur + 2.0 + (k * 3 % 7) as f64 * 0.4;
        }
        let off = 3.0 * 3600.0 + 0.123;
        let points: Vec<(usize, f64)> = dwells
            .iter()
            .enumerate()
            .filter(|(j, _)| *j != 3 && *j != 7)
            .map(|(j, d)| (j + 2, d.mid_s() + off))
            .collect();
        let m = match_times(Path::new("p"), &points, &dwells, None, 0.2).unwrap();
        assert!((m.offset_s - off).abs() < 1e-9, "{}", m.offset_s);
        assert!(m.found);
        assert_eq!(m.unmatched_dwells, vec![3, 7]);
        assert!(m.dwell_of.iter().all(Option::is_some));
    }

    #[test]
    fn evenly_spaced_dwells_all_measured_give_one_offset() {
        let dwells: Vec<Dwell> = (0..3600)
            .map(|k| dwell(k as f64 * 10.0 + 7.0, k as f64 * 10.0 + 10.0))
            .collect();
        let off = 3.0 * 3600.0;
        let points: Vec<(usize, f64)> = dwells
            .iter()
            .enumerate()
            .map(|(k, d)| (k + 2, d.mid_s() + off))
            .collect();
        let m = match_times(Path::new("p"), &points, &dwells, None, 0.2).unwrap();
        assert!((m.offset_s - off).abs() < 1e-6, "{}", m.offset_s);
        assert!(m.unmatched_dwells.is_empty());
    }

    #[test]
    fn periodic_dwells_make_the_offset_ambiguous() {
        let dwells: Vec<Dwell> = (0..10)
            .map(|k| dwell(k as f64 * 3.0, k as f64 * 3.0 + 1.0))
            .collect();
        // Points at the middles of dwells 2..=6: offsets shifting by whole periods pair all.
        let points: Vec<(usize, f64)> = (2..7).map(|k| (k, dwells[k].mid_s() + 50.0)).collect();
        let e = match_times(Path::new("p"), &points, &dwells, None, 0.2)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("ambiguous") && e.contains("the `time_offset_s` setting"),
            "{e}"
        );
    }
}
