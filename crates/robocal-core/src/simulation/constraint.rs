//! Simulated constraint data (issue 31): the true robot brings its tool point to fixed points,
//! onto spheres or onto planes from varied orientations, each configuration found by inverse
//! kinematics on the true robot ([`Compensator::reach_pose`]); the contact carries probe noise
//! and the robot's repeatability (`noise_mm`, Gaussian per axis at the contact). Each feature is
//! placed where a random reference configuration of the true robot puts its tool point, so it
//! is reachable; the orientations spread up to `tilt_deg` about the reference's.

use crate::compensation::{Compensator, DampedLeastSquares};
use crate::error::{Error, Result};
use crate::frame::Frame;
use crate::io::{Measurement, MeasurementSet};
use crate::model::Robot;
use crate::observations::constraint::{ConstraintData, ConstraintKind, KnownDistance};
use crate::registration::rigid::fit_rigid;
use crate::simulation::{random_poses, GeometricErrors, PoseSampler};
use nalgebra::{Rotation3, Translation3, Vector3};
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, StandardNormal};

/// What to simulate.
#[derive(Debug, Clone, PartialEq)]
pub struct ConstraintSimulation {
    /// The kind of feature.
    pub kind: ConstraintKind,
    /// How many features (points, spheres or planes).
    pub features: usize,
    /// Configurations per feature.
    pub per_feature: usize,
    /// 1-sigma noise of the contact per axis (mm): probe and repeatability.
    pub noise_mm: f64,
    /// A sphere's radius (mm).
    pub radius_mm: f64,
    /// Whether the sphere's radius is written to the data (known) or left empty.
    pub radius_known: bool,
    /// Largest tilt of the tool's orientation from the reference configuration's (degrees).
    pub tilt_deg: f64,
    /// A plane's touched region: a square of this half-size (mm) about the reference point; a
    /// sphere's: contacts within this angle (degrees) of the reference direction, as
    /// `span_mm / radius_mm` radians capped at 80 degrees.
    pub span_mm: f64,
    /// Give the distances between every pair of points or sphere centres.
    pub distances: bool,
    /// Seed of every random draw.
    pub seed: u64,
}

impl Default for ConstraintSimulation {
    fn default() -> Self {
        ConstraintSimulation {
            kind: ConstraintKind::Point,
            features: 4,
            per_feature: 20,
            noise_mm: 0.01,
            radius_mm: 25.0,
            radius_known: true,
            tilt_deg: 60.0,
            span_mm: 300.0,
            distances: true,
            seed: 1,
        }
    }
}

impl ConstraintSimulation {
    /// Rejects counts of zero, too few rows per feature, and lengths, noise or angles outside
    /// their ranges.
    pub fn validate(&self) -> Result<()> {
        if self.features == 0 {
            return Err(Error::invalid("features", "must be at least 1"));
        }
        if self.per_feature < self.kind.min_rows() {
            return Err(Error::invalid(
                "per_feature",
                format!(
                    "{} is fewer than a {} needs ({})",
                    self.per_feature,
                    self.kind.key(),
                    self.kind.min_rows()
                ),
            ));
        }
        if !(self.noise_mm >= 0.0 && self.noise_mm <= 10.0) {
            return Err(Error::invalid(
                "noise_mm",
                format!("{} is not within 0..10 mm", self.noise_mm),
            ));
        }
        if !(self.radius_mm > 0.0 && self.radius_mm <= 1000.0) {
            return Err(Error::invalid(
                "radius_mm",
                format!("{} is not within (0, 1000] mm", self.radius_mm),
            ));
        }
        if !(self.tilt_deg >= 0.0 && self.tilt_deg <= 90.0) {
            return Err(Error::invalid(
                "tilt_deg",
                format!("{} is not within 0..90 degrees", self.tilt_deg),
            ));
        }
        if !(self.span_mm > 0.0 && self.span_mm <= 5000.0) {
            return Err(Error::invalid(
                "span_mm",
                format!("{} is not within (0, 5000] mm", self.span_mm),
            ));
        }
        Ok(())
    }
}

/// Simulated constraint data with the truth behind it.
#[derive(Debug, Clone)]
pub struct SimulatedConstraints {
    /// The rows (and known distances, when asked).
    pub data: ConstraintData,
    /// Each feature's true position (point, sphere centre, or plane's reference point), in the
    /// true robot's base frame (mm).
    pub true_positions: Vec<Vector3<f64>>,
    /// Each plane's true unit normal (None for points and spheres).
    pub true_normals: Vec<Option<Vector3<f64>>>,
}

