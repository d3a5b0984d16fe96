//! Made-up report data shaped like the paper's experiment, for previews and tests of the report's
//! layout. The numbers are synthetic: nothing here is a calibration result.

use crate::build::{before_after_histogram, paper_tables};
use crate::data::*;
use robocal_core::io::result::BeforeAfter;
use robocal_core::{ErrorStats, Unit};

/// A small deterministic generator (SplitMix64) so that the example needs no RNG crate.
struct Mix(u64);

impl Mix {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Approximately normal (sum of uniforms).
    fn normal(&mut self) -> f64 {
        (0..12).map(|_| self.next()).sum::<f64>() - 6.0
    }
}

fn set(name: &str, n: usize, after_mean: f64, rng: &mut Mix) -> PointSet {
    let mut points = Vec::with_capacity(n);
    let mut details = Vec::with_capacity(n);
    for _ in 0..n {
        // Joint values of a six-joint arm, and a tool point that follows them roughly (a
        // shoulder at 1045 mm, a 3 m arm); errors that grow with the reach and with joint 3.
        let q: Vec<f64> = [170.0, 60.0, 100.0, 300.0, 110.0, 300.0]
            .iter()
            .map(|r| r * (2.0 * rng.next() - 1.0))
            .collect();
        let (q1, q2, q3) = (q[0].to_radians(), q[1].to_radians(), q[2].to_radians());
        let reach = 1200.0 + 1050.0 * (1.0 + (q2 - 0.3 * q3).sin());
        let z = 1045.0 + 1400.0 * (q2 + 0.4 * q3).cos() - 900.0;
        let position = [reach * q1.cos(), reach * q1.sin(), z];
        let before = (0.55 + 0.00045 * reach + 0.22 * rng.normal()).abs();
        let after = (after_mean * (1.0 + 0.45 * rng.normal() + 0.3 * q3.sin())).abs();
        let mut dir = |norm: f64| {
            let v = [rng.normal(), rng.normal(), 0.6 * rng.normal() - 0.4];
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt().max(1e-9);
            [norm * v[0] / l, norm * v[1] / l, norm * v[2] / l]
        };
        details.push(PointDetail {
            joints: q,
            position_mm: position,
            before_mm: dir(before),
            after_mm: dir(after),
        });
        points.push(PointError {
            reach_mm: reach,
            before_mm: before,
            after_mm: after,
        });
    }
    PointSet {
        name: name.into(),
        points,
        details,
    }
}

fn stats(s: &PointSet, after: bool) -> ErrorStats {
    let v: Vec<f64> = s
        .points
        .iter()
        .map(|p| if after { p.after_mm } else { p.before_mm })
        .filter(|x| x.is_finite())
        .collect();
    ErrorStats::from_norms(&v)
}

impl ReportData {
    /// Synthetic data shaped like the paper's experiment (75 calibration, 73 validation and 75
    /// verification points; a six-joint MDH model with 36 parameters, 10 of them fixed), with
    /// the paper's figures beside the tables. For previewing the report's layout and for tests:
    /// the numbers are made up.
    pub fn synthetic_example(seed: u64) -> ReportData {
        ReportData::synthetic_sized(seed, 75, 73)
    }

    /// [`ReportData::synthetic_example`] with `calibration` calibration and verification points
    /// and `validation` validation points: a large run for tests of the page's size and speed.
    pub fn synthetic_sized(seed: u64, calibration: usize, validation: usize) -> ReportData {
        let mut rng = Mix(seed);
        let cal = set("Calibration", calibration, 0.17, &mut rng);
        let val = set("Validation", validation, 0.24, &mut rng);
        let ver = verification_set(&cal, calibration, &mut rng);
        let error_tables = synthetic_tables(&cal, &val, &ver);
        let point_sets = vec![cal, val, ver];
        let histogram = before_after_histogram(&point_sets, &["Calibration"], &["Calibration"]);
        let parameters = synthetic_parameters(&mut rng);
        let fixed = fixed_params(&parameters);
        ReportData {
            metadata: vec![
                Setting::new("Robot serial", "KR480-EXAMPLE-0001"),
                Setting::new("Tracker", "laser tracker (example)"),
                Setting::new("Operator", "A. Example"),
            ],
            joint_units: vec![Unit::Deg; 6],
            point_table: false,
            title: "KUKA KR 480 R3330 – calibration report (synthetic example)".into(),
            subtitle: Some(
                "Made-up data shaped like the paper's experiment: a preview of the report layout."
                    .into(),
            ),
            settings: synthetic_settings(seed),
            error_tables,
            histogram,
            point_sets,
            reach: ReachKind::Radial,
            parameters,
            orientation: Vec::new(),
            iso9283: Vec::new(),
            identifiability: Some(synthetic_identifiability(fixed)),
            solver: Some(synthetic_solver()),
            notes: vec![Note::warning(
                "Synthetic example: these numbers are made up to preview the layout.",
            )],
        }
    }
}

