//! The report's view of one ISO 9283 test (the data its section draws, read from an
//! evaluation or a report JSON).

use robocal_core::iso9283::Evaluation;
use serde::{Deserialize, Serialize};

/// One pose's figures in the report.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct IsoPoseRow {
    /// The pose (1..5).
    pub pose: usize,
    /// Attained poses.
    pub n: usize,
    /// Commanded position (mm, base frame).
    pub commanded_mm: [f64; 3],
    /// AP (mm).
    pub ap_mm: f64,
    /// AP components (mm).
    pub ap_xyz_mm: [f64; 3],
    /// RP (mm).
    pub rp_mm: f64,
    /// The tracker's MPE at the pose (mm).
    pub tracker_mpe_mm: f64,
    /// RP below the tracker's MPE.
    pub rp_below_tracker: bool,
    /// Pass/fail against the spec (`None` without a spec).
    pub pass: Option<bool>,
}

/// One ISO 9283 test in the report.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct IsoTest {
    /// What the test is, e.g. "After calibration (compensated joints)".
    pub label: String,
    /// The cube's centre (mm, base frame).
    pub cube_centre_mm: [f64; 3],
    /// The cube's edge (mm).
    pub cube_edge_mm: f64,
    /// The poses P1..P5.
    pub poses: Vec<IsoPoseRow>,
    /// Distance accuracy and repeatability between `distance_poses` (mm).
    pub ad_mm: f64,
    /// See [`IsoTest::ad_mm`].
    pub rd_mm: f64,
    /// The two poses of the distance.
    pub distance_poses: [usize; 2],
    /// The tracker's MPE model, e.g. "0.015 mm + 0.006 mm/m".
    pub tracker: String,
    /// The spec's AP limit (mm).
    pub spec_ap_mm: Option<f64>,
    /// The spec's RP limit (mm).
    pub spec_rp_mm: Option<f64>,
    /// Whether every pose passes (`None` without a spec).
    pub pass: Option<bool>,
}

impl IsoTest {
    /// The report's view of an evaluation; the cube is recovered from the commanded P1 (its
    /// centre) and P2 (at 80 % of the half diagonal from it).
    pub fn from_evaluation(label: impl Into<String>, ev: &Evaluation) -> IsoTest {
        let centre = ev.poses.first().map_or([0.0; 3], |p| p.commanded_mm);
        let edge = ev.poses.iter().find(|p| p.pose == 2).map_or(0.0, |p| {
            let d: f64 = (0..3)
                .map(|k| (p.commanded_mm[k] - centre[k]).powi(2))
                .sum::<f64>()
                .sqrt();
            2.0 * d / (0.8 * 3f64.sqrt())
        });
        IsoTest {
            label: label.into(),
            cube_centre_mm: centre,
            cube_edge_mm: edge,
            poses: ev
                .poses
                .iter()
                .map(|p| IsoPoseRow {
                    pose: p.pose,
                    n: p.n,
                    commanded_mm: p.commanded_mm,
                    ap_mm: p.ap_mm,
                    ap_xyz_mm: [p.ap_x_mm, p.ap_y_mm, p.ap_z_mm],
                    rp_mm: p.rp_mm,
                    tracker_mpe_mm: p.tracker_mpe_mm,
                    rp_below_tracker: p.rp_below_tracker,
                    pass: p.pass,
                })
                .collect(),
            ad_mm: ev.distance.ad_mm,
            rd_mm: ev.distance.rd_mm,
            distance_poses: [ev.distance.from, ev.distance.to],
            tracker: format!("{} mm + {} mm/m", ev.tracker.mpe_mm, ev.tracker.per_m_mm),
            spec_ap_mm: ev.spec.and_then(|s| s.ap_mm),
            spec_rp_mm: ev.spec.and_then(|s| s.rp_mm),
            pass: ev.pass,
        }
    }
}
