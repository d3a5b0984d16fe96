//! `robocal compensate --program`: KUKA KRL, ABB RAPID and URScript programs with joint and
//! Cartesian targets, compensated end to end. Every written target is checked here by forward
//! kinematics on the calibrated model (as the controller reads it back), and the rest of each
//! file is byte-identical; the exit codes, `--keep-going` and `--changes`.

use crate::util::library::*;
use crate::util::*;
use rand::SeedableRng;
use robocal_core::compensation::PoseNewton;
use robocal_core::frame::TrackerFrame;
use robocal_core::programs::seed::{branch_joints, BranchJoints};
use robocal_core::programs::{pose_distance, Format, ProgramTarget, TargetKind};
use robocal_core::simulation::GeometricErrors;
use robocal_core::{load_robot_file, preset, Robot};
use std::ops::Range;
use std::path::{Path, PathBuf};

/// The nominal robot of a shipped program, its calibrated model (KUKA: Table III; the others:
/// random geometric errors of 0.5 mm and 0.05 deg) and a result file for them in `dir`.
pub(crate) fn models(dir: &Dir, program: &str) -> (Robot, Robot, PathBuf) {
    let (nom, cal) = match program {
        "kr480.src" => (preset(KUKA).unwrap(), preset(TRUTH).unwrap()),
        _ => {
            let file = if program.ends_with(".mod") {
                "examples/programs/irb-like.toml"
            } else {
                "examples/ur5.toml"
            };
            let nom = load_robot_file(&root().join(file)).unwrap();
            let e = GeometricErrors {
                length_sigma_mm: 0.5,
                angle_sigma_deg: 0.05,
                tilt_parallel_axes: false,
            };
            let cal = e
                .apply(&nom, &mut rand_chacha::ChaCha8Rng::seed_from_u64(5))
                .unwrap();
            (nom, cal)
        }
    };
    let res = dir.join("result.json");
    result_for(&nom, &cal, &TrackerFrame::identity())
        .write(&res)
        .unwrap();
    (nom, cal, res)
}

pub(crate) fn shipped(name: &str) -> PathBuf {
    root().join("examples/programs").join(name)
}

/// The text outside the targets' replaced spans (numbers and KRL turns), in order.
fn outside(text: &str, targets: &[ProgramTarget]) -> Vec<String> {
    let mut spans: Vec<Range<usize>> = targets
        .iter()
        .flat_map(|t| t.fields.iter().map(|f| f.span.clone()))
        .chain(targets.iter().filter_map(|t| t.turn_span.clone()))
        .collect();
    spans.sort_by_key(|r| r.start);
    let mut out = Vec::new();
    let mut at = 0;
    for r in spans {
        out.push(text[at..r.start].to_owned());
        at = r.end;
    }
    out.push(text[at..].to_owned());
    out
}

