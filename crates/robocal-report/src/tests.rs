//! Tests of the rendered documents: well-formed XML, expected labels, counts, escaping, edge
//! cases, atomic output.

use super::*;
use quick_xml::events::Event;
use quick_xml::Reader;

/// Parses `doc` as XML, checking that every tag is closed in order; returns the element names.
/// HTML void elements (`<meta>`, `<br>`) are accepted unclosed.
fn xml_elements(doc: &str) -> Vec<String> {
    let doc = doc.strip_prefix("<!DOCTYPE html>").unwrap_or(doc);
    let mut r = Reader::from_str(doc);
    r.config_mut().check_end_names = true;
    let mut names = Vec::new();
    let mut stack: Vec<String> = Vec::new();
    loop {
        match r.read_event() {
            Ok(Event::Start(e)) => {
                let n = String::from_utf8(e.name().as_ref().to_vec()).unwrap();
                names.push(n.clone());
                if !matches!(n.as_str(), "meta" | "br" | "hr" | "img" | "link") {
                    stack.push(n);
                }
            }
            Ok(Event::Empty(e)) => {
                names.push(String::from_utf8(e.name().as_ref().to_vec()).unwrap())
            }
            Ok(Event::End(e)) => {
                let n = String::from_utf8(e.name().as_ref().to_vec()).unwrap();
                assert_eq!(
                    stack.pop().as_deref(),
                    Some(n.as_str()),
                    "unbalanced </{n}>"
                );
            }
            Ok(Event::Text(t)) => {
                t.unescape().expect("text with a bad entity");
            }
            Ok(Event::Eof) => break,
            Ok(_) => {}
            Err(e) => panic!("not well-formed at {}: {e}", r.buffer_position()),
        }
    }
    assert!(stack.is_empty(), "unclosed elements: {stack:?}");
    names
}

/// The HTML with void `<meta>` tags made self-closing, so that an XML parser can check it.
fn xmlish(html: &str) -> String {
    let mut out = String::with_capacity(html.len());
    let mut rest = html;
    while let Some(i) = rest.find("<meta ") {
        out.push_str(&rest[..i]);
        let end = rest[i..].find('>').unwrap() + i;
        out.push_str(&rest[i..end]);
        out.push_str("/>");
        rest = &rest[end + 1..];
    }
    out.push_str(rest);
    out
}

#[test]
fn example_report_is_well_formed_and_complete() {
    let data = ReportData::synthetic_example(7);
    let r = render(&data).unwrap();
    let names = xml_elements(&xmlish(&r.html));
    // histogram, x/y/z components, reach, joints and workspace map inline
    assert!(
        names.iter().filter(|n| *n == "svg").count() == 5,
        "histogram, components, scatter, joints and map inline"
    );
    for title in [
        "<title>Displacement error before and after calibration</title>",
        "<title>Error components in the base frame</title>",
        "<title>Displacement error across the workspace</title>",
        "<title>Error after calibration against each joint</title>",
        "<title>Error after calibration across the workspace</title>",
    ] {
        assert!(r.html.contains(title), "missing figure {title}");
    }
    xml_elements(&r.histogram_svg);
    for label in [
        "Displacement error ‖Eᵢ‖ (mm)",
        "Number of points",
        "Before calibration",
        "After calibration",
        "Reach from the base z axis (mm)",
        "Before calibration (Table II)",
        "After calibration, predicted (Table IV)",
        "Verification, measured after compensation (Table V)",
        "Samak et al. 2019, Table II",
        "1.619",
        "0.293",
        "Fixed parameters",
        "absorbed by the base frame",
        "Condition number",
        "Levenberg–Marquardt",
        "Run settings",
        "tool_c",
    ] {
        assert!(r.html.contains(label), "missing {label:?}");
    }
    assert!(r.histogram_svg.contains("Number of points"));
    assert!(r.histogram_svg.contains("<title>"));
    // self-contained: no scripts, no external references
    let lower = r.html.to_lowercase();
    for bad in [
        "<script",
        "http://",
        "https://",
        "@import",
        "url(",
        "@font-face",
        "<link",
    ] {
        let ok = if bad == "http://" {
            // the SVG namespace is the only URL allowed
            lower.matches(bad).count() == lower.matches("http://www.w3.org/2000/svg").count()
        } else {
            !lower.contains(bad)
        };
        assert!(ok, "HTML contains {bad}");
    }
}

