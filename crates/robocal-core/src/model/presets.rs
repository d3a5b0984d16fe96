//! Built-in robots.
//!
//! - `kuka-kr480-r3330`: the paper's Table I (modified DH), the nominal tool T0 of eq. 7 and the
//!   joint limits of DESIGN.md (model joint values), and KUKA's axis map
//!   q = (-A1, A2, A3, -A4, A5, -A6) (DESIGN.md) as its `[controller]`.
//! - `kuka-kr480-r3330-table3`: the paper's calibrated parameters (Table III), with the base and
//!   tool corrections of its columns B and T and the same axis map; the simulator uses it as a
//!   "true" robot.

use super::{Controller, Convention, JointLimit, Link, Param, Robot};
use crate::error::{Error, Result};

/// Names of the built-in presets.
pub const PRESETS: &[&str] = &["kuka-kr480-r3330", "kuka-kr480-r3330-table3"];

/// The paper's nominal tool vector T0 (eq. 7): mm and degrees.
pub const KR480_T0: [f64; 6] = [42.4163, -70.9065, 239.5558, -0.038, 0.237, 0.054];

/// Table I rows `(alpha deg, d mm, a mm, phi deg)`.
const KR480_TABLE1: [[f64; 4]; 6] = [
    [0.0, 1045.0, 0.0, 0.0],
    [-90.0, 0.0, 500.0, 0.0],
    [0.0, 0.0, 1300.0, -90.0],
    [-90.0, 1525.0, -55.0, 0.0],
    [90.0, 0.0, 0.0, 0.0],
    [-90.0, 290.0, 0.0, 180.0],
];

/// Table III rows `(alpha deg, d mm, a mm, phi deg)`.
const KR480_TABLE3: [[f64; 4]; 6] = [
    [0.0, 1044.237, 0.0, 0.0786],
    [-89.9952, -0.0003, 499.263, -0.0028],
    [-0.00560, -0.0001, 1300.18, -89.946],
    [-90.0078, 1525.997, -55.08, 0.0027],
    [90.0378, 0.0002, 0.1369, -0.0019],
    [-90.0493, 289.8875, 0.0000, 179.987],
];

/// Table III column B (mm, mm, mm, deg, deg, deg).
const KR480_TABLE3_B: [f64; 6] = [1.9418, -0.5750, -0.9741, -0.0497, -0.0512, 0.0011];
/// Table III column T (mm, mm, mm, deg, deg, deg).
const KR480_TABLE3_T: [f64; 6] = [0.0035, -0.4149, -0.1159, 0.0781, 0.0198, -0.0797];

/// KR 480 R3330 joint limits in model joint values (degrees).
const KR480_LIMITS: [[f64; 2]; 6] = [
    [-185.0, 185.0],
    [-130.0, 20.0],
    [-100.0, 144.0],
    [-350.0, 350.0],
    [-120.0, 120.0],
    [-350.0, 350.0],
];

/// KUKA's controller axes A1..A6 against the model joints of Table I: q = (-A1, A2, A3, -A4, A5,
/// -A6) (DESIGN.md).
pub const KUKA_AXIS_SIGNS: [f64; 6] = [-1.0, 1.0, 1.0, -1.0, 1.0, -1.0];

fn kr480(name: &str, table: &[[f64; 4]; 6]) -> Robot {
    let links = table
        .iter()
        .map(|r| Link {
            alpha: r[0].to_radians(),
            d: r[1],
            a: r[2],
            phi: r[3].to_radians(),
            beta: 0.0,
        })
        .collect();
    let limits = KR480_LIMITS
        .iter()
        .map(|l| JointLimit {
            min: l[0].to_radians(),
            max: l[1].to_radians(),
        })
        .collect();
    let mut r = Robot::new(
        name,
        Convention::Mdh,
        links,
        limits,
        [0.0; 6],
        crate::frame::vec_deg_to_rad(&KR480_T0),
    )
    .expect("built-in preset is valid");
    let kuka = Controller::new(KUKA_AXIS_SIGNS.to_vec(), vec![0.0; 6], Vec::new())
        .expect("KUKA axis map is valid");
    r.set_controller(Some(kuka))
        .expect("KUKA axis map has 6 axes");
    r
}

/// Returns a built-in robot by name.
pub fn preset(name: &str) -> Result<Robot> {
    match name {
        "kuka-kr480-r3330" => Ok(kr480(name, &KR480_TABLE1)),
        "kuka-kr480-r3330-table3" => {
            let mut r = kr480(name, &KR480_TABLE3);
            for k in 0..6 {
                r.set_display(Param::base(k), KR480_TABLE3_B[k]);
                r.set_display(Param::tool(k), KR480_TABLE3_T[k]);
            }
            Ok(r)
        }
        _ => Err(Error::UnknownPreset {
            name: name.to_owned(),
            known: PRESETS.join(", "),
        }),
    }
}