/// Compensates a shipped program through the CLI and checks every target of the output by
/// forward kinematics on the calibrated model, and the bytes outside the replaced spans.
fn program_round_trip(name: &str) {
    let dir = Dir::new();
    let (nom, cal, res) = models(&dir, name);
    let input = shipped(name);
    let out = dir.join(format!("out-{name}"));
    let changes = dir.join("changes.csv");
    let o = robocal(&[
        "compensate",
        "--params",
        p(&res),
        "--program",
        p(&input),
        "--out",
        p(&out),
        "--changes",
        p(&changes),
    ]);
    o.assert_ok();
    let format = Format::from_path(&input).unwrap();
    let text_in = std::fs::read_to_string(&input).unwrap();
    let text_out = std::fs::read_to_string(&out).unwrap();
    let tin = format.targets(&input, &text_in).unwrap();
    let tout = format.targets(&out, &text_out).unwrap();
    assert_eq!(tin.len(), 6, "{name}");
    assert_eq!(tout.len(), tin.len());
    assert_eq!(outside(&text_in, &tin), outside(&text_out, &tout), "{name}");
    let js = nom.joint_space();
    let mut previous: Option<Vec<f64>> = None;
    for (a, b) in tin.iter().zip(&tout) {
        let old: Vec<f64> = a.fields.iter().map(|f| f.value).collect();
        let new: Vec<f64> = b.fields.iter().map(|f| f.value).collect();
        assert_ne!(old, new, "{name}: {} line {} unchanged", a.name, a.line);
        // As the controller stores them.
        let new: Vec<f64> = new
            .iter()
            .enumerate()
            .map(|(k, v)| format.precision(a.kind, k).stored(*v))
            .collect();
        let (desired, reached) = match a.kind {
            TargetKind::Joints => (
                nom.tool_pose(&js.joints_from_axes(&format.axes_of(&old))),
                js.joints_from_axes(&format.axes_of(&new)),
            ),
            TargetKind::Pose => {
                // The controller's nominal inverse kinematics of the written pose, on the branch
                // its configuration data (or the previous joints) give, through the work object
                // its motion names: the RAPID example's `p2` is given in `table` (user frame
                // (800, -300, 200) mm turned 0.5 rad about z, object frame 50 mm above it).
                let wobj = if name.ends_with(".mod") && a.name == "p2" {
                    robocal_core::pose(&[800.0, -300.0, 200.0, 0.5, 0.0, 0.0])
                        * robocal_core::pose(&[0.0, 0.0, 50.0, 0.0, 0.0, 0.0])
                } else {
                    robocal_core::Frame::identity()
                };
                let branch = b.branch(previous.as_deref());
                let found = branch_joints(
                    &nom,
                    &PoseNewton::default(),
                    &(wobj * format.pose_of(&new)),
                    &branch,
                );
                let BranchJoints::Found(q) = found else {
                    panic!("{name}: {} line {}: {found:?}", b.name, b.line)
                };
                (wobj * format.pose_of(&old), q)
            }
        };
        // RAPID's targets are for the tool `gun`, the robot description's tool, taken as given.
        let actual = if name.ends_with(".mod") && a.kind == TargetKind::Pose {
            cal.tool_pose(&reached) * cal.tool_frame().inverse() * nom.tool_frame()
        } else {
            cal.tool_pose(&reached)
        };
        let (dp, dw) = pose_distance(&actual, &desired);
        // URScript keeps 64-bit numbers: 1e-4 mm, 1e-5 deg; KRL and RAPID 32-bit ones (see the
        // cell test).
        let (lim_mm, lim_deg) = if name.ends_with(".script") {
            (1e-4, 1e-5)
        } else {
            (3e-4, 3e-5)
        };
        assert!(
            dp < lim_mm && dw < lim_deg,
            "{name}: {} line {}: {dp} mm {dw} deg",
            a.name,
            a.line
        );
        // Listed with its line.
        assert!(
            o.stdout()
                .contains(&format!("{:<16} {:>6}", a.name, a.line)),
            "{}",
            o.stdout()
        );
        previous = Some(reached);
    }
    assert!(
        o.stdout().contains("6 compensated, 0 left unchanged"),
        "{}",
        o.stdout()
    );
    let csv = std::fs::read_to_string(&changes).unwrap();
    assert_eq!(csv.lines().count(), 7, "{csv}");
}

#[test]
fn a_krl_program_is_compensated_and_checked_by_fk() {
    program_round_trip("kr480.src");
}

#[test]
fn a_rapid_program_is_compensated_and_checked_by_fk() {
    program_round_trip("irb-like.mod");
}

#[test]
fn a_urscript_program_is_compensated_and_checked_by_fk() {
    program_round_trip("ur5.script");
}

/// The KRL example with a target out of reach on line 14.
fn with_unreachable(dir: &Dir) -> PathBuf {
    let mut text = std::fs::read_to_string(shipped("kr480.src")).unwrap();
    let end = text.rfind("END").unwrap();
    text.insert_str(
        end,
        "LIN {X 9000, Y 0, Z 1000, A 0, B 90, C 0} ; too far\r\n",
    );
    dir.write("far.src", text)
}

