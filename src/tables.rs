//! Text tables in the layout of the paper's tables.

use robocal_core::{Controller, Param, Robot};

/// A number with `decimals` decimals, without a minus sign on zero; `-` when not finite.
pub fn num(v: f64, decimals: usize) -> String {
    if !v.is_finite() {
        return "-".into();
    }
    let s = format!("{v:.decimals$}");
    if s.trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        s.trim_start_matches('-').to_owned()
    } else {
        s
    }
}

/// The parameter table in the layout of the paper's Tables I and III: one row per joint with
/// alpha, d, a, phi (and beta where enabled), and the columns B (base) and T (tool correction),
/// x, y, z in mm then A, B, C in degrees.
pub fn parameter_table(robot: &Robot, decimals: usize) -> String {
    layout(robot, &|p| num(robot.get_display(p), decimals))
}

/// The layout of the paper's Table III (rows per joint: alpha, d, a, phi and beta where enabled;
/// columns B and T with x, y, z in mm and A, B, C in degrees), each cell given by `cell`. A robot
/// with a prismatic joint gets a column with each joint's type.
pub fn layout(robot: &Robot, cell: &dyn Fn(Param) -> String) -> String {
    use std::fmt::Write;
    let n = robot.dof();
    let any_beta = (0..n).any(|i| robot.beta_enabled(i));
    let types = robot.joint_space().any_prismatic();
    let mut s = String::new();
    let _ = write!(s, "{:>3}", "i");
    if types {
        let _ = write!(s, " {:>9}", "joint");
    }
    let _ = write!(
        s,
        " {:>13} {:>13} {:>13} {:>13}",
        "alpha (deg)", "d (mm)", "a (mm)", "phi (deg)"
    );
    if any_beta {
        let _ = write!(s, " {:>13}", "beta (deg)");
    }
    let _ = writeln!(s, " {:>13} {:>13}", "B", "T");
    let units = ["mm", "mm", "mm", "deg", "deg", "deg"];
    for i in 0..n.max(6) {
        if i < n {
            let _ = write!(s, "{:>3}", i + 1);
            if types {
                let _ = write!(s, " {:>9}", robot.joint_type(i).as_str());
            }
            for p in [Param::Alpha(i), Param::D(i), Param::A(i), Param::Phi(i)] {
                let _ = write!(s, " {:>13}", cell(p));
            }
            if any_beta {
                let b = if robot.beta_enabled(i) {
                    cell(Param::Beta(i))
                } else {
                    String::new()
                };
                let _ = write!(s, " {b:>13}");
            }
        } else {
            let _ = write!(
                s,
                "{:>3}{}",
                "",
                " ".repeat(14 * if any_beta { 5 } else { 4 } + if types { 10 } else { 0 })
            );
        }
        if i < 6 {
            let _ = write!(
                s,
                " {:>13} {:>13}  ({})",
                cell(Param::Base(i)),
                cell(Param::Tool(i)),
                units[i]
            );
        }
        s.push('\n');
    }
    s
}

/// The controller map as one equation per joint, e.g. `q3 = -axis3 - 1 axis2` or
/// `q1 = axis1 + 100 mm`.
pub fn controller_map(c: &Controller, robot: &Robot) -> Vec<String> {
    let term = |k: f64, name: String, first: bool| -> String {
        let sign = if k < 0.0 {
            "-"
        } else if first {
            ""
        } else {
            "+"
        };
        let mag = k.abs();
        let body = if mag == 1.0 {
            name
        } else {
            format!("{mag} {name}")
        };
        if first {
            format!("{sign}{body}")
        } else {
            format!(" {sign} {body}")
        }
    };
    (0..c.dof())
        .map(|i| {
            let mut s = format!(
                "q{} = {}",
                i + 1,
                term(c.sign()[i], format!("axis{}", i + 1), true)
            );
            for cp in c.coupling().iter().filter(|cp| cp.joint == i) {
                s.push_str(&term(cp.factor, format!("axis{}", cp.axis + 1), false));
            }
            let o = c.offset()[i];
            if o != 0.0 {
                s.push_str(&format!(
                    " {} {} {}",
                    if o < 0.0 { "-" } else { "+" },
                    o.abs(),
                    robot.joint_unit(i).as_str()
                ));
            }
            s
        })
        .collect()
}
