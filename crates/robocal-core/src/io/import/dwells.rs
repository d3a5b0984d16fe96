//! Dwells in a joint log: runs of rows during which every joint stays within `still_deg` of the
//! run's first row for at least `min_s` seconds (the robot at rest while the tracker measures).
//! Found row by row, so a log of any length is never held in memory.

use crate::error::{Error, Result};

/// How dwells are found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DwellSettings {
    /// Largest motion of any joint during a dwell (deg, or mm for a prismatic joint).
    pub still_deg: f64,
    /// Shortest dwell (s).
    pub min_s: f64,
}

impl Default for DwellSettings {
    /// 0.01 deg and 0.5 s: well above encoder noise, well below a motion's first 10 ms.
    fn default() -> Self {
        DwellSettings {
            still_deg: 0.01,
            min_s: 0.5,
        }
    }
}

impl DwellSettings {
    /// Checks the settings (positive, finite).
    pub fn check(&self) -> Result<()> {
        for (field, v) in [
            ("dwell.still_deg", self.still_deg),
            ("dwell.min_s", self.min_s),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::invalid(
                    field,
                    format!("{v} must be a positive number"),
                ));
            }
        }
        Ok(())
    }
}

/// The robot at rest.
#[derive(Debug, Clone, PartialEq)]
pub struct Dwell {
    /// Time of the first still row (s, the log's clock).
    pub start_s: f64,
    /// Time of the last still row.
    pub end_s: f64,
    /// Line of the first still row.
    pub first_line: usize,
    /// Line of the last still row.
    pub last_line: usize,
    /// Each joint's median over the dwell (deg): the value the robot rests at, unmoved by the
    /// slow last and first samples of the motions before and after (still within `still_deg`)
    /// and by encoder noise; exactly the logged value when most rows hold it.
    pub q_deg: Vec<f64>,
}

impl Dwell {
    /// The middle of the dwell (s).
    pub fn mid_s(&self) -> f64 {
        0.5 * (self.start_s + self.end_s)
    }
}

/// Finds dwells in rows given one at a time, in time order.
#[derive(Debug)]
pub struct DwellFinder {
    settings: DwellSettings,
    anchor: Vec<f64>,
    /// The run's joint values, row after row.
    samples: Vec<f64>,
    scratch: Vec<f64>,
    count: usize,
    start: (f64, usize),
    last: (f64, usize),
    dwells: Vec<Dwell>,
}

impl DwellFinder {
    /// A finder with these settings.
    pub fn new(settings: DwellSettings) -> Self {
        DwellFinder {
            settings,
            anchor: Vec::new(),
            samples: Vec::new(),
            scratch: Vec::new(),
            count: 0,
            start: (0.0, 0),
            last: (0.0, 0),
            dwells: Vec::new(),
        }
    }

    /// The next row: its line, time (s) and joint values (deg).
    pub fn push(&mut self, line: usize, t: f64, q: &[f64]) {
        let still = self.count > 0
            && q.iter()
                .zip(&self.anchor)
                .all(|(a, b)| (a - b).abs() <= self.settings.still_deg);
        if still {
            self.samples.extend_from_slice(q);
            self.count += 1;
        } else {
            self.close();
            self.anchor.clear();
            self.anchor.extend_from_slice(q);
            self.samples.clear();
            self.samples.extend_from_slice(q);
            self.count = 1;
            self.start = (t, line);
        }
        self.last = (t, line);
    }

    fn close(&mut self) {
        if self.count > 1 && self.last.0 - self.start.0 >= self.settings.min_s {
            let dof = self.anchor.len();
            let mut q_deg = Vec::with_capacity(dof);
            for j in 0..dof {
                self.scratch.clear();
                self.scratch
                    .extend(self.samples.iter().skip(j).step_by(dof.max(1)));
                q_deg.push(median(&mut self.scratch));
            }
            self.dwells.push(Dwell {
                start_s: self.start.0,
                end_s: self.last.0,
                first_line: self.start.1,
                last_line: self.last.1,
                q_deg,
            });
        }
        self.count = 0;
    }

    /// The dwells found, in time order.
    pub fn finish(mut self) -> Vec<Dwell> {
        self.close();
        self.dwells
    }
}

/// The median of `v` (the mean of the two middle values for an even count).
fn median(v: &mut [f64]) -> f64 {
    let n = v.len();
    let (_, hi, _) = v.select_nth_unstable_by(n / 2, f64::total_cmp);
    let hi = *hi;
    if n % 2 == 1 {
        return hi;
    }
    let lo = v[..n / 2].iter().copied().fold(f64::NEG_INFINITY, f64::max);
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dwells_are_found_with_their_times_and_exact_values() {
        let mut f = DwellFinder::new(DwellSettings::default());
        // 100 Hz: 1 s still at 10 deg, 0.5 s moving, 0.3 s still (too short), moving, 2 s still.
        let mut t = 0.0;
        let mut line = 1;
        let mut push = |f: &mut DwellFinder, q: f64| {
            line += 1;
            f.push(line, t, &[q, -q]);
            t += 0.01;
        };
        for _ in 0..101 {
            push(&mut f, 10.0);
        }
        for k in 0..50 {
            push(&mut f, 10.0 + k as f64);
        }
        for _ in 0..31 {
            push(&mut f, 60.0);
        }
        for k in 0..50 {
            push(&mut f, 60.0 - k as f64 * 0.5);
        }
        for _ in 0..201 {
            push(&mut f, 0.1 + 0.2);
        }
        let d = f.finish();
        assert_eq!(d.len(), 2, "{d:?}");
        assert_eq!(d[0].q_deg, vec![10.0, -10.0]);
        assert_eq!(d[0].first_line, 2);
        assert!((d[0].end_s - d[0].start_s - 1.0).abs() < 0.011);
        assert_eq!(d[1].q_deg, vec![0.1 + 0.2, -(0.1 + 0.2)]);
        // Slow first and last samples within the tolerance do not move the resting value.
        let mut f = DwellFinder::new(DwellSettings::default());
        for (k, q) in [
            5.0, 5.004, 5.006, 5.007, 5.0071, 5.0071, 5.0071, 5.0071, 5.0071, 5.009,
        ]
        .iter()
        .enumerate()
        {
            f.push(k + 1, k as f64 * 0.1, &[*q]);
        }
        assert_eq!(f.finish()[0].q_deg, vec![5.0071]);
        assert!((d[1].end_s - d[1].start_s - 2.0).abs() < 0.011);
    }
}