#[test]
fn a_target_that_cannot_be_compensated_stops_the_run_unless_keep_going() {
    let dir = Dir::new();
    let (_, _, res) = models(&dir, "kr480.src");
    let input = with_unreachable(&dir);
    let line = std::fs::read_to_string(&input)
        .unwrap()
        .lines()
        .position(|l| l.contains("9000"))
        .unwrap()
        + 1;
    let out = dir.join("out.src");
    let changes = dir.join("changes.csv");
    let args = |extra: &[&str]| {
        let mut v = vec![
            "compensate",
            "--params",
            p(&res),
            "--program",
            p(&input),
            "--out",
            p(&out),
            "--changes",
            p(&changes),
        ];
        v.extend_from_slice(extra);
        v.iter().map(|s| s.to_string()).collect::<Vec<String>>()
    };
    let o = robocal(&args(&[]));
    o.assert_code(5);
    assert!(
        o.stderr()
            .contains(&format!("LIN (line {line}): unreachable")),
        "{}",
        o.stderr()
    );
    assert!(!out.exists() && !changes.exists(), "nothing written");

    let o = robocal(&args(&["--keep-going"]));
    o.assert_ok();
    assert!(o.stdout().contains("left unchanged"), "{}", o.stdout());
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.contains("LIN {X 9000, Y 0, Z 1000, A 0, B 90, C 0} ; too far"));
    let csv = std::fs::read_to_string(&changes).unwrap();
    let rows: Vec<Vec<&str>> = csv.lines().map(|l| l.split(',').collect()).collect();
    assert_eq!(
        rows[0],
        [
            "name",
            "line",
            "kind",
            "status",
            "applied",
            "correction_mm",
            "correction_deg",
            "verified_mm",
            "verified_deg",
            "old",
            "new",
            "reason",
            "file"
        ]
    );
    // Six targets, the one out of reach, and its motion.
    assert_eq!(rows.len(), 9, "{csv}");
    assert_eq!(
        rows[8][..5],
        ["LIN", &line.to_string(), "motion", "unchanged", "false"]
    );
    let far = &rows[7];
    assert_eq!(
        far[..5],
        ["LIN", &line.to_string(), "pose", "unreachable", "false"]
    );
    assert_eq!(far[5], "");
    assert_eq!(far[9], "9000 0 1000 0 90 0");
    assert_eq!(far[9], far[10]);
    for r in &rows[1..7] {
        assert_eq!(r.len(), 13, "{r:?}");
        // One file: the program.
        assert_eq!(r[12], "far.src", "{r:?}");
        assert_eq!(r[4], "true", "{r:?}");
        let corr: f64 = r[5].parse().unwrap();
        let verified: f64 = r[7].parse().unwrap();
        assert!(corr > 0.1 && verified < 0.01, "{r:?}");
        assert_eq!(r[9].split(' ').count(), 6);
        assert_ne!(r[9], r[10]);
    }
    // The joint targets: the new values as written in the program.
    let t = Format::Krl.targets(&out, &text).unwrap();
    let written: Vec<String> = t[0].fields.iter().map(|f| f.value.to_string()).collect();
    assert_eq!(rows[1][10], written.join(" "));
}

#[test]
fn bad_program_arguments_are_refused() {
    let dir = Dir::new();
    let (_, _, res) = models(&dir, "kr480.src");
    let input = dir.write("prog.src", std::fs::read(shipped("kr480.src")).unwrap());
    // The output over the input.
    let o = robocal(&[
        "compensate",
        "--params",
        p(&res),
        "--program",
        p(&input),
        "--out",
        p(&input),
    ]);
    o.assert_code(2);
    assert!(o.stderr().contains("--out"), "{}", o.stderr());
    // An unknown extension.
    let txt = dir.write("prog.txt", "PTP {A1 0}\n");
    let o = robocal(&[
        "compensate",
        "--params",
        p(&res),
        "--program",
        p(&txt),
        "--out",
        p(&dir.join("o.txt")),
    ]);
    o.assert_code(2);
    assert!(o.stderr().contains("--program"), "{}", o.stderr());
    assert!(!dir.join("o.txt").exists());
    // Exclusive with the other inputs.
    let o = robocal(&[
        "compensate",
        "--params",
        p(&res),
        "--program",
        p(&input),
        "--joints",
        p(&input),
        "--out",
        p(&dir.join("o.src")),
    ]);
    o.assert_code(2);
    // `--changes` and `--keep-going` need a program.
    let o = robocal(&[
        "compensate",
        "--params",
        p(&res),
        "--joints",
        p(&input),
        "--out",
        p(&dir.join("o.csv")),
        "--keep-going",
    ]);
    o.assert_code(2);
    // A malformed target: exit 3 naming the file and line.
    let bad = dir.write(
        "bad.src",
        "DEF m()\r\nPTP {A1 0, A2 -90, A3 x, A4 0, A5 30, A6 0}\r\nEND\r\n",
    );
    let o = robocal(&[
        "compensate",
        "--params",
        p(&res),
        "--program",
        p(&bad),
        "--out",
        p(&dir.join("o.src")),
    ]);
    o.assert_code(3);
    assert!(o.stderr().contains("bad.src:2"), "{}", o.stderr());
    assert!(!dir.join("o.src").exists());
}