/// Reference configurations tried per feature before giving up.
pub(crate) const REFERENCE_TRIES: usize = 50;

/// Simulates `spec` on the true robot `truth`, reference configurations drawn by `sampler`.
pub fn simulate_constraints(
    truth: &Robot,
    sampler: &PoseSampler,
    spec: &ConstraintSimulation,
) -> Result<SimulatedConstraints> {
    spec.validate()?;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(spec.seed);
    let mut ik = Compensator::new(truth, truth, DampedLeastSquares::default())?;
    // Contacts to rounding: noise-free data must be exact.
    ik.pose_solver.tolerance_mm = 1e-10;
    ik.pose_solver.tolerance_deg = 1e-9;
    let mut data = ConstraintData::new(truth.dof());
    let mut true_positions = Vec::new();
    let mut true_normals = Vec::new();
    for k in 0..spec.features {
        let mut done = None;
        for _ in 0..REFERENCE_TRIES {
            let q0 = random_poses(truth, 1, sampler, &mut rng)?.remove(0);
            if let Some(found) = feature_rows(truth, &ik, &q0, spec, &mut rng) {
                done = Some(found);
                break;
            }
        }
        let Some((rows, position, normal)) = done else {
            return Err(Error::Numerical(format!(
                "simulation: no reference configuration in {REFERENCE_TRIES} draws from which the \
                 robot reaches a {} in {} orientations (lower the tilt or the span)",
                spec.kind.key(),
                spec.per_feature
            )));
        };
        let name = format!(
            "{}{}",
            spec.kind
                .key()
                .to_ascii_uppercase()
                .chars()
                .next()
                .unwrap_or('F'),
            k + 1
        );
        let radius =
            (spec.kind == ConstraintKind::Sphere && spec.radius_known).then_some(spec.radius_mm);
        let f = data
            .feature_index(spec.kind, &name, radius, 0)
            .map_err(|(_, m)| Error::invalid("simulation", m))?;
        for q in rows {
            data.push(q, f, 0)?;
        }
        true_positions.push(position);
        true_normals.push(normal);
    }
    if spec.distances && spec.kind != ConstraintKind::Plane {
        for a in 0..spec.features {
            for b in a + 1..spec.features {
                data.distances.push(KnownDistance {
                    from: a,
                    to: b,
                    distance_mm: (true_positions[a] - true_positions[b]).norm(),
                    line: 0,
                });
            }
        }
    }
    Ok(SimulatedConstraints {
        data,
        true_positions,
        true_normals,
    })
}

/// A random rotation of at most `max_deg` about a uniformly random axis.
fn random_tilt<R: Rng>(rng: &mut R, max_deg: f64) -> Rotation3<f64> {
    let axis = random_unit(rng);
    let angle = max_deg.to_radians() * rng.gen::<f64>();
    Rotation3::from_scaled_axis(axis * angle)
}

fn random_unit<R: Rng>(rng: &mut R) -> Vector3<f64> {
    loop {
        let v = Vector3::from_fn(|_, _| StandardNormal.sample(rng));
        let n: f64 = v.norm();
        if n > 1e-9 {
            return v / n;
        }
    }
}

/// The rows of one feature from reference configuration `q0`: `None` when the robot cannot
/// reach every contact from there.
#[allow(clippy::type_complexity)]
fn feature_rows<R: Rng>(
    truth: &Robot,
    ik: &Compensator<'_>,
    q0: &[f64],
    spec: &ConstraintSimulation,
    rng: &mut R,
) -> Option<(Vec<Vec<f64>>, Vector3<f64>, Option<Vector3<f64>>)> {
    let t0 = truth.tool_pose(q0);
    let r0 = t0.rotation;
    let p0 = t0.translation.vector;
    let z0 = r0.matrix().column(2).into_owned();
    let (position, normal) = match spec.kind {
        ConstraintKind::Point => (p0, None),
        ConstraintKind::Sphere => (p0 - spec.radius_mm * z0, None),
        ConstraintKind::Plane => (p0, Some(z0)),
    };
    let rows = contacts(truth, ik, q0, spec, rng)?;
    Some((rows, position, normal))
}

