//! Text tables in the layout of the paper's tables.

use robocal_core::{Param, Robot};
use std::fmt::Write;

fn num(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    // Avoid "-0.0000".
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
    let n = robot.dof();
    let any_beta = (0..n).any(|i| robot.beta_enabled(i));
    let mut s = String::new();
    let _ = write!(
        s,
        "{:>3} {:>12} {:>12} {:>12} {:>12}",
        "i", "alpha (deg)", "d (mm)", "a (mm)", "phi (deg)"
    );
    if any_beta {
        let _ = write!(s, " {:>12}", "beta (deg)");
    }
    let _ = writeln!(s, " {:>12} {:>12}", "B", "T");
    let axes = ["mm", "mm", "mm", "deg", "deg", "deg"];
    for i in 0..n.max(6) {
        if i < n {
            let _ = write!(
                s,
                "{:>3} {:>12} {:>12} {:>12} {:>12}",
                i + 1,
                num(robot.get_display(Param::Alpha(i)), decimals),
                num(robot.get_display(Param::D(i)), decimals),
                num(robot.get_display(Param::A(i)), decimals),
                num(robot.get_display(Param::Phi(i)), decimals),
            );
            if any_beta {
                let b = if robot.beta_enabled(i) {
                    num(robot.get_display(Param::Beta(i)), decimals)
                } else {
                    "-".into()
                };
                let _ = write!(s, " {b:>12}");
            }
        } else {
            let _ = write!(s, "{:>3} {:>12} {:>12} {:>12} {:>12}", "", "", "", "", "");
            if any_beta {
                let _ = write!(s, " {:>12}", "");
            }
        }
        if i < 6 {
            let _ = write!(
                s,
                " {:>12} {:>12}  ({})",
                num(robot.get_display(Param::Base(i)), decimals),
                num(robot.get_display(Param::Tool(i)), decimals),
                axes[i]
            );
        }
        s.push('\n');
    }
    s
}