#[test]
fn position_only_applies_to_programs() {
    let dir = Dir::new();
    let (_, _, res) = models(&dir, "ur5.script");
    let out = dir.join("o.script");
    let o = robocal(&[
        "compensate",
        "--params",
        p(&res),
        "--program",
        p(&shipped("ur5.script")),
        "--out",
        p(&out),
        "--position-only",
    ]);
    o.assert_ok();
    assert!(o.stdout().contains("position only"), "{}", o.stdout());
    assert!(Path::new(&out).exists());
}

/// Runs `compensate --program` on `input` (result `res`) with `extra` flags.
pub(crate) fn compensate_program(res: &Path, input: &Path, out: &Path, extra: &[&str]) -> Outcome {
    let mut v = vec![
        "compensate".to_owned(),
        "--params".to_owned(),
        p(res).to_owned(),
        "--program".to_owned(),
        p(input).to_owned(),
        "--out".to_owned(),
        p(out).to_owned(),
    ];
    v.extend(extra.iter().map(|s| s.to_string()));
    robocal(&v)
}

/// The malformed programs of issue 26: exit 3 naming the file, line and field, nothing written.
#[test]
fn malformed_programs_are_exit_3_naming_line_and_field() {
    let dir = Dir::new();
    let (_, _, res) = models(&dir, "kr480.src");
    let cases = [
        ("a.src", "DEF a()\nPTP {A1 0, A2 -9e99, A3 90, A4 0, A5 30, A6 0}\nEND\n", "a.src:2", "`A2`"),
        ("b.src", "DEF b()\nLIN {X 9e15, Y 0, Z 1000, A 0, B 90, C 0}\nEND\n", "b.src:2", "`X`"),
        ("c.src", "DEF c()\nLIN {X 2000, Y 0, Z 1000, A 0, B 90, C 0, T -5}\nEND\n", "c.src:2", "turn `T`"),
        ("d.src", "DEF d()\nPTP {A1 0, A2 -90, A3 90, A3 91, A4 0, A5 30, A6 0}\nEND\n", "d.src:2", "twice"),
        ("e.src", "DEF e()\nPTP {A1 0, A2 -90, A3 90, A4 0, A5 30, A6 0, A7 5}\nEND\n", "e.src:2", "`A7`"),
        ("f.src", "DEF f()\nPTP {A1 0, A2 -90, A3 90, A4 0, A5 30\nEND\n", "f.src:2", "not closed"),
        ("g.mod", "MODULE g\nCONST robtarget p := [[9E+09,0,1000],[1,0,0,0],[0,0,0,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];\nENDMODULE\n", "g.mod:2", "`x`"),
        ("h.mod", "MODULE h\nCONST robtarget p := [[1000,0,1000],[1,0,0,0],[0,0,0,99],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];\nENDMODULE\n", "h.mod:2", "`cfx`"),
        ("i.src", "MODULE i\nCONST robtarget p := [[1000,0,1000],[1,0,0,0],[0,0,0,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];\nENDMODULE\n", "i.src", "ABB RAPID"),
    ];
    for (name, text, at, field) in cases {
        let input = dir.write(name, text);
        let out = dir.join(format!("out-{name}"));
        let o = compensate_program(&res, &input, &out, &[]);
        o.assert_code(3);
        assert!(
            o.stderr().contains(at) && o.stderr().contains(field),
            "{name}: {}",
            o.stderr()
        );
        assert!(!out.exists(), "{name}");
    }
}

