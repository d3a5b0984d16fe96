//! The fixed features of a cell to plan constraint configurations for (issue 31): where they
//! are, roughly (a features file, or places drawn as `simulate --constraint` draws them), and
//! the candidate configurations that reach them, found by inverse kinematics on the nominal
//! robot with [`crate::simulation::constraint`]'s generator.
//!
//! A features file is a CSV with a header naming its columns (any order, any case):
//! `constraint` (`point:NAME`, `sphere:NAME` or `plane:NAME`, as in the measurement file),
//! `x,y,z` (mm, the robot's base frame: a point's place, a sphere's centre, a point of the
//! plane), `nx,ny,nz` (a plane's normal, pointing to the side the probe comes from; for a sphere
//! the direction from its centre to the middle of the touched cap, default straight up) and
//! `radius_mm` (a sphere's radius). Places need only be as good as a teach pendant gives them
//! (the calibration estimates them).

use crate::compensation::{Compensator, DampedLeastSquares};
use crate::error::{Error, Result};
use crate::frame::Frame;
use crate::model::Robot;
use crate::observations::constraint::{ConstraintData, ConstraintKind, KnownDistance};
use crate::simulation::constraint::{
    contacts, simulate_constraints, ConstraintSimulation, SimulatedConstraints, REFERENCE_TRIES,
};
use crate::simulation::{random_poses, PoseSampler};
use nalgebra::{Rotation3, Translation3, Vector3};
use rand::SeedableRng;
use std::path::{Path, PathBuf};

/// Most features a plan takes.
pub const MAX_FEATURES: usize = 100;

/// A feature whose place is given.
#[derive(Debug, Clone, PartialEq)]
pub struct GivenFeature {
    /// Its kind.
    pub kind: ConstraintKind,
    /// Its name.
    pub name: String,
    /// A point's place, a sphere's centre, a point of a plane (mm, base frame).
    pub position: Vector3<f64>,
    /// A plane's unit normal (toward the probe's side); a sphere's touched side (unit).
    pub normal: Option<Vector3<f64>>,
    /// A sphere's radius (mm).
    pub radius_mm: Option<f64>,
    /// The 1-based line in its file (0 when not from a file).
    pub line: usize,
}

/// Where a plan's features are.
#[derive(Debug, Clone, PartialEq)]
pub enum FeaturePlaces {
    /// Drawn as `simulate --constraint` draws them: where random configurations of the robot
    /// put its tool point (the simulation's kind, count, radius and seed).
    Drawn,
    /// Given (a features file, named in messages).
    Given {
        /// The file, for messages.
        path: PathBuf,
        /// The features.
        features: Vec<GivenFeature>,
    },
}

/// Reads a features file (see the module docs). Every error names the file, line and column.
pub fn read_features(path: &Path) -> Result<Vec<GivenFeature>> {
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
        path: path.to_owned(),
        source,
    })?;
    parse_features(path, &text)
}

/// Parses a features file's `text` (see [`read_features`]).
pub fn parse_features(path: &Path, text: &str) -> Result<Vec<GivenFeature>> {
    let perr =
        |line: Option<usize>, field: &str, msg: String| Error::parse(path, line, Some(field), msg);
    let mut rd = csv::ReaderBuilder::new()
        .has_headers(true)
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_reader(text.as_bytes());
    let header: Vec<String> = rd
        .headers()
        .map_err(|e| perr(Some(1), "header", e.to_string()))?
        .iter()
        .map(|h| h.to_ascii_lowercase())
        .collect();
    let cols = FeatureColumns::of(&header, path)?;
    let mut out: Vec<GivenFeature> = Vec::new();
    for rec in rd.records() {
        let rec = rec.map_err(|e| {
            perr(
                e.position().map(|p| p.line() as usize),
                "row",
                e.to_string(),
            )
        })?;
        let feature = feature_row(&rec, &cols, &out, path)?;
        out.push(feature);
    }
    if out.is_empty() {
        return Err(perr(
            None,
            "constraint",
            "no feature: give at least one row (constraint,x,y,z, ...)".into(),
        ));
    }
    if out.len() > MAX_FEATURES {
        return Err(perr(
            None,
            "constraint",
            format!(
                "{} features; a plan takes at most {MAX_FEATURES}",
                out.len()
            ),
        ));
    }
    Ok(out)
}

/// The columns of a features file: `constraint,x,y,z` required, `nx,ny,nz,radius_mm` optional.
struct FeatureColumns {
    label: usize,
    xyz: [usize; 3],
    normal: [Option<usize>; 3],
    radius: Option<usize>,
}