#[test]
fn histogram_counts_sum_to_n_and_match_the_bars() {
    let data = ReportData::synthetic_example(3);
    let fig = histogram_svg(&data.histogram, HISTOGRAM_TITLE).unwrap();
    let b = fig.binning.as_ref().unwrap();
    for (s, series) in data.histogram.iter().enumerate() {
        let finite = series.values_mm.iter().filter(|v| v.is_finite()).count();
        assert_eq!(b.counts[s].iter().sum::<usize>(), finite);
        assert_eq!(b.n[s], finite);
    }
    // one filled <rect> per non-empty bin in the series' colour, plus its legend swatch
    for s in 0..data.histogram.len() {
        let c = crate::plot::series_color(s);
        let fill = format!("fill=\"#{:02X}{:02X}{:02X}\"", c.0, c.1, c.2);
        let rects = fig
            .svg
            .lines()
            .filter(|l| l.starts_with("<rect") && l.contains(&fill))
            .count();
        let nonempty = b.counts[s].iter().filter(|c| **c > 0).count();
        assert_eq!(rects, nonempty + 1, "series {s}");
    }
}

#[test]
fn text_is_escaped_everywhere() {
    let evil = "<script>alert('x')</script> & \"q\" \u{1}";
    let mut data = ReportData::synthetic_example(1);
    data.title = evil.into();
    data.subtitle = Some(evil.into());
    data.settings.push(Setting::new(evil, evil));
    data.notes.push(Note::warning(evil));
    data.histogram[0].label = evil.into();
    data.point_sets[0].name = evil.into();
    data.error_tables[0].rows[0].label = evil.into();
    data.parameters[0].name = evil.into();
    data.identifiability.as_mut().unwrap().fixed[0].reason = evil.into();
    let r = render(&data).unwrap();
    assert!(!r.html.contains("<script"), "unescaped markup");
    assert!(!r.histogram_svg.contains("<script"));
    assert!(r.html.contains("&lt;script&gt;"));
    assert!(!r.html.contains('\u{1}'));
    xml_elements(&xmlish(&r.html));
    xml_elements(&r.histogram_svg);
}

#[test]
fn edge_cases_render() {
    let p = |r: f64, b: f64, a: f64| PointError {
        reach_mm: r,
        before_mm: b,
        after_mm: a,
    };
    let cases: Vec<(&str, Vec<f64>, Vec<PointError>)> = vec![
        ("empty", vec![], vec![]),
        ("single", vec![1.3], vec![p(2000.0, 1.3, 0.2)]),
        ("all equal", vec![0.5; 20], vec![p(1500.0, 0.5, 0.5); 20]),
        (
            "nan",
            vec![f64::NAN, 1.0, f64::INFINITY, 2.0],
            vec![
                p(f64::NAN, 1.0, 0.1),
                p(2500.0, f64::NAN, 0.2),
                p(2600.0, 1.5, 0.3),
            ],
        ),
        (
            "huge",
            (0..30).map(|i| 0.1 * i as f64).chain([1.0e9]).collect(),
            (0..30)
                .map(|i| p(1000.0 + 50.0 * i as f64, 1.0 + 0.01 * i as f64, 0.1))
                .chain([p(3000.0, 1.0e9, 5.0e3)])
                .collect(),
        ),
    ];
    for (name, values, points) in cases {
        let data = ReportData {
            title: name.into(),
            histogram: vec![
                HistogramSeries::new("Before", values.clone()),
                HistogramSeries::new("After", values.iter().map(|v| v / 10.0).collect()),
            ],
            point_sets: vec![PointSet {
                name: "Calibration".into(),
                points,
                details: Vec::new(),
            }],
            ..ReportData::default()
        };
        let r = render(&data).unwrap_or_else(|e| panic!("{name}: {e}"));
        xml_elements(&xmlish(&r.html));
        xml_elements(&r.histogram_svg);
        let body = &r.html[r.html.find("</style>").unwrap()..];
        for word in body.split(|c: char| !c.is_alphanumeric()) {
            assert!(word != "NaN" && word != "inf", "{name}: {word} shown");
        }
        match name {
            "empty" => assert!(r.histogram_svg.contains("No error values to show")),
            "nan" => assert!(
                r.html.contains("2 missing or non-finite values not shown"),
                "{name}"
            ),
            "huge" => {
                assert!(r.html.contains("gathered in the last bin"), "{name}");
                assert!(r.html.contains("drawn as ▲"), "{name}");
            }
            _ => {}
        }
    }
}