/// Motions the readers cannot compensate are counted and named: exit 5, nothing written;
/// with --keep-going listed and written with --changes.
#[test]
fn every_motion_is_accounted_for() {
    let dir = Dir::new();
    let (_, _, res) = models(&dir, "ur5.script");
    let text = "def m():\n  movej(q=[0.1, -1.2, 1.4, -1.7, -1.5, 0.2], a=1.4, v=1.05)\n  \
                movej(get_inverse_kin(p[0.4, -0.1, 0.3, 0, 3.1, 0]))\n  \
                movel(pose_trans(get_actual_tcp_pose(), p[0, 0, 0.05, 0, 0, 0]))\n  \
                speedj([0.1, 0, 0, 0, 0, 0], 0.5)\n  set_tcp(get_tcp_offset())\n  \
                movel(p[0.4, -0.1, 0.35, 0, 3.1, 0])\nend\n";
    let input = dir.write("m.script", text);
    let out = dir.join("o.script");
    let changes = dir.join("c.csv");
    let o = compensate_program(&res, &input, &out, &["--changes", p(&changes)]);
    o.assert_code(5);
    for want in [
        "(line 4): target `pose_trans",
        "(line 5): a speed command",
        "(line 7): target",
        "tool unknown",
    ] {
        assert!(o.stderr().contains(want), "{want}: {}", o.stderr());
    }
    assert!(!out.exists() && !changes.exists());
    let o = compensate_program(
        &res,
        &input,
        &out,
        &["--changes", p(&changes), "--keep-going"],
    );
    o.assert_ok();
    assert!(
        o.stdout()
            .contains("motions: 5 in the program, 2 compensated, 3 left unchanged"),
        "{}",
        o.stdout()
    );
    let written = std::fs::read_to_string(&out).unwrap();
    // The named argument and the pose given to get_inverse_kin are compensated.
    assert!(!written.contains("q=[0.1, -1.2") && !written.contains("p[0.4, -0.1, 0.3, 0, 3.1, 0]"));
    assert!(
        written.contains("movel(p[0.4, -0.1, 0.35, 0, 3.1, 0])"),
        "{written}"
    );
    let csv = std::fs::read_to_string(&changes).unwrap();
    assert_eq!(
        csv.lines()
            .filter(|l| l.contains(",motion,unchanged,"))
            .count(),
        3,
        "{csv}"
    );
}

/// A real cell's shape: a .src whose inline forms (folds) name points of its .dat, tools and
/// bases from the controller's $config.dat, 120 points.
pub(crate) fn cell(dir: &Dir, nom: &Robot, n: usize) -> (PathBuf, PathBuf) {
    cell_named(dir, nom, n, "cell", "$config.dat")
}