/// The configurations of one feature touched from reference configuration `q0` (whose tool
/// pose is the reference contact, its z axis the feature's normal): `spec.per_feature` of
/// them, or `None` when the robot misses too many contacts.
pub(crate) fn contacts<R: Rng>(
    truth: &Robot,
    ik: &Compensator<'_>,
    q0: &[f64],
    spec: &ConstraintSimulation,
    rng: &mut R,
) -> Option<Vec<Vec<f64>>> {
    let t0 = truth.tool_pose(q0);
    let r0 = t0.rotation;
    let p0 = t0.translation.vector;
    let z0 = r0.matrix().column(2).into_owned();
    let position = match spec.kind {
        ConstraintKind::Sphere => p0 - spec.radius_mm * z0,
        _ => p0,
    };
    let (t1, t2) = crate::identification::constraint::features::tangents(&z0);
    let cone = (spec.span_mm / spec.radius_mm).min(80f64.to_radians());
    let mut rows = Vec::with_capacity(spec.per_feature);
    let mut q = vec![0.0; truth.dof()];
    let mut misses = 0;
    while rows.len() < spec.per_feature {
        let contact = match spec.kind {
            ConstraintKind::Point => p0,
            ConstraintKind::Sphere => {
                let phi = rng.gen::<f64>() * std::f64::consts::TAU;
                // Uniform over the spherical cap of half-angle `cone`.
                let cos_t = 1.0 - rng.gen::<f64>() * (1.0 - cone.cos());
                let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
                let u = cos_t * z0 + sin_t * (phi.cos() * t1 + phi.sin() * t2);
                position + spec.radius_mm * u
            }
            ConstraintKind::Plane => {
                let a = (2.0 * rng.gen::<f64>() - 1.0) * spec.span_mm;
                let b = (2.0 * rng.gen::<f64>() - 1.0) * spec.span_mm;
                p0 + a * t1 + b * t2
            }
        };
        let noise = Vector3::from_fn(|_, _| {
            let z: f64 = StandardNormal.sample(rng);
            spec.noise_mm * z
        });
        let rot = random_tilt(rng, spec.tilt_deg) * r0;
        let target = Frame::from_parts(Translation3::from(contact + noise), rot);
        let rep = ik.reach_pose(&target, Some(q0), &mut q);
        let at = truth.tool_position(&q);
        if rep.status.reaches_target()
            && truth.joints_outside_limits(&q).is_empty()
            && (at - (contact + noise)).norm() < 1e-6
        {
            rows.push(q.clone());
        } else {
            misses += 1;
            if misses > 4 * spec.per_feature {
                return None;
            }
        }
    }
    Some(rows)
}

/// The rows of `planned` (configurations in which `nominal` touches the features) as the true
/// robot `truth` measures them: each configuration moved by inverse kinematics on the truth,
/// from the planned one, until the truth's tool frame is where the nominal's was (the operator
/// jogs the probe into the socket or onto the surface), the contact with Gaussian noise
/// `noise_mm` per axis (seed `seed`). Distances are kept. A contact the truth cannot reach from
/// there within its joint limits (a planned configuration at a limit or a singularity) is left
/// out, as an operator would skip it: its index (0-based, in `planned.rows`) is returned beside
/// the data; a feature left with fewer rows than it needs is an error naming it.
pub fn touch(
    truth: &Robot,
    nominal: &Robot,
    planned: &ConstraintData,
    noise_mm: f64,
    seed: u64,
) -> Result<(ConstraintData, Vec<usize>)> {
    if !(0.0..=10.0).contains(&noise_mm) {
        return Err(Error::invalid(
            "noise_mm",
            format!("{noise_mm} is not within 0..10 mm"),
        ));
    }
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut ik = Compensator::new(truth, truth, DampedLeastSquares::default())?;
    ik.pose_solver.tolerance_mm = 1e-10;
    ik.pose_solver.tolerance_deg = 1e-9;
    let mut out = planned.clone();
    let mut q = vec![0.0; truth.dof()];
    let mut missed = Vec::new();
    for (i, r) in out.rows.iter_mut().enumerate() {
        let t = nominal.tool_pose(&r.q);
        let noise = Vector3::from_fn(|_, _| {
            let z: f64 = StandardNormal.sample(&mut rng);
            noise_mm * z
        });
        let target =
            Frame::from_parts(Translation3::from(t.translation.vector + noise), t.rotation);
        let rep = ik.reach_pose(&target, Some(&r.q), &mut q);
        if !rep.status.reaches_target() || !truth.joints_outside_limits(&q).is_empty() {
            missed.push(i);
            continue;
        }
        r.q.clone_from(&q);
    }
    let mut i = 0;
    out.rows.retain(|_| {
        i += 1;
        !missed.contains(&(i - 1))
    });
    out.check_counts().map_err(|e| {
        Error::Numerical(format!(
            "the true robot does not reach {} of the planned contacts from their planned \
             configurations: {e}",
            missed.len()
        ))
    })?;
    Ok((out, missed))
}