impl FeatureColumns {
    /// The columns of the lower-cased `header`; an error names a required one missing.
    fn of(header: &[String], path: &Path) -> Result<FeatureColumns> {
        let col = |name: &str| header.iter().position(|h| h == name);
        let need = |name: &str| {
            col(name).ok_or_else(|| {
                Error::parse(
                    path,
                    Some(1),
                    Some(name),
                    format!(
                        "no `{name}` column (a features file has the columns constraint,x,y,z \
                         and, as needed, nx,ny,nz,radius_mm)"
                    ),
                )
            })
        };
        Ok(FeatureColumns {
            label: need("constraint")?,
            xyz: [need("x")?, need("y")?, need("z")?],
            normal: [col("nx"), col("ny"), col("nz")],
            radius: col("radius_mm"),
        })
    }
}

/// The feature of one row: its kind and name (not one of the `earlier` rows'), position, normal
/// (all three or none; a plane needs one) and radius (a sphere needs one within (0, 1000] mm).
fn feature_row(
    rec: &csv::StringRecord,
    cols: &FeatureColumns,
    earlier: &[GivenFeature],
    path: &Path,
) -> Result<GivenFeature> {
    let perr =
        |line: Option<usize>, field: &str, msg: String| Error::parse(path, line, Some(field), msg);
    let line = rec.position().map_or(0, |p| p.line() as usize);
    let cell = |c: Option<usize>| c.and_then(|c| rec.get(c)).unwrap_or("");
    let num = |c: Option<usize>, field: &str| -> Result<Option<f64>> {
        let s = cell(c);
        if s.is_empty() {
            return Ok(None);
        }
        match s.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(Some(v)),
            _ => Err(perr(
                Some(line),
                field,
                format!("`{s}` is not a finite number"),
            )),
        }
    };
    let label = cell(Some(cols.label));
    let (kind, name) = label
        .split_once(':')
        .and_then(|(k, n)| Some((ConstraintKind::parse(k)?, n.trim())))
        .filter(|(_, n)| !n.is_empty())
        .ok_or_else(|| {
            perr(
                Some(line),
                "constraint",
                format!("`{label}` is not point:NAME, sphere:NAME or plane:NAME"),
            )
        })?;
    if let Some(f) = earlier.iter().find(|f| f.name == name) {
        return Err(perr(
            Some(line),
            "constraint",
            format!("the name `{name}` is already given on line {}", f.line),
        ));
    }
    let mut xyz = [0.0; 3];
    for (v, (c, f)) in xyz
        .iter_mut()
        .zip(cols.xyz.into_iter().zip(["x", "y", "z"]))
    {
        *v = num(Some(c), f)?
            .ok_or_else(|| perr(Some(line), f, "missing (mm, base frame)".into()))?;
    }
    let [cnx, cny, cnz] = cols.normal;
    let n = [num(cnx, "nx")?, num(cny, "ny")?, num(cnz, "nz")?];
    let normal = match n {
        [None, None, None] => None,
        [Some(a), Some(b), Some(c)] => {
            let v = Vector3::new(a, b, c);
            if v.norm() < 1e-9 {
                return Err(perr(Some(line), "nx", "the normal is zero".into()));
            }
            Some(v.normalize())
        }
        _ => {
            return Err(perr(
                Some(line),
                "nx",
                "give all three of nx,ny,nz or none".into(),
            ))
        }
    };
    let radius_mm = num(cols.radius, "radius_mm")?;
    match kind {
        ConstraintKind::Plane if normal.is_none() => {
            return Err(perr(
                Some(line),
                "nx",
                format!(
                    "plane `{name}` needs its normal nx,ny,nz (toward the side the probe comes \
                     from)"
                ),
            ))
        }
        ConstraintKind::Sphere if !radius_mm.is_some_and(|r| r > 0.0 && r <= 1000.0) => {
            return Err(perr(
                Some(line),
                "radius_mm",
                format!("sphere `{name}` needs its radius, within (0, 1000] mm"),
            ))
        }
        _ => {}
    }
    Ok(GivenFeature {
        kind,
        name: name.to_owned(),
        position: Vector3::from(xyz),
        normal: match kind {
            ConstraintKind::Point => None,
            ConstraintKind::Sphere => Some(normal.unwrap_or(Vector3::z())),
            ConstraintKind::Plane => normal,
        },
        radius_mm: (kind == ConstraintKind::Sphere)
            .then_some(radius_mm)
            .flatten(),
        line,
    })
}

