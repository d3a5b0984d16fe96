//! Text tables in the layout of the paper's tables.

use robocal_core::model::family::{self, FamilyId};
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

/// The layout of the paper's Table III, built from the parameter families (each cell given by
/// `cell`): one row per joint with a column per template of every family whose parameters belong
/// to joints (alpha, d, a, phi, then beta where enabled, then any further family), and a column per
/// family of frame-vector parameters (B for the base, T for the tool correction) with x, y, z in mm
/// then A, B, C in degrees, and one per further reflector (T2, T3, ...: its tool, the same
/// rows). A column shows when some joint has its parameter; a cell is blank
/// where the robot lacks it. A robot with a prismatic joint gets a column with each joint's type.
pub fn layout(robot: &Robot, cell: &dyn Fn(Param) -> String) -> String {
    use std::fmt::Write;
    let n = robot.dof();
    let all = robot.param_list();
    // Per-joint columns: (family, template) with a `{j}` template that some joint has.
    let mut joint_cols: Vec<(FamilyId, u8, String)> = Vec::new();
    let mut frame_cols: Vec<(FamilyId, u8, &'static str)> = Vec::new();
    // Single parameters (a template without placeholder, e.g. `thermal_k`): a line each.
    let mut singles: Vec<Param> = Vec::new();
    // Further reflectors (`tool{j}_x`, j = 2..k: one per target, not per joint): a frame column
    // each, beside the tool's (T2, T3, ...).
    let mut target_cols: Vec<(FamilyId, u16, String)> = Vec::new();
    for (id, span) in robot.family_spans() {
        let fam = family::get(*id);
        if fam.key() == "reflector" {
            let mut targets: Vec<u16> =
                all[span.clone()].iter().map(|p| p.index() as u16).collect();
            targets.sort_unstable();
            targets.dedup();
            for t in targets {
                target_cols.push((*id, t, format!("{}{}", "T", t + 1)));
            }
            continue;
        }
        for (t, tpl) in fam.templates().iter().enumerate() {
            let present = all[span.clone()].iter().find(|p| p.template() == t);
            let Some(first) = present else { continue };
            if tpl.contains("{j}") {
                let title = format!("{} ({})", tpl.replace("{j}", ""), first.unit().as_str());
                joint_cols.push((*id, t as u8, title));
            } else if !tpl.contains("{axis}") {
                singles.push(*first);
            } else {
                frame_cols.push((*id, t as u8, fam.symbol()));
            }
        }
    }
    let types = robot.joint_space().any_prismatic();
    let mut s = String::new();
    let _ = write!(s, "{:>3}", "i");
    if types {
        let _ = write!(s, " {:>9}", "joint");
    }
    for (_, _, title) in &joint_cols {
        let _ = write!(s, " {title:>13}");
    }
    for (_, _, symbol) in &frame_cols {
        let _ = write!(s, " {symbol:>13}");
    }
    for (_, _, symbol) in &target_cols {
        let _ = write!(s, " {symbol:>13}");
    }
    s.push('\n');
    let frames = !frame_cols.is_empty() || !target_cols.is_empty();
    let rows = if frames { n.max(6) } else { n };
    for i in 0..rows {
        if i < n {
            let _ = write!(s, "{:>3}", i + 1);
            if types {
                let _ = write!(s, " {:>9}", robot.joint_type(i).as_str());
            }
            for (id, t, _) in &joint_cols {
                let p = Param::new(*id, *t, i as u16);
                let c = if robot.has_param(p) {
                    cell(p)
                } else {
                    String::new()
                };
                let _ = write!(s, " {c:>13}");
            }
        } else {
            let _ = write!(
                s,
                "{:>3}{}",
                "",
                " ".repeat(14 * joint_cols.len() + if types { 10 } else { 0 })
            );
        }
        if i < 6 && frames {
            for (id, t, _) in &frame_cols {
                let _ = write!(s, " {:>13}", cell(Param::new(*id, *t, i as u16)));
            }
            for (id, t, _) in &target_cols {
                let _ = write!(s, " {:>13}", cell(Param::new(*id, i as u8, *t)));
            }
            let unit = frame_cols
                .first()
                .map(|f| Param::new(f.0, f.1, i as u16))
                .or_else(|| target_cols.first().map(|t| Param::new(t.0, i as u8, t.1)))
                .map(|p| p.unit());
            if let Some(u) = unit {
                let _ = write!(s, "  ({})", u.as_str());
            }
        }
        s.push('\n');
    }
    for p in singles {
        let _ = writeln!(
            s,
            "{:<8} {:>13}  ({})",
            p.name(),
            cell(p),
            p.unit().as_str()
        );
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Table III of a robot with three reflectors: each further reflector is a column of its own
    /// (T2, T3) beside the tool's, its six offsets in the rows x..C; not six columns of joints.
    #[test]
    fn further_reflectors_are_columns_of_their_own() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/ur5-3reflectors.toml");
        let robot = robocal_core::load_robot_file(&path).unwrap();
        assert_eq!(robot.target_count(), 3);
        let t = parameter_table(&robot, 3);
        let lines: Vec<&str> = t.lines().collect();
        let head: Vec<&str> = lines[0].split_whitespace().collect();
        assert_eq!(&head[head.len() - 4..], ["B", "T", "T2", "T3"], "{t}");
        assert!(!t.contains("tool_x"), "{t}");
        let width = lines.iter().map(|l| l.chars().count()).max().unwrap();
        // Two columns more than one reflector's table (122 characters; with the reflectors as
        // joint columns it was 178).
        assert!(width <= 122, "{width} characters wide:\n{t}");
        // The rows x..C carry each reflector's correction, as T does the tool's.
        for (k, name) in ["x", "y", "z", "a", "b", "c"].iter().enumerate() {
            let p = robot.param_by_name(&format!("tool2_{name}")).unwrap();
            let cells: Vec<&str> = lines[k + 1].split_whitespace().collect();
            assert_eq!(cells[cells.len() - 3], num(robot.get_display(p), 3), "{t}");
        }
    }
}
