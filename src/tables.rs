//! Text tables in the layout of the paper's tables.

use robocal_core::{Param, Robot};

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
/// columns B and T with x, y, z in mm and A, B, C in degrees), each cell given by `cell`.
pub fn layout(robot: &Robot, cell: &dyn Fn(Param) -> String) -> String {
    use std::fmt::Write;
    let n = robot.dof();
    let any_beta = (0..n).any(|i| robot.beta_enabled(i));
    let mut s = String::new();
    let _ = write!(
        s,
        "{:>3} {:>13} {:>13} {:>13} {:>13}",
        "i", "alpha (deg)", "d (mm)", "a (mm)", "phi (deg)"
    );
    if any_beta {
        let _ = write!(s, " {:>13}", "beta (deg)");
    }
    let _ = writeln!(s, " {:>13} {:>13}", "B", "T");
    let units = ["mm", "mm", "mm", "deg", "deg", "deg"];
    for i in 0..n.max(6) {
        if i < n {
            let _ = write!(s, "{:>3}", i + 1);
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
                " ".repeat(14 * if any_beta { 5 } else { 4 })
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