/// [`cell`] with the program's name and the config file's name.
fn cell_named(
    dir: &Dir,
    nom: &Robot,
    n: usize,
    name: &str,
    config_name: &str,
) -> (PathBuf, PathBuf) {
    use robocal_core::programs::krl;
    use robocal_core::programs::seed::krl_status;
    let tool = robocal_core::frame::pose(&[10.0, -5.0, 300.0, 0.0, 0.3, 0.0]);
    let base = robocal_core::frame::pose(&[1200.0, -400.0, 50.0, 0.5, 0.0, 0.0]);
    let config = "DEFDAT $CONFIG\nDECL FRAME TOOL_DATA[16]\nTOOL_DATA[1]={X 10.0,Y -5.0,Z 300.0,A 0.0,B 17.188733853924695,C 0.0}\n\
                  BASE_DATA[1]={X 1200.0,Y -400.0,Z 50.0,A 28.64788975654116,B 0.0,C 0.0}\nENDDAT\n";
    let js = nom.joint_space();
    let mut src = format!("&ACCESS RVP\r\n&REL 1\r\nDEF {name}( )\r\n;FOLD INI;%{{PE}}\r\nBAS(#INITMOV,0)\r\n;ENDFOLD (INI)\r\n\r\n");
    let mut dat = format!("&ACCESS RVP\r\nDEFDAT {name}\r\nDECL E6AXIS XHOME={{A1 0.0,A2 -90.0,A3 90.0,A4 0.0,A5 45.0,A6 0.0,E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}}\r\n\
        DECL FDAT FHOME={{TOOL_NO 0,BASE_NO 0,IPO_FRAME #BASE,POINT2[] \" \"}}\r\nDECL PDAT PPDAT1={{VEL 100.0,ACC 100.0,APO_DIST 100.0,APO_MODE #CDIS}}\r\n");
    src += ";FOLD PTP HOME Vel=100 % DEFAULT;%{PE}\r\nFDAT_ACT=FHOME\r\nBAS(#PTP_PARAMS,100)\r\nPTP XHOME\r\n;ENDFOLD\r\n";
    for k in 0..n {
        let a = [
            -40.0 + 80.0 * (k as f64 * 0.37).sin().abs(),
            -80.0 + 20.0 * (k as f64 * 0.11).cos(),
            80.0 + 15.0 * (k as f64 * 0.23).sin(),
            20.0 * (k as f64 * 0.5).cos() + 5.0,
            50.0 + 10.0 * (k as f64 * 0.3).sin(),
            30.0 * (k as f64 * 0.7).sin() + 3.0,
        ];
        let q = js.joints_from_axes(&a);
        let flange = nom.tool_pose(&q) * nom.tool_frame().inverse();
        let v = krl::pose_values(&(base.inverse() * flange * tool));
        let (cmd, kw) = if k % 3 == 0 {
            ("PTP", "PTP")
        } else {
            ("LIN", "LIN")
        };
        src += &format!(
            ";FOLD {cmd} P{k} CONT Vel=2 m/s CPDAT1 Tool[1]:gun Base[1]:table;%{{PE}}%R 8.3.48,%MKUKATPBASIS,%CMOVE\r\n\
             $BWDSTART=FALSE\r\nPDAT_ACT=PPDAT1\r\nFDAT_ACT=FP{k}\r\nBAS(#CP_PARAMS,2)\r\n{kw} XP{k} C_DIS\r\n;ENDFOLD\r\n"
        );
        dat += &format!(
            "DECL E6POS XP{k}={{X {:.3},Y {:.3},Z {:.3},A {:.4},B {:.4},C {:.4},S {},T {},E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}}\r\n\
             DECL FDAT FP{k}={{TOOL_NO 1,BASE_NO 1,IPO_FRAME #BASE,POINT2[] \" \",TQ_STATE FALSE}}\r\n",
            v[0], v[1], v[2], v[3], v[4], v[5],
            krl_status(nom, &q).unwrap(),
            robocal_core::programs::turn_of(nom, &q)
        );
    }
    src += "PTP XHOME\r\nEND\r\n";
    dat += "ENDDAT\r\n";
    dir.write(format!("{name}.dat"), dat);
    (
        dir.write(format!("{name}.src"), src),
        dir.write(config_name, config),
    )
}