/// `spec.per_feature` candidate configurations for every feature of `places`, reached by
/// `robot` (noise-free), with the features' places and normals. Given features unreachable from
/// [`REFERENCE_TRIES`] random configurations are an error naming their line.
pub(crate) fn candidates(
    robot: &Robot,
    sampler: &PoseSampler,
    spec: &ConstraintSimulation,
    places: &FeaturePlaces,
) -> Result<SimulatedConstraints> {
    let (path, given) = match places {
        FeaturePlaces::Drawn => return simulate_constraints(robot, sampler, spec),
        FeaturePlaces::Given { path, features } => (path, features),
    };
    if given.is_empty() {
        return Err(Error::parse(
            path,
            None,
            Some("constraint"),
            "no feature".to_string(),
        ));
    }
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(spec.seed);
    let mut ik = Compensator::new(robot, robot, DampedLeastSquares::default())?;
    ik.pose_solver.tolerance_mm = 1e-10;
    ik.pose_solver.tolerance_deg = 1e-9;
    let mut data = ConstraintData::new(robot.dof());
    let mut q1 = vec![0.0; robot.dof()];
    for g in given {
        let fspec = ConstraintSimulation {
            kind: g.kind,
            radius_mm: g.radius_mm.unwrap_or(spec.radius_mm),
            ..spec.clone()
        };
        fspec.validate()?;
        let contact = match g.kind {
            ConstraintKind::Sphere => g.position + fspec.radius_mm * g.normal.unwrap_or_default(),
            _ => g.position,
        };
        let mut rows = None;
        for _ in 0..REFERENCE_TRIES {
            let q = random_poses(robot, 1, sampler, &mut rng)?.remove(0);
            let t = robot.tool_pose(&q);
            let rot = match g.normal {
                Some(n) => {
                    let z = t.rotation * Vector3::z();
                    Rotation3::rotation_between(&z, &n)
                        .unwrap_or_else(|| Rotation3::from_axis_angle(&Vector3::x_axis(), 1.0e-9))
                        * t.rotation
                }
                None => t.rotation,
            };
            let target = Frame::from_parts(Translation3::from(contact), rot);
            let rep = ik.reach_pose(&target, Some(&q), &mut q1);
            if !rep.status.reaches_target()
                || !robot.joints_outside_limits(&q1).is_empty()
                || (robot.tool_position(&q1) - contact).norm() > 1e-6
            {
                continue;
            }
            if let Some(r) = contacts(robot, &ik, &q1, &fspec, &mut rng) {
                rows = Some(r);
                break;
            }
        }
        let Some(rows) = rows else {
            return Err(Error::parse(
                path,
                Some(g.line),
                Some("x"),
                format!(
                    "`{}:{}` at ({:.1}, {:.1}, {:.1}) mm is out of the robot's reach: no \
                     configuration of {REFERENCE_TRIES} tried brings the tool there{} within the \
                     joint limits (check the place and the frame: the robot's base frame, mm)",
                    g.kind.key(),
                    g.name,
                    g.position.x,
                    g.position.y,
                    g.position.z,
                    if g.kind == ConstraintKind::Point {
                        String::new()
                    } else {
                        " along the normal and into its touched region".to_string()
                    }
                ),
            ));
        };
        let radius =
            (g.kind == ConstraintKind::Sphere && spec.radius_known).then_some(fspec.radius_mm);
        let f = data
            .feature_index(g.kind, &g.name, radius, g.line)
            .map_err(|(field, m)| Error::parse(path, Some(g.line), Some(field), m))?;
        for q in rows {
            data.push(q, f, 0)?;
        }
    }
    let true_positions: Vec<Vector3<f64>> = given.iter().map(|g| g.position).collect();
    if spec.distances {
        let centres: Vec<usize> = (0..given.len())
            .filter(|&i| given[i].kind != ConstraintKind::Plane)
            .collect();
        for (a, &i) in centres.iter().enumerate() {
            for &j in &centres[a + 1..] {
                data.distances.push(KnownDistance {
                    from: i,
                    to: j,
                    distance_mm: (true_positions[i] - true_positions[j]).norm(),
                    line: 0,
                });
            }
        }
    }
    Ok(SimulatedConstraints {
        data,
        true_positions,
        true_normals: given
            .iter()
            .map(|g| {
                (g.kind == ConstraintKind::Plane)
                    .then_some(g.normal)
                    .flatten()
            })
            .collect(),
    })
}