/// A plan's configurations (`planned`, where `nominal` touches its features) measured by the
/// true robot `truth` ([`touch`]), with the features' true places: where the nominal's planned
/// contacts put them (the truth reaches the same poses of the base frame), from the nominal
/// tool points of each feature's rows (a point's mean, a sphere's centre, a plane's point and
/// normal; exact for the noise-free plan). With `distances`, the true distances between every
/// pair of points or sphere centres replace the plan's. The rows the truth missed are returned
/// beside (see [`touch`]).
pub fn measure_plan(
    truth: &Robot,
    nominal: &Robot,
    planned: &ConstraintData,
    noise_mm: f64,
    seed: u64,
    distances: bool,
) -> Result<(SimulatedConstraints, Vec<usize>)> {
    use crate::identification::constraint::FeatureEstimate;
    let (mut data, missed) = touch(truth, nominal, planned, noise_mm, seed)?;
    let mut true_positions = Vec::new();
    let mut true_normals = Vec::new();
    for (k, f) in planned.features.iter().enumerate() {
        let pts: Vec<Vector3<f64>> = planned
            .rows_of(k)
            .map(|r| nominal.tool_position(&r.q))
            .collect();
        // A sphere of unknown radius: its centre and radius from the points.
        let e = FeatureEstimate::start(f.kind, &f.name, f.radius_mm, &pts).map_err(|m| {
            planned.parse_error(
                f.first_line,
                crate::observations::constraint::CONSTRAINT_COLUMN,
                m,
            )
        })?;
        match f.kind {
            ConstraintKind::Plane => {
                let n = e.normal.unwrap_or(Vector3::z());
                true_positions.push(pts.iter().sum::<Vector3<f64>>() / pts.len().max(1) as f64);
                true_normals.push(Some(n));
            }
            _ => {
                true_positions.push(e.position);
                true_normals.push(None);
            }
        }
    }
    data.distances.clear();
    if distances {
        let n = planned.features.len();
        for a in 0..n {
            for b in a + 1..n {
                if planned.features[a].kind == ConstraintKind::Plane
                    || planned.features[b].kind == ConstraintKind::Plane
                {
                    continue;
                }
                data.distances.push(KnownDistance {
                    from: a,
                    to: b,
                    distance_mm: (true_positions[a] - true_positions[b]).norm(),
                    line: 0,
                });
            }
        }
    }
    Ok((
        SimulatedConstraints {
            data,
            true_positions,
            true_normals,
        },
        missed,
    ))
}

/// The measurement file of simulated constraint data: joints, `constraint` and (for spheres)
/// `radius_mm` columns, no `x,y,z`.
pub fn constraint_measurements(robot: &Robot, data: &ConstraintData) -> MeasurementSet {
    let spheres = data
        .features
        .iter()
        .any(|f| f.kind == ConstraintKind::Sphere);
    let mut extra_columns = vec![crate::observations::constraint::CONSTRAINT_COLUMN.to_string()];
    if spheres {
        extra_columns.push(crate::observations::constraint::RADIUS_COLUMN.to_string());
    }
    let rows = data
        .rows
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let f = &data.features[r.feature];
            let mut extra = vec![f.label()];
            if spheres {
                extra.push(f.radius_mm.map_or(String::new(), |v| format!("{v}")));
            }
            Measurement {
                line: i + 2,
                q: r.q.clone(),
                p: None,
                extra,
            }
        })
        .collect();
    MeasurementSet {
        path: std::path::PathBuf::new(),
        joints: robot.joint_space().clone(),
        extra_columns,
        rows,
        warnings: Vec::new(),
    }
}

/// The distances file of `data` (`from,to,distance_mm`, 6 decimals).
pub fn distances_csv(data: &ConstraintData) -> String {
    let mut s = String::from("from,to,distance_mm\n");
    for d in &data.distances {
        s.push_str(&format!(
            "{},{},{:.6}\n",
            data.features[d.from].name, data.features[d.to].name, d.distance_mm
        ));
    }
    s
}

