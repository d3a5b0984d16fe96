//! The "ISO 9283" section: the acceptance test's cube and five poses in the workspace (top and
//! side views), and per test (e.g. before and after calibration) the table per pose: AP with its
//! components, RP, the tracker's MPE beside it (RP below it marked), pass/fail against the spec,
//! and the distance accuracy.

use crate::escape::xml as esc;
pub use crate::iso_results::{IsoPoseRow, IsoTest};
use crate::page::Page;
use crate::svgplot::{range_of, Frame, Svg};
use robocal_core::Result;
use std::fmt::Write;

/// The cube's 12 edges (pairs of corners) for `centre` and `edge`.
fn cube_edges(c: &[f64; 3], edge: f64) -> Vec<([f64; 3], [f64; 3])> {
    let h = 0.5 * edge;
    let corner = |k: usize| {
        let s = |bit: usize| if k & bit != 0 { h } else { -h };
        [c[0] + s(1), c[1] + s(2), c[2] + s(4)]
    };
    let mut out = Vec::new();
    for a in 0..8usize {
        for bit in [1, 2, 4] {
            if a & bit == 0 {
                out.push((corner(a), corner(a | bit)));
            }
        }
    }
    out
}

/// The cube and poses of `t` seen from above (x, y) and from the front (x, z).
fn workspace_svg(t: &IsoTest) -> String {
    const W: u32 = 960;
    const H: u32 = 430;
    let mut svg = Svg::new(
        W,
        H,
        "ISO 9283 test cube and poses",
        &format!(
            "The test cube ({:.0} mm edge) and the poses P1 to P5 on its measuring plane, from \
             above and from the front.",
            t.cube_edge_mm
        ),
    );
    let edges = cube_edges(&t.cube_centre_mm, t.cube_edge_mm);
    let plane = {
        let (c, h) = (t.cube_centre_mm, 0.5 * t.cube_edge_mm);
        [
            (-1.0, -1.0, -1.0),
            (1.0, -1.0, -1.0),
            (1.0, 1.0, 1.0),
            (-1.0, 1.0, 1.0),
        ]
        .map(|(a, b, d)| [c[0] + a * h, c[1] + b * h, c[2] + d * h])
    };
    let pw = W as f64 / 2.0;
    for (i, (title, axes)) in [("Top view", [0usize, 1]), ("Front view", [0, 2])]
        .iter()
        .enumerate()
    {
        let pts = edges.iter().flat_map(|(a, b)| [*a, *b]);
        let xs: Vec<f64> = pts.clone().map(|p| p[axes[0]]).collect();
        let ys: Vec<f64> = pts.map(|p| p[axes[1]]).collect();
        let frame = Frame {
            left: i as f64 * pw + 70.0,
            top: 30.0,
            width: pw - 100.0,
            height: H as f64 - 90.0,
            x: range_of(xs.iter().copied(), false),
            y: range_of(ys.iter().copied(), false),
        }
        .equal_aspect();
        let label = |k: usize| ["x (mm)", "y (mm)", "z (mm)"][k];
        frame.axes(&mut svg, title, label(axes[0]), label(axes[1]));
        let px = |p: &[f64; 3]| (frame.px(p[axes[0]]), frame.py(p[axes[1]]));
        let mut d = String::new();
        for (a, b) in &edges {
            let ((x0, y0), (x1, y1)) = (px(a), px(b));
            let _ = write!(d, "M{x0:.1} {y0:.1}L{x1:.1} {y1:.1}");
        }
        svg.raw(&format!(
            "<path d=\"{d}\" stroke=\"#888\" stroke-width=\"1\" fill=\"none\"/>\n"
        ));
        let mut poly = String::new();
        for p in &plane {
            let (x, y) = px(p);
            let _ = write!(poly, "{x:.1},{y:.1} ");
        }
        svg.raw(&format!(
            "<polygon points=\"{}\" fill=\"#4a7bd0\" fill-opacity=\"0.12\" stroke=\"#4a7bd0\"/>\n",
            poly.trim_end()
        ));
        for p in &t.poses {
            let (x, y) = px(&p.commanded_mm);
            svg.raw(&format!(
                "<circle cx=\"{x:.1}\" cy=\"{y:.1}\" r=\"4\" fill=\"#c0392b\"/>\n"
            ));
            svg.text(x + 6.0, y - 6.0, &format!("P{}", p.pose), 12.0, "start", "");
        }
    }
    svg.finish()
}

fn limit(v: Option<f64>) -> String {
    v.map_or("—".to_owned(), |v| format!("{v} mm"))
}

