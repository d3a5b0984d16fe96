//! The fixed features' own parameters, estimated with the robot's: a point (3 coordinates), a
//! sphere (centre, and the radius when unknown) or a plane (unit normal `n` and offset `d`, the
//! plane `n . x = d`; the normal moves in its tangent plane, two parameters). Each gives residual
//! rows for a tool point `p` (base frame, mm) and their derivatives with respect to `p` and to
//! its parameters:
//!
//! - point: `e = p - c` (3 rows);
//! - sphere: `e = |p - c| - r` (1 row);
//! - plane: `e = n . p - d` (1 row).
//!
//! Start values need no guess: from the nominal model's tool points of the feature's rows, the
//! mean point, an algebraic sphere fit (linear in the centre and `r^2 - |c|^2`), a least-squares
//! plane (the smallest principal axis of the points).

use crate::observations::constraint::ConstraintKind;
use nalgebra::{DMatrix, DVector, Matrix3, SymmetricEigen, Vector3};

/// Smallest spread of a plane's points across their main direction, relative to the spread
/// along it (RMS): below, the points are (nearly) collinear and the plane turns freely about
/// their line.
pub const MIN_PLANE_SPREAD: f64 = 0.01;

/// An estimated fixed feature.
#[derive(Debug, Clone, PartialEq)]
pub struct FeatureEstimate {
    /// Its kind.
    pub kind: ConstraintKind,
    /// Its name.
    pub name: String,
    /// A point's position, a sphere's centre, or a plane's point nearest the base origin
    /// (`n d`) (mm, base frame of the calibrated model).
    pub position: Vector3<f64>,
    /// A sphere's radius (mm): given, or estimated when `radius_known` is false.
    pub radius_mm: Option<f64>,
    /// Whether a sphere's radius was given (and held).
    pub radius_known: bool,
    /// A plane's unit normal (base frame).
    pub normal: Option<Vector3<f64>>,
    /// A plane's offset `d` along its normal (mm).
    pub offset_mm: Option<f64>,
}

impl FeatureEstimate {
    /// `kind:name`.
    pub fn label(&self) -> String {
        format!("{}:{}", self.kind.key(), self.name)
    }

    /// Number of the feature's own parameters in a fit.
    pub fn param_count(&self) -> usize {
        match self.kind {
            ConstraintKind::Point => 3,
            ConstraintKind::Sphere => 3 + usize::from(!self.radius_known),
            ConstraintKind::Plane => 3,
        }
    }

    /// Names of the feature's parameters (`A.x`, `S.r`, `F.tilt1`, `F.d`), for messages.
    pub fn param_names(&self) -> Vec<String> {
        let n = &self.name;
        match self.kind {
            ConstraintKind::Point | ConstraintKind::Sphere => {
                let mut v: Vec<String> =
                    ["x", "y", "z"].iter().map(|a| format!("{n}.{a}")).collect();
                if self.param_count() == 4 {
                    v.push(format!("{n}.r"));
                }
                v
            }
            ConstraintKind::Plane => {
                vec![format!("{n}.tilt1"), format!("{n}.tilt2"), format!("{n}.d")]
            }
        }
    }

    /// Residual rows per tool point.
    pub fn rows(&self) -> usize {
        match self.kind {
            ConstraintKind::Point => 3,
            _ => 1,
        }
    }

    /// The residual rows `e` for tool point `p`, their derivatives with respect to `p` (one
    /// vector per row) and to the feature's parameters (row-major, `rows x param_count`).
    pub fn residual(
        &self,
        p: &Vector3<f64>,
        e: &mut [f64],
        dp: &mut [Vector3<f64>],
        df: &mut [f64],
    ) {
        let k = self.param_count();
        df[..self.rows() * k].fill(0.0);
        match self.kind {
            ConstraintKind::Point => {
                let r = p - self.position;
                for a in 0..3 {
                    e[a] = r[a];
                    dp[a] = Vector3::ith(a, 1.0);
                    df[a * k + a] = -1.0;
                }
            }
            ConstraintKind::Sphere => {
                let r = p - self.position;
                let len = r.norm();
                let u = if len > 0.0 { r / len } else { Vector3::z() };
                e[0] = len - self.radius_mm.unwrap_or(0.0);
                dp[0] = u;
                for a in 0..3 {
                    df[a] = -u[a];
                }
                if k == 4 {
                    df[3] = -1.0;
                }
            }
            ConstraintKind::Plane => {
                let n = self.normal.unwrap_or(Vector3::z());
                let (t1, t2) = tangents(&n);
                e[0] = n.dot(p) - self.offset_mm.unwrap_or(0.0);
                dp[0] = n;
                df[0] = t1.dot(p);
                df[1] = t2.dot(p);
                df[2] = -1.0;
            }
        }
    }