#[test]
fn write_report_creates_dir_and_both_files() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("a/b/report");
    let data = ReportData::synthetic_example(2);
    let files = write_report(&dir, &data).unwrap();
    assert_eq!(files.html, dir.join("report.html"));
    let html = std::fs::read_to_string(&files.html).unwrap();
    let svg = std::fs::read_to_string(&files.histogram_svg).unwrap();
    assert!(html.starts_with("<!DOCTYPE html>"));
    assert!(svg.starts_with("<?xml"));
    assert_eq!(
        std::fs::read_dir(&dir).unwrap().count(),
        2,
        "temporary files left"
    );
    // a file where the directory should be: an error naming it, nothing written
    let f = tmp.path().join("file");
    std::fs::write(&f, "x").unwrap();
    let e = write_report(&f, &data).unwrap_err().to_string();
    assert!(e.contains("not a directory"), "{e}");
}

#[test]
fn report_data_round_trips_through_json() {
    let data = ReportData::synthetic_example(5);
    let j = serde_json::to_string(&data).unwrap();
    let back: ReportData = serde_json::from_str(&j).unwrap();
    // serde_json's float parsing may differ in the last bit: compare what the report shows
    assert_eq!(back.parameters.len(), data.parameters.len());
    for (a, b) in back.parameters.iter().zip(&data.parameters) {
        assert_eq!(
            (&a.name, a.unit, a.fixed, &a.reason),
            (&b.name, b.unit, b.fixed, &b.reason)
        );
        assert!((a.calibrated - b.calibrated).abs() <= 1e-12 * b.calibrated.abs().max(1.0));
    }
    assert_eq!(back.error_tables.len(), data.error_tables.len());
    // verification points have no "before" error: NaN survives as null
    assert!(back.point_sets[2].points[0].before_mm.is_nan());
    xml_elements(&xmlish(&render(&back).unwrap().html));
}

mod runs {
    //! Reports of real runs: the simulated paper's experiment, and a result file with and
    //! without its measurement files.
    use super::{xml_elements, xmlish};
    use crate::*;
    use robocal_core::experiment::{run_experiment, Experiment, ExperimentConfig};
    use robocal_core::identification::{calibrate, split_measurements, CalibrationData};

    fn experiment() -> Experiment {
        run_experiment(ExperimentConfig::paper(1).unwrap(), &()).unwrap()
    }

    fn svg_count(html: &str) -> usize {
        html.matches("<svg").count()
    }