fn table(h: &mut String, t: &IsoTest) {
    let _ = writeln!(h, "<h3>{}</h3>", esc(&t.label));
    h.push_str(
        "<table class=\"stats\">\n<thead><tr><th>Pose</th><th class=\"num\">n</th>\
         <th class=\"num\">AP (mm)</th><th class=\"num\">AP<sub>x</sub></th>\
         <th class=\"num\">AP<sub>y</sub></th><th class=\"num\">AP<sub>z</sub></th>\
         <th class=\"num\">RP (mm)</th><th class=\"num\">Tracker MPE (mm)</th>\
         <th>Result</th></tr></thead>\n<tbody>\n",
    );
    for p in &t.poses {
        let result = match p.pass {
            Some(true) => "pass",
            Some(false) => "FAIL",
            None => "",
        };
        let mark = if p.rp_below_tracker { " *" } else { "" };
        let _ = writeln!(
            h,
            "<tr><td>P{}</td><td class=\"num\">{}</td><td class=\"num\">{:.4}</td>\
             <td class=\"num\">{:.4}</td><td class=\"num\">{:.4}</td><td class=\"num\">{:.4}</td>\
             <td class=\"num\">{:.4}{mark}</td><td class=\"num\">{:.4}</td><td>{result}</td></tr>",
            p.pose,
            p.n,
            p.ap_mm,
            p.ap_xyz_mm[0],
            p.ap_xyz_mm[1],
            p.ap_xyz_mm[2],
            p.rp_mm,
            p.tracker_mpe_mm
        );
    }
    h.push_str("</tbody>\n</table>\n");
    let _ = writeln!(
        h,
        "<p>Distance P{}–P{}: AD {:.4} mm, RD {:.4} mm. Tracker MPE {}{}. Spec: AP ≤ {}, RP ≤ {}{}.</p>",
        t.distance_poses[0],
        t.distance_poses[1],
        t.ad_mm,
        t.rd_mm,
        esc(&t.tracker),
        if t.poses.iter().any(|p| p.rp_below_tracker) {
            "; * RP below the tracker's MPE: not resolved by the instrument"
        } else {
            ""
        },
        limit(t.spec_ap_mm),
        limit(t.spec_rp_mm),
        match t.pass {
            Some(true) => ": PASS",
            Some(false) => ": FAIL",
            None => "",
        }
    );
}

/// Writes the section when the report has ISO 9283 tests.
pub(crate) fn section(page: &Page, h: &mut String) -> Result<bool> {
    let tests = &page.data.iso9283;
    if tests.is_empty() {
        return Ok(false);
    }
    h.push_str(
        "<section id=\"iso9283\">\n<h2>ISO 9283 pose accuracy and repeatability</h2>\n\
         <p class=\"lead\">Per pose: AP = |G − commanded| (G the barycentre of the attained \
         positions) with its components, RP = mean(l) + 3 s(l) (l the distances to G, s the \
         sample standard deviation).</p>\n",
    );
    crate::markup::figure(
        h,
        &workspace_svg(&tests[0]),
        &format!(
            "The test cube ({:.1} mm edge, centre {:.1}, {:.1}, {:.1} mm), its measuring plane \
             (shaded) and the commanded poses P1 to P5, in the base frame.",
            tests[0].cube_edge_mm,
            tests[0].cube_centre_mm[0],
            tests[0].cube_centre_mm[1],
            tests[0].cube_centre_mm[2]
        ),
    );
    for t in tests {
        table(h, t);
    }
    h.push_str("</section>\n");
    Ok(true)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Rotation3, Translation3, Vector3};
    use robocal_core::frame::Frame;
    use robocal_core::iso9283::{evaluate, Cube, PoseSamples, Sample, Spec, TrackerMpe};

    /// A test on a known cube whose attained points sit 0.1 mm above the commanded ones and
    /// 1, 2, 3 um aside in cycles 1, 2, 3.
    fn test_of(cube: &Cube) -> IsoTest {
        let poses: Vec<PoseSamples> = cube
            .test_points()
            .iter()
            .enumerate()
            .map(|(k, p)| PoseSamples {
                pose: k + 1,
                commanded: Frame::from_parts(Translation3::from(*p), Rotation3::identity()),
                samples: (1..=3)
                    .map(|c| Sample {
                        cycle: c,
                        position: p + Vector3::new(0.0, 0.001 * c as f64, 0.1),
                        rotation: None,
                        time_s: None,
                    })
                    .collect(),
            })
            .collect();
        let spec = Spec::parse("ap=0.05").unwrap();
        let ev = evaluate(
            &poses,
            &TrackerMpe::default(),
            &Vector3::zeros(),
            Some(&spec),
        )
        .unwrap();
        IsoTest::from_evaluation("Before <calibration>", &ev)
    }

    #[test]
    fn cube_recovered_and_section_rendered() {
        let cube = Cube {
            centre: Vector3::new(1500.0, -200.0, 900.0),
            edge_mm: 640.0,
        };
        let t = test_of(&cube);
        assert!((t.cube_edge_mm - 640.0).abs() < 1e-9, "{}", t.cube_edge_mm);
        assert_eq!(t.cube_centre_mm, [1500.0, -200.0, 900.0]);
        // G is 0.1 mm above and 0.002 mm (the mean of 1, 2, 3 um) aside.
        let ap = (0.01f64 + 4e-6).sqrt();
        assert!(t.poses.iter().all(|p| (p.ap_mm - ap).abs() < 1e-9));
        assert_eq!(t.pass, Some(false));
        let data = crate::ReportData {
            iso9283: vec![t],
            ..crate::ReportData::default()
        };
        let html = crate::render(&data).unwrap().html;
        assert!(html.contains("<section id=\"iso9283\">"));
        assert!(html.contains("Before &lt;calibration&gt;"), "escaped label");
        assert!(html.contains(">P5</text>") && html.contains("FAIL"));
        assert!(html.contains("0.1000"));
        // Without tests, no section.
        let html = crate::render(&crate::ReportData::default()).unwrap().html;
        assert!(!html.contains("id=\"iso9283\""));
    }
}