    /// Applies a step `dx` (`param_count` numbers) to the feature's parameters.
    pub fn apply(&mut self, dx: &[f64]) {
        match self.kind {
            ConstraintKind::Point | ConstraintKind::Sphere => {
                self.position += Vector3::new(dx[0], dx[1], dx[2]);
                if self.param_count() == 4 {
                    self.radius_mm = self.radius_mm.map(|r| r + dx[3]);
                }
            }
            ConstraintKind::Plane => {
                let n = self.normal.unwrap_or(Vector3::z());
                let (t1, t2) = tangents(&n);
                let n = (n + dx[0] * t1 + dx[1] * t2).normalize();
                let d = self.offset_mm.unwrap_or(0.0) + dx[2];
                self.set_plane(n, d);
            }
        }
    }

    fn set_plane(&mut self, n: Vector3<f64>, d: f64) {
        self.normal = Some(n);
        self.offset_mm = Some(d);
        self.position = n * d;
    }

    /// The feature's start values from the nominal tool points of its rows (see the module
    /// docs). A sphere whose points lie on one plane or a plane whose points lie on one line is
    /// an error (the message says what is wrong).
    pub fn start(
        kind: ConstraintKind,
        name: &str,
        radius_mm: Option<f64>,
        points: &[Vector3<f64>],
    ) -> std::result::Result<FeatureEstimate, String> {
        let n = points.len().max(1) as f64;
        let mean = points.iter().sum::<Vector3<f64>>() / n;
        let mut f = FeatureEstimate {
            kind,
            name: name.to_owned(),
            position: mean,
            radius_mm,
            radius_known: radius_mm.is_some(),
            normal: None,
            offset_mm: None,
        };
        match kind {
            ConstraintKind::Point => {}
            ConstraintKind::Sphere => {
                // |p - c|^2 = r^2  <=>  2 p.c + (r^2 - |c|^2) = |p|^2, about the mean.
                let a = DMatrix::from_fn(points.len(), 4, |i, j| {
                    let p = points[i] - mean;
                    if j < 3 {
                        2.0 * p[j]
                    } else {
                        1.0
                    }
                });
                let b = DVector::from_fn(points.len(), |i, _| (points[i] - mean).norm_squared());
                let svd = a.svd(true, true);
                let (smax, smin) = (svd.singular_values.max(), svd.singular_values.min());
                if smin.is_nan() || smin <= 1e-9 * smax {
                    return Err(format!(
                        "sphere `{name}`: its points lie on one plane (or line), so its centre is \
                         undetermined; touch it from directions spread over the sphere"
                    ));
                }
                let x = svd.solve(&b, 0.0).map_err(|e| e.to_string())?;
                let c = Vector3::new(x[0], x[1], x[2]);
                f.position = mean + c;
                if radius_mm.is_none() {
                    f.radius_mm = Some((x[3] + c.norm_squared()).max(0.0).sqrt());
                }
            }
            ConstraintKind::Plane => {
                let cov: Matrix3<f64> = points
                    .iter()
                    .map(|p| (p - mean) * (p - mean).transpose())
                    .sum::<Matrix3<f64>>()
                    / n;
                let eig = SymmetricEigen::new(cov);
                let mut order = [0, 1, 2];
                order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
                let along = eig.eigenvalues[order[2]].max(0.0).sqrt();
                let across = eig.eigenvalues[order[1]].max(0.0).sqrt();
                if across.is_nan() || across <= MIN_PLANE_SPREAD * along {
                    return Err(format!(
                        "plane `{name}`: its points are collinear (spread {across:.3} mm across \
                         their line against {along:.3} mm along it), so the plane can turn about \
                         that line; touch it at points spread in two directions"
                    ));
                }
                let normal: Vector3<f64> =
                    eig.eigenvectors.column(order[0]).into_owned().normalize();
                f.set_plane(normal, normal.dot(&mean));
            }
        }
        Ok(f)
    }
}

/// Two unit vectors completing `n` to a right-handed orthonormal basis.
pub(crate) fn tangents(n: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let k = n.iamin();
    let t1 = n.cross(&Vector3::ith(k, 1.0)).normalize();
    (t1, n.cross(&t1))
}