#[test]
fn a_cell_program_with_its_dat_and_config_is_compensated_completely() {
    let dir = Dir::new();
    let (nom, cal, res) = models(&dir, "kr480.src");
    let (src, config) = cell(&dir, &nom, 120);
    let out = dir.join("new/cell.src");
    std::fs::create_dir_all(dir.join("new")).unwrap();
    // Without the $config.dat the tool and base are unknown: exit 5, nothing written.
    let o = compensate_program(&res, &src, &out, &[]);
    o.assert_code(5);
    assert!(
        o.stderr()
            .contains("TOOL_DATA[1] without the controller's $config.dat"),
        "{}",
        o.stderr()
    );
    let o = compensate_program(&res, &src, &out, &["--config", p(&config)]);
    o.assert_ok();
    assert!(
        o.stdout()
            .contains("motions: 122 in the program, 122 compensated, 0 left unchanged"),
        "{}",
        o.stdout()
    );
    // The .src is kept; the points are compensated in the .dat beside the output.
    assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&src).unwrap());
    let dat_in = std::fs::read_to_string(dir.join("cell.dat")).unwrap();
    let dat_out = std::fs::read_to_string(dir.join("new/cell.dat")).unwrap();
    let tin = Format::Krl.targets(Path::new("cell.dat"), &dat_in).unwrap();
    let tout = Format::Krl
        .targets(Path::new("cell.dat"), &dat_out)
        .unwrap();
    assert_eq!(tin.len(), 121);
    assert_eq!(outside(&dat_in, &tin), outside(&dat_out, &tout));
    // FK of every written point after the controller's 32-bit rounding, through the frames.
    let tool = robocal_core::frame::pose(&[10.0, -5.0, 300.0, 0.0, 0.3, 0.0]);
    let base = robocal_core::frame::pose(&[1200.0, -400.0, 50.0, 0.5, 0.0, 0.0]);
    let (mut worst_mm, mut worst_deg) = (0.0f64, 0.0f64);
    for (a, b) in tin.iter().zip(&tout).skip(1) {
        let old: Vec<f64> = a.fields.iter().map(|f| f.value).collect();
        let new: Vec<f64> = b.fields.iter().map(|f| f64::from(f.value as f32)).collect();
        assert_ne!(old, new);
        let x = base * Format::Krl.pose_of(&new) * tool.inverse() * nom.tool_frame();
        let found = branch_joints(&nom, &PoseNewton::default(), &x, &b.branch(None));
        let BranchJoints::Found(q) = found else {
            panic!("{}: {found:?}", b.name)
        };
        let real = cal.tool_pose(&q) * cal.tool_frame().inverse() * tool;
        let (dp, dw) = pose_distance(&real, &(base * Format::Krl.pose_of(&old)));
        worst_mm = worst_mm.max(dp);
        worst_deg = worst_deg.max(dw);
    }
    eprintln!(
        "cell: 120 points, worst after 32-bit rounding {worst_mm:.2e} mm, {worst_deg:.2e} deg"
    );
    assert!(
        worst_mm < 1e-3 && worst_deg < 1e-4,
        "{worst_mm} {worst_deg}"
    );
}

/// A cell program of 5000 targets is compensated completely. Its time is a benchmark's
/// (`benches/programs.rs`), not this test's: the test prints it only.
#[test]
fn five_thousand_targets_are_compensated() {
    let dir = Dir::new();
    let (nom, _, res) = models(&dir, "kr480.src");
    let (src, config) = cell(&dir, &nom, 5000);
    let out = dir.join("o.src");
    let t = std::time::Instant::now();
    let o = compensate_program(&res, &src, &out, &["--config", p(&config)]);
    let s = t.elapsed().as_secs_f64();
    o.assert_ok();
    // Exit 0 means every motion was compensated; the summary says so.
    assert!(o.stdout().contains(", 0 left unchanged"), "{}", o.stdout());
    eprintln!("5000 targets: {s:.3} s (whole command)");
}

/// The shipped KRL cell example (`examples/programs/kr480_cell.src`, its `.dat` and
/// `kr480-config.dat`) is [`cell_named`] with 8 points; `ROBOCAL_WRITE_EXAMPLE=1` rewrites it.
#[test]
fn the_shipped_cell_example_is_the_generator() {
    let dir = Dir::new();
    let nom = preset(KUKA).unwrap();
    cell_named(&dir, &nom, 8, "kr480_cell", "kr480-config.dat");
    for f in ["kr480_cell.src", "kr480_cell.dat", "kr480-config.dat"] {
        let made = std::fs::read_to_string(dir.join(f)).unwrap();
        if std::env::var_os("ROBOCAL_WRITE_EXAMPLE").is_some() {
            std::fs::write(shipped(f), &made).unwrap();
            continue;
        }
        let have = std::fs::read_to_string(shipped(f)).unwrap();
        assert_eq!(have, made, "{f}: regenerate with ROBOCAL_WRITE_EXAMPLE=1");
    }
}