/// The verification set: `n` points drawn like the others, then moved to the calibration
/// points' poses (same reach, joints and positions) with no error before calibration (NaN).
fn verification_set(cal: &PointSet, n: usize, rng: &mut Mix) -> PointSet {
    let mut ver = set("Verification", n, 0.29, rng);
    for (p, c) in ver.points.iter_mut().zip(&cal.points) {
        p.reach_mm = c.reach_mm;
        p.before_mm = f64::NAN;
    }
    for (d, c) in ver.details.iter_mut().zip(&cal.details) {
        d.joints.clone_from(&c.joints);
        d.position_mm = c.position_mm;
        d.before_mm = [f64::NAN; 3];
    }
    ver
}

/// The error tables (Tables II, IV, V with the paper's figures) of the three sets.
fn synthetic_tables(cal: &PointSet, val: &PointSet, ver: &PointSet) -> Vec<ErrorTable> {
    paper_tables(
        BeforeAfter {
            before: stats(cal, false),
            after: stats(cal, true),
        },
        Some(BeforeAfter {
            before: stats(val, false),
            after: stats(val, true),
        }),
        Some(stats(ver, true)),
        true,
    )
}

/// Why the example fixes parameter `name`, or `None` when it is identified.
fn fixed_reason(name: &str) -> Option<&'static str> {
    Some(match name {
        "alpha1" | "a1" | "d1" | "phi1" => "absorbed by the base frame",
        "d3" => "interchangeable with d2 (axes 2 and 3 parallel)",
        "d6" | "phi6" => "absorbed by the tool position",
        "tool_a" | "tool_b" | "tool_c" => "no effect on a measured point",
        _ => return None,
    })
}

/// The parameter table: the paper's robot's nominal values, the identified ones moved by random
/// amounts with random standard deviations, the fixed ones unchanged with their reasons.
fn synthetic_parameters(rng: &mut Mix) -> Vec<ParamRow> {
    // The paper's Table I robot; tool_* are corrections to T0 (nominal zero), as in results.
    let robot = robocal_core::preset("kuka-kr480-r3330").expect("built-in preset");
    let parameters: Vec<(String, Unit, f64)> = robot
        .params()
        .into_iter()
        .map(|p| (p.name(), p.unit(), robot.get_display(p)))
        .collect();
    parameters
        .into_iter()
        .map(|(name, unit, nominal)| {
            let reason = fixed_reason(&name);
            let scale = if unit == Unit::Mm { 0.6 } else { 0.03 };
            let delta = if reason.is_some() {
                0.0
            } else {
                scale * rng.normal()
            };
            ParamRow {
                calibrated: nominal + delta,
                std: reason.is_none().then(|| scale * 0.02 * (0.5 + rng.next())),
                fixed: reason.is_some(),
                reason: reason.map(str::to_owned),
                truth: None,
                name,
                unit,
                nominal,
            }
        })
        .collect()
}

/// The fixed parameters of the table, with their reasons.
fn fixed_params(parameters: &[ParamRow]) -> Vec<FixedParam> {
    parameters
        .iter()
        .filter(|p| p.fixed)
        .map(|p| FixedParam {
            name: p.name.clone(),
            reason: p.reason.clone().unwrap_or_default(),
        })
        .collect()
}

/// The example's settings (robot, `seed`, points, tracker noise, objective).
fn synthetic_settings(seed: u64) -> Vec<Setting> {
    vec![
        Setting::new("Robot", "kuka-kr480-r3330 (Table I, T0 of eq. 7)"),
        Setting::new("Seed", seed),
        Setting::new("Points", "3 plane + 75 calibration + 73 validation"),
        Setting::new("Tracker noise", "0.010 mm + 0.005 mm/m (1σ)"),
        Setting::new("Objective", "sum of displacement error norms (eq. 4)"),
    ]
}

/// Made-up identifiability figures (condition number, counts, correlated pairs) with the
/// `fixed` parameters.
fn synthetic_identifiability(fixed: Vec<FixedParam>) -> Identifiability {
    Identifiability {
        condition_number: Some(412.7),
        identified: Some(26),
        total: Some(36),
        correlated_pairs: vec![
            CorrelatedPair {
                a: "d2".into(),
                b: "base_z".into(),
                correlation: -0.962,
            },
            CorrelatedPair {
                a: "a2".into(),
                b: "base_x".into(),
                correlation: 0.918,
            },
            CorrelatedPair {
                a: "phi2".into(),
                b: "phi3".into(),
                correlation: -0.874,
            },
        ],
        fixed,
    }
}

/// A made-up solver summary (Levenberg–Marquardt with IRLS, 14 iterations).
fn synthetic_solver() -> SolverSummary {
    SolverSummary {
        method: "Levenberg–Marquardt with IRLS".into(),
        objective: "sum of displacement error norms (eq. 4)".into(),
        initial_value: Some(121.4),
        final_value: Some(12.83),
        value_unit: Some("mm".into()),
        termination: "relative reduction of the objective below 1e-12".into(),
        iterations: Some(14),
        evaluations: Some(17),
        extra: vec![],
    }
}