/// The error of a model against the true robot at `poses` after the best rigid alignment of
/// the model's tool points onto the truth's (a constraint calibration is up to the base pose):
/// mean and largest distance (mm).
pub fn aligned_model_error(model: &Robot, truth: &Robot, poses: &[Vec<f64>]) -> Result<(f64, f64)> {
    let m: Vec<Vector3<f64>> = poses.iter().map(|q| model.tool_position(q)).collect();
    let t: Vec<Vector3<f64>> = poses.iter().map(|q| truth.tool_position(q)).collect();
    let f = fit_rigid(&m, &t, None)?;
    let d: Vec<f64> = m
        .iter()
        .zip(&t)
        .map(|(a, b)| (f.to_base(a) - b).norm())
        .collect();
    let mean = d.iter().sum::<f64>() / d.len().max(1) as f64;
    Ok((mean, d.iter().cloned().fold(0.0, f64::max)))
}

/// The truth file of a constraint simulation (`FILE.truth.json` beside the data): the one the
/// other simulate modes write (the true robot's parameters; the tracker frame the identity, as
/// there is no tracker), with a `constraint` section holding the true features (base frame of
/// the true robot) and the simulation's settings. `truth_label` is the truth as given
/// (`random`, a preset, a file), `errors` the random errors' sizes (random truth), `data_file`
/// the data file's name.
pub fn truth_json(
    (nominal, truth): (&Robot, &Robot),
    (truth_label, errors): (&str, Option<GeometricErrors>),
    spec: &ConstraintSimulation,
    sim: &SimulatedConstraints,
    data_file: &str,
) -> Result<String> {
    use crate::io::result::{FrameVec, RobotInfo};
    use crate::simulation::{SetInfo, SimulationConfig, TruthFile};
    let identity = FrameVec {
        x: 0.0,
        y: 0.0,
        z: 0.0,
        a: 0.0,
        b: 0.0,
        c: 0.0,
    };
    let tf = TruthFile {
        generator: format!("robocal-core {}", env!("CARGO_PKG_VERSION")),
        robot: RobotInfo::shape_of(truth),
        nominal: nominal.name().to_owned(),
        truth: truth_label.to_owned(),
        parameters: TruthFile::parameter_entries(nominal, truth),
        tracker_frame: identity,
        settings: SimulationConfig {
            seed: spec.seed,
            poses: sim.data.rows.len(),
            validation_poses: 0,
            plane_points: false,
            plane_z_mm: None,
            tracker_frame: identity,
            noise_mm: spec.noise_mm,
            noise_per_m: 0.0,
            ..SimulationConfig::default()
        },
        geometric_errors: errors,
        joints_file: None,
        sets: [(
            "constraint".to_owned(),
            SetInfo {
                rows: sim.data.rows.len(),
                file: data_file.to_owned(),
            },
        )]
        .into_iter()
        .collect(),
        plane_z_mm: None,
        outliers: Vec::new(),
        gravity_effect: None,
        warnings: Vec::new(),
    };
    let ser = |e: serde_json::Error| Error::Numerical(format!("cannot serialize truth file: {e}"));
    let mut v = serde_json::to_value(&tf).map_err(ser)?;
    let features: Vec<serde_json::Value> = sim
        .data
        .features
        .iter()
        .zip(sim.true_positions.iter().zip(&sim.true_normals))
        .map(|(f, (p, n))| {
            serde_json::json!({
                "kind": f.kind.key(),
                "name": f.name,
                "position_mm": [p.x, p.y, p.z],
                "radius_mm": (f.kind == ConstraintKind::Sphere).then_some(spec.radius_mm),
                "radius_given": f.radius_mm.is_some(),
                "normal": n.map(|n| [n.x, n.y, n.z]),
            })
        })
        .collect();
    v["constraint"] = serde_json::json!({
        "frame": "base frame of the true robot",
        "kind": spec.kind.key(),
        "features": features,
        "per_feature": spec.per_feature,
        "tilt_deg": spec.tilt_deg,
        "span_mm": spec.span_mm,
        "distances": sim.data.distances.len(),
    });
    let mut s = serde_json::to_string_pretty(&v).map_err(ser)?;
    s.push('\n');
    Ok(s)
}
