//! `robocal compensate --program`: where each listed line is (a KRL `.src` or its `.dat`), and a
//! target one value cannot serve: used directly and with an offset, or as the base of an offset
//! the controller computes. Such a run stops (exit 5, nothing written) naming the target and
//! both lines, unless `--keep-going`.

use crate::cli_programs::{cell, compensate_program, models, shipped};
use crate::util::*;

/// With a `.src` and its `.dat`, the listing, the refusal and `--changes` name each line's file.
#[test]
fn the_listing_names_the_file_of_each_kuka_line() {
    let dir = Dir::new();
    let (nom, _, res) = models(&dir, "kr480.src");
    let (src, config) = cell(&dir, &nom, 3);
    let dat = std::fs::read_to_string(dir.join("cell.dat")).unwrap();
    let xp1 = dat
        .lines()
        .position(|l| l.starts_with("DECL E6POS XP1="))
        .unwrap()
        + 1;
    let out = dir.join("out.src");
    // Without the $config.dat the points' frames are unknown: each named with its file.
    let o = compensate_program(&res, &src, &out, &[]);
    o.assert_code(5);
    assert!(
        o.stderr()
            .contains(&format!("XP1 (cell.dat line {xp1}): frame unknown")),
        "{}",
        o.stderr()
    );
    assert!(o.stderr().contains("(cell.src line "), "{}", o.stderr());
    assert!(!out.exists());
    let changes = dir.join("changes.csv");
    let o = compensate_program(
        &res,
        &src,
        &out,
        &["--config", p(&config), "--changes", p(&changes)],
    );
    o.assert_ok();
    assert!(o.stdout().contains("file:line"), "{}", o.stdout());
    assert!(
        o.stdout().contains(&format!("cell.dat:{xp1} ")),
        "{}",
        o.stdout()
    );
    let csv = std::fs::read_to_string(&changes).unwrap();
    let rows: Vec<Vec<&str>> = csv.lines().map(|l| l.split(',').collect()).collect();
    assert_eq!(rows[0].last(), Some(&"file"));
    // XHOME and the three points, all in the .dat.
    assert_eq!(rows.len(), 5, "{csv}");
    for r in &rows[1..] {
        assert_eq!(r.last(), Some(&"cell.dat"), "{r:?}");
    }
    let r = rows.iter().find(|r| r[0] == "XP1").unwrap();
    assert_eq!(r[1], xp1.to_string());
}

/// A URScript target used directly and with a literal offset: exit 5 naming both lines, nothing
/// written; with `--keep-going` the target keeps its text.
#[test]
fn a_target_used_directly_and_with_an_offset_stops_the_run() {
    let dir = Dir::new();
    let (_, _, res) = models(&dir, "ur5.script");
    let text = std::fs::read_to_string(shipped("ur5.script")).unwrap();
    let text = text.replace(
        "  movel(pick, a=1.2, v=0.25)\n",
        "  movel(pick, a=1.2, v=0.25)\n  movel(pose_trans(pick, offset_lit), a=1.2)\n",
    );
    let text = text.replace("offset_lit", "p[0, 0, 0.05, 0, 0, 0]");
    let line = |s: &str| text.lines().position(|l| l.contains(s)).unwrap() + 1;
    let (direct, offset) = (line("movel(pick,"), line("pose_trans(pick"));
    let input = dir.write("two.script", &text);
    let out = dir.join("out.script");
    let o = compensate_program(&res, &input, &out, &[]);
    o.assert_code(5);
    let want = format!(
        "pick (line {}): used both directly (line {direct}) and with an offset (line {offset})",
        line("pick = p[")
    );
    assert!(o.stderr().contains(&want), "{}", o.stderr());
    assert!(o
        .stderr()
        .contains(&format!("motion movel (line {offset})")));
    assert!(!out.exists());
    let o = compensate_program(&res, &input, &out, &["--keep-going"]);
    o.assert_ok();
    let written = std::fs::read_to_string(&out).unwrap();
    let pick = text.lines().nth(line("pick = p[") - 1).unwrap();
    assert!(written.contains(pick), "{written}");
    // The other targets are compensated.
    assert_ne!(written, text);
}

/// RAPID `Offs` of a declared target: the motion is listed naming the target it is built on.
#[test]
fn an_offs_of_a_target_names_it() {
    let dir = Dir::new();
    let (_, _, res) = models(&dir, "irb-like.mod");
    let text = std::fs::read_to_string(shipped("irb-like.mod")).unwrap();
    let name = text
        .lines()
        .find_map(|l| {
            let l = l.trim_start();
            l.strip_prefix("CONST robtarget ")
                .or_else(|| l.strip_prefix("PERS robtarget "))
                .and_then(|r| r.split(|c: char| c == ':' || c.is_whitespace()).next())
        })
        .unwrap()
        .to_owned();
    let decl = text
        .lines()
        .position(|l| l.contains(&format!("robtarget {name}")))
        .unwrap()
        + 1;
    let text = text.replace(
        "ENDPROC",
        &format!("  MoveL Offs({name}, 0, 0, 100), v100, fine, tool0;\n  ENDPROC"),
    );
    let offs = text.lines().position(|l| l.contains("Offs(")).unwrap() + 1;
    let input = dir.write("offs.mod", &text);
    let out = dir.join("out.mod");
    let o = compensate_program(&res, &input, &out, &[]);
    o.assert_code(5);
    let want = format!(
        "motion MoveL (line {offs}): target `Offs({name}, 0, 0, 100)` computed at run time from \
         {name} (line {decl}): its correction is for {name}'s own pose, not for this one"
    );
    assert!(o.stderr().contains(&want), "{}", o.stderr());
    assert!(!out.exists());
}