    #[test]
    fn demo_report_is_well_formed_and_shows_every_table() {
        let e = experiment();
        let data = ReportData::from_experiment(&e, "out").unwrap();
        let r = render(&data).unwrap();
        xml_elements(&xmlish(&r.html));
        xml_elements(&r.histogram_svg);
        assert_eq!(
            svg_count(&r.html),
            5,
            "histogram, components, reach plot, joints and map"
        );
        for label in [
            "Before calibration (Table II)",
            "After calibration, predicted (Table IV)",
            "Verification, measured after compensation (Table V)",
            "Paper: Samak et al. 2019, Table II",
            "Paper: Samak et al. 2019, Table V",
            "Fixed parameters",
            "same effect as base_z",
            "Cal. − true",
            "Condition number",
            "Gravity deflection",
            "After calibration, measured – verification points",
        ] {
            assert!(r.html.contains(label), "missing {label:?}");
        }
        // Our figures, as the tables print them.
        for s in [
            e.before(),
            e.predicted(),
            e.verified(),
            e.result.errors.validation.unwrap().after,
        ] {
            assert!(r.html.contains(&format!("{:.3}", s.mean_mm)), "{s:?}");
        }
        // Every parameter once, in joint order, each with its true value.
        assert_eq!(data.parameters.len(), 36);
        assert!(data.parameters.iter().all(|p| p.truth.is_some()));
        let names: Vec<&str> = data.parameters.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(&names[..5], ["alpha1", "d1", "a1", "phi1", "alpha2"]);
        // Point sets: 75 calibration, 73 validation, 75 verification, all with a reach.
        let sizes: Vec<(String, usize)> = data
            .point_sets
            .iter()
            .map(|s| (s.name.clone(), s.points.len()))
            .collect();
        assert_eq!(
            sizes,
            [
                ("Calibration".into(), 75),
                ("Validation".into(), 73),
                ("Verification".into(), 75)
            ]
        );
        for s in &data.point_sets {
            assert!(s
                .points
                .iter()
                .all(|p| p.reach_mm > 500.0 && p.after_mm.is_finite()));
        }
        // The per-point errors are the result's: the same statistics.
        let after: Vec<f64> = data.point_sets[0]
            .points
            .iter()
            .map(|p| p.after_mm)
            .collect();
        let s = robocal_core::ErrorStats::from_norms(&after);
        assert!((s.mean_mm - e.predicted().mean_mm).abs() < 1e-9);
    }

    #[test]
    fn result_alone_gives_tables_and_histogram_but_no_reach_plot() {
        let e = experiment();
        let data = ReportData::from_run(&RunData {
            result: &e.result,
            nominal: &e.config.nominal,
            calibrated: &e.calibrated,
            calibration: None,
            validation: None,
            verification: None,
            with_paper: false,
        })
        .unwrap();
        let r = render(&data).unwrap();
        xml_elements(&xmlish(&r.html));
        assert_eq!(svg_count(&r.html), 1, "histogram only");
        assert_eq!(data.histogram[0].values_mm.len(), 75);
        assert!(r.html.contains("cannot place the points"));
        assert!(!r.html.contains("Paper: Samak"));
        assert!(data.identifiability.as_ref().unwrap().fixed.len() == 10);
        let iterations = serde_json::to_value(&e.result).unwrap()["solver"]["iterations"]
            .as_u64()
            .unwrap() as usize;
        assert!(iterations > 0);
        assert_eq!(data.solver.as_ref().unwrap().iterations, Some(iterations));
    }

    #[test]
    fn validation_statistics_are_computed_when_the_result_has_none() {
        let e = experiment();
        let split = split_measurements(&e.data).unwrap();
        let cal = calibrate(
            &e.config.nominal,
            CalibrationData {
                calibration: &split.calibration,
                plane: Some(&split.plane),
                validation: None,
            },
            // The experiment's settings (the paper's objective).
            &e.config.calibration,
            &(),
        )
        .unwrap();
        let result = cal.to_result();
        assert!(result.errors.validation.is_none());
        let data = ReportData::from_run(&RunData {
            result: &result,
            nominal: &e.config.nominal,
            calibrated: &cal.calibrated,
            calibration: Some(&e.data),
            validation: Some(&e.validation),
            verification: None,
            with_paper: false,
        })
        .unwrap();
        let table2 = &data.error_tables[0];
        assert_eq!(table2.rows.len(), 2);
        // The same calibration as the experiment's: the same validation figures.
        let want = e.result.errors.validation.unwrap();
        assert!((table2.rows[1].stats.mean_mm - want.before.mean_mm).abs() < 1e-9);
        assert!((data.error_tables[1].rows[1].stats.mean_mm - want.after.mean_mm).abs() < 1e-9);
        assert!(data.notes.iter().any(|n| n.text.contains("computed here")));
        assert!(!data
            .notes
            .iter()
            .any(|n| n.text.starts_with("No validation set")));
        // The histogram shows the validation points after calibration beside the calibration
        // points, all of them.
        let v = data
            .histogram
            .iter()
            .find(|h| h.label.contains("validation points"))
            .expect("a validation series");
        assert_eq!(v.values_mm.len(), e.validation.rows.len());
        assert!(v.label.starts_with("After calibration"));
    }

