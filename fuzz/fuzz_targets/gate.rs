//! Fuzzes the plausibility gate with the mistakes users make: measured data of a UR5 (40 exact
//! points of a robot with small geometric errors) scaled (units), mirrored, with joints in
//! radians, a joint sign reversed, a J2/J3 coupling left out, noise, gross outliers, a tracker
//! anywhere, and points dropped; then the whole calibration.
//!
//! Asserts: no panic, whatever the data; and a gross mistake (another unit, a mirrored frame,
//! joints in radians) never comes out as a calibration that passed the gate.
#![no_main]
use libfuzzer_sys::arbitrary::{self, Arbitrary};
use libfuzzer_sys::fuzz_target;
use nalgebra::Vector3;
use rand::SeedableRng;
use robocal_core::frame::TrackerFrame;
use robocal_core::identification::{calibrate, CalibrationData, CalibrationSettings, Observations};
use robocal_core::simulation::{random_poses, PoseSampler};
use robocal_core::{pose, Robot};
use std::path::Path;
use std::sync::OnceLock;

const SCALES: [f64; 6] = [1.0, 1.0, 1e-3, 25.4, 10.0, 1.0 / 25.4];

#[derive(Arbitrary, Debug)]
struct Mistakes {
    scale: u8,
    mirror: Option<u8>,
    radians: bool,
    flip_joint: Option<u8>,
    drop_coupling: bool,
    noise_um: u8,
    outliers: Vec<(u8, i8, i8, i8)>,
    tracker: [i16; 6],
    keep: u64,
    objective: u8,
}

struct Cell {
    nominal: Robot,
    qs: Vec<Vec<f64>>,
    points: Vec<Vector3<f64>>,
}

fn cell() -> &'static Cell {
    static CELL: OnceLock<Cell> = OnceLock::new();
    CELL.get_or_init(|| {
        let nominal = robocal_core::parse_robot_toml(
            include_str!("../../examples/ur5.toml"),
            Path::new("ur5.toml"),
        )
        .expect("robot");
        let mut truth = nominal.clone();
        for (i, p) in nominal.params().into_iter().enumerate() {
            let size = if p.unit() == robocal_core::Unit::Mm { 0.3 } else { 3e-4 };
            let sign = if i % 3 == 0 { -1.0 } else { 1.0 };
            truth.set(p, truth.get(p) + sign * size * (1.0 + (i % 5) as f64 * 0.2));
        }
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let qs = random_poses(&nominal, 40, &PoseSampler::default(), &mut rng).expect("poses");
        let points = qs.iter().map(|q| truth.tool_position(q)).collect();
        Cell {
            nominal,
            qs,
            points,
        }
    })
}

fuzz_target!(|m: Mistakes| {
    let c = cell();
    let n = c.nominal.dof();
    let scale = SCALES[m.scale as usize % SCALES.len()];
    let t = &m.tracker;
    let tracker = TrackerFrame::new(pose(&[
        t[0] as f64 / 10.0,
        t[1] as f64 / 10.0,
        t[2] as f64 / 10.0,
        (t[3] as f64 / 100.0).to_radians(),
        (t[4] as f64 / 400.0).to_radians(),
        (t[5] as f64 / 100.0).to_radians(),
    ]));
    let mut obs = Observations::new(n);
    let mut kept = 0;
    for (i, (q, p)) in c.qs.iter().zip(&c.points).enumerate() {
        if m.keep & (1 << i) != 0 && c.qs.len() - i + kept > 30 {
            continue;
        }
        let mut q = q.clone();
        if m.drop_coupling && n > 2 {
            q[2] += q[1];
        }
        if let Some(j) = m.flip_joint {
            let j = j as usize % n;
            q[j] = -q[j];
        }
        if m.radians {
            for v in q.iter_mut() {
                *v = v.to_radians();
            }
        }
        // The reading in the tracker frame, with noise and outliers.
        let mut r = tracker.to_tracker(p);
        let e = m.noise_um as f64 * 1e-3;
        r += Vector3::new(
            e * ((i * 7 % 11) as f64 / 5.0 - 1.0),
            e * ((i * 5 % 13) as f64 / 6.0 - 1.0),
            e * ((i * 3 % 7) as f64 / 3.0 - 1.0),
        );
        for (k, dx, dy, dz) in &m.outliers {
            if *k as usize % c.qs.len() == i {
                r += Vector3::new(*dx as f64, *dy as f64, *dz as f64) * 0.05;
            }
        }
        if let Some(axis) = m.mirror {
            let a = axis as usize % 3;
            r[a] = -r[a];
        }
        r *= scale;
        if obs.push(&q, r, i + 2).is_err() {
            return;
        }
        kept += 1;
    }
    let mut settings = CalibrationSettings::default();
    settings.objective = match m.objective % 3 {
        0 => robocal_core::identification::Objective::SumOfNorms,
        1 => robocal_core::identification::Objective::LeastSquares,
        _ => robocal_core::identification::Objective::Robust(
            robocal_core::identification::RobustLoss::Cauchy,
        ),
    };
    let data = CalibrationData {
        calibration: &obs,
        plane: None,
        validation: None,
    };
    let Ok(cal) = calibrate(&c.nominal, data, &settings, &()) else {
        return;
    };
    // A mirrored frame together with a reversed joint sign can describe a mirrored robot that fits
    // (two mistakes cancelling): only a mirror alone counts as gross here.
    let gross = scale != 1.0 || m.radians || (m.mirror.is_some() && m.flip_joint.is_none());
    assert!(
        !(gross && cal.plausibility.passed()),
        "a gross mistake passed the gate: {m:?}\n{}",
        cal.plausibility.summary()
    );
});