    /// Table V's caption names the poses the verification file holds, not the calibration's.
    #[test]
    fn table_v_caption_is_true_to_the_poses_verified() {
        let e = experiment();
        let s = e.result.errors.calibration.after;
        let tables = paper_tables(e.result.errors.calibration, None, Some(s), false);
        let caption = tables[2].caption.as_deref().unwrap();
        assert!(caption.contains(&format!("The {} poses of the verification file", s.n)));
        assert!(!caption.contains("Calibration poses"), "{caption}");
    }
}

/// Table III of a cell with three reflectors: each reflector's tool is a group of its own,
/// headed by its number, its six offsets in axis order under it (not under `tool_x`); with one
/// reflector the tool stays "Tool (column T)".
#[test]
fn each_reflector_has_its_own_rows_in_the_parameter_table() {
    let row = |name: &str| ParamRow {
        name: name.into(),
        unit: robocal_core::Unit::Mm,
        nominal: 1.0,
        calibrated: 1.5,
        std: Some(0.01),
        fixed: false,
        reason: None,
        truth: None,
    };
    let axes = ["x", "y", "z", "a", "b", "c"];
    // The result's (model) order: every reflector's x, then every reflector's y, ...
    let mut names = vec!["d1".to_owned(), "base_x".to_owned()];
    for a in axes {
        names.push(format!("tool_{a}"));
        for j in [2, 3] {
            names.push(format!("tool{j}_{a}"));
        }
    }
    let mut params: Vec<ParamRow> = names.iter().map(|n| row(n)).collect();
    params.sort_by_key(|p| crate::build::display_order(&p.name));
    let data = ReportData {
        parameters: params,
        ..ReportData::default()
    };
    let html = render(&data).unwrap().html;
    xml_elements(&xmlish(&html));
    let table = &html[html.find("<table class=\"params\">").unwrap()..];
    let table = &table[..table.find("</table>").unwrap()];
    let mut at = 0;
    for (j, head) in [
        (1, "Reflector 1 of 3: its tool (column T)"),
        (2, "Reflector 2 of 3: its tool (offset on the flange)"),
        (3, "Reflector 3 of 3: its tool (offset on the flange)"),
    ] {
        let h = table[at..].find(head).unwrap_or_else(|| panic!("{head}")) + at;
        // The group's six rows follow its heading, before the next group's.
        let next = table[h + 1..]
            .find("class=\"group\"")
            .map_or(table.len(), |n| n + h + 1);
        let group = &table[h..next];
        for a in axes {
            let name = if j == 1 {
                format!("tool_{a}")
            } else {
                format!("tool{j}_{a}")
            };
            assert!(
                group.contains(&format!(">{name}<")),
                "{name} not under {head}"
            );
        }
        assert_eq!(group.matches("<tr>").count(), 6, "{head}: {group}");
        at = h;
    }
    // One reflector: the paper's heading.
    let one = ReportData {
        parameters: ["d1", "tool_x"].iter().map(|n| row(n)).collect(),
        ..ReportData::default()
    };
    let html = render(&one).unwrap().html;
    assert!(html.contains("Tool (column T)") && !html.contains("Reflector 1"));
}
