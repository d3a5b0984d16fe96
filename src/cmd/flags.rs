//! The one table from the library's setting names to this program's flags.
//!
//! `robocal-core` never names a command-line flag: its errors name the setting (the field of its
//! settings struct, e.g. `noise_mm` or `gravity.payload_kg`), as the `field` of an
//! [`robocal_core::Error::Invalid`] or in backticks inside a message (`` `outliers.max_mm` ``).
//! When the program reports an error ([`crate::exit::message`]) it shows the flag the user typed
//! instead, through [`cli_text`].

/// Library setting -> the flag that sets it.
const FLAGS: &[(&str, &str)] = &[
    // simulation::SimulationConfig
    ("noise_mm", "--noise-mm"),
    ("noise_per_m", "--noise-per-m"),
    ("tracker_frame", "--tracker"),
    ("floor_z_mm", "--floor-mm"),
    ("footprint_radius_mm", "--footprint-mm"),
    ("plane_z_mm", "--plane-z-mm"),
    ("plane_points", "--no-plane"),
    ("poses", "--poses"),
    ("validation_poses", "--validation"),
    ("truth.tilt_parallel_axes", "--tilt-parallel-axes"),
    ("backlash.half_play_deg", "--backlash-deg"),
    ("thermal.rise_c", "--thermal-rise-c"),
    ("thermal.start_s", "--thermal-start-s"),
    ("thermal.seconds_per_pose", "--seconds-per-pose"),
    ("station", "--station"),
    ("truth", "--truth"),
    ("truth.length_sigma_mm", "--length-error-mm"),
    ("truth.angle_sigma_deg", "--angle-error-deg"),
    ("gravity.compliance_rad_per_nm", "--compliance"),
    ("gravity.link_masses_kg", "--link-masses-kg"),
    ("gravity.payload_kg", "--payload-kg"),
    ("outliers.fraction", "--outlier-fraction"),
    ("outliers.min_mm", "--outlier-min-mm"),
    ("outliers.max_mm", "--outlier-max-mm"),
    ("repeatability.std_deg", "--repeatability-deg"),
    // iso9283::PlanSettings, Spec, TrackerMpe
    ("cycles", "--cycles"),
    ("edge_mm", "--cube-mm"),
    ("centre_mm", "--center"),
    ("orientation_deg", "--orientation"),
    ("program_format", "--program-format"),
    ("dwell_s", "--dwell-s"),
    ("spec", "--spec"),
    ("tracker_mpe", "--tracker-mpe"),
    // identification::CalibrationSettings
    ("identifiability.fix", "--fix"),
    ("identifiability.free", "--free"),
    ("identifiability.rank_tolerance", "--rank-tol"),
    ("robust_scale_mm", "--robust-scale"),
    ("weighting.tracker", "--tracker-sigma"),
    ("weighting.mm_per_deg", "--orientation-weight"),
    ("solver.max_iterations", "--max-iterations"),
    ("validation_refit_frame", "--validate-refit-frame"),
    // evaluate
    ("refit_frame", "--refit-frame"),
    // simulate (targets)
    ("targets", "--all-targets"),
    ("orientation_sigma_deg", "--orientation-sigma-deg"),
    ("orientation_mm_per_deg", "--orientation-weight"),
    // planning::PlanSettings (`poses` and `noise_mm` as above)
    ("candidates", "--candidates"),
    ("candidates_per_feature", "--candidates-per-feature"),
    // simulation::ConstraintSimulation (simulate --constraint, plan --constraint)
    ("features", "--features"),
    ("per_feature", "--per-feature"),
    ("radius_mm", "--radius-mm"),
    ("tilt_deg", "--tilt-deg"),
    ("span_mm", "--span-mm"),
    ("include", "--include"),
    ("tracker_range", "--range-mm"),
    ("payload_kg", "--payload-kg"),
    ("compliance", "--compliance"),
    ("harmonics", "--harmonics"),
    // compensation::DampedLeastSquares
    ("tolerance_mm", "--tolerance-mm"),
    ("max_iterations", "--max-iterations"),
    // compensation::PoseNewton
    ("tolerance_deg", "--tolerance-deg"),
    // programs (compensate --program)
    ("program", "--program"),
    // io::import::ImportConfig
    ("time_offset_s", "--time-offset"),
    ("time_tolerance_s", "--time-tolerance"),
    ("dwell.still_deg", "--still-deg"),
    ("dwell.min_s", "--dwell-min-s"),
    ("joint_columns", "--joint-columns"),
];

/// The flag that sets a library setting, if there is one.
pub fn flag_for(setting: &str) -> Option<&'static str> {
    FLAGS.iter().find(|(s, _)| *s == setting).map(|(_, f)| *f)
}

/// Phrases the library uses for a setting that is no field of its settings structs, and the flag
/// that sets it.
const PHRASES: &[(&str, &str)] = &[
    ("wrong nominal robot", "wrong --robot"),
    ("rank tolerance", "rank tolerance (--rank-tol)"),
    ("the `base_link` setting", "--base-link"),
    ("the `tip_link` setting", "--tip-link"),
    ("`base_link` and `tip_link`", "--base-link and --tip-link"),
    // io::import: errors about files (Parse) name the settings that resolve them.
    ("the `length_unit` setting", "--length-unit"),
    ("the `angle_unit` setting", "--angle-unit"),
    ("the `joint_columns` setting", "--joint-columns"),
    ("the `name_column` setting", "--name-column"),
    ("the `match_by` setting", "--match"),
    ("the `time_offset_s` setting", "--time-offset"),
    ("`time_tolerance_s` setting", "--time-tolerance"),
    ("the `dwell.min_s` setting", "--dwell-min-s"),
    ("the `dwell.still_deg` setting", "--still-deg"),
    ("the `nominal_limits` setting", "--nominal-limits"),
];

/// `text` with every setting named in backticks (`` `noise_mm` ``) replaced by its flag.
pub fn with_flags(text: &str) -> String {
    let mut out = text.to_owned();
    // Only text with a quoted word can name a setting; each is looked for, unquoted first (no
    // allocation), then quoted where the bare name occurs.
    if !out.contains('`') {
        return out;
    }
    for (setting, flag) in FLAGS {
        if !out.contains(setting) {
            continue;
        }
        let quoted = format!("`{setting}`");
        if out.contains(&quoted) {
            out = out.replace(&quoted, flag);
        }
    }
    out
}

/// `text` (e.g. a library report's line) with the library's phrases for settings ([`PHRASES`])
/// replaced by the flags.
pub fn with_phrases(text: &str) -> String {
    PHRASES
        .iter()
        .fold(text.to_owned(), |t, (phrase, flag)| t.replace(phrase, flag))
}

/// The text of one error as the user of this program should read it. A library error about
/// settings ([`robocal_core::Error::Invalid`], `Numerical`, `Implausible`) names the flags: the
/// field (`--noise-mm: ...` for `noise_mm: ...`) and the settings in backticks in its message.
/// Other library errors only get [`PHRASES`] replaced: their backticks quote the fields of files
/// (`missing field `tracker_frame``), which must stay as they are; and the program's own errors
/// already speak of flags.
pub fn cli_text(e: &(dyn std::error::Error + 'static)) -> String {
    use robocal_core::Error as E;
    let Some(core) = e.downcast_ref::<E>() else {
        return e.to_string();
    };
    let text = match core {
        E::Invalid { field, message } | E::Usage { field, message } => {
            // `setting (joint 2)`: the flag, and which of its values.
            let (head, tail) = field
                .split_once(" (")
                .map_or((field.as_str(), ""), |(h, _)| (h, &field[h.len()..]));
            match flag_for(head) {
                Some(flag) => format!("{flag}{tail}: {}", with_flags(message)),
                None => format!("{field}: {}", with_flags(message)),
            }
        }
        E::Numerical(m) | E::Implausible(m) => with_flags(m),
        other => other.to_string(),
    };
    PHRASES
        .iter()
        .fold(text, |t, (phrase, flag)| t.replace(phrase, flag))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The identifiability's numerical failures speak of the rank tolerance in prose; the user
    /// learns its flag.
    #[test]
    fn the_rank_tolerance_is_named_with_its_flag() {
        let e = robocal_core::Error::Numerical(
            "the least independent is d3 (2.0e-9, rank tolerance 1e-6). Raise the rank tolerance \
             above 2.0e-9 to fix it"
                .into(),
        );
        let t = cli_text(&e);
        assert_eq!(t.matches("rank tolerance (--rank-tol)").count(), 2, "{t}");
    }

    #[test]
    fn setting_errors_name_the_flag() {
        let e = robocal_core::Error::invalid("noise_mm", "-1 mm is out of range");
        assert_eq!(cli_text(&e), "--noise-mm: -1 mm is out of range");
        let e = robocal_core::Error::invalid(
            "outliers.min_mm",
            "5 is greater than `outliers.max_mm` 2",
        );
        assert_eq!(
            cli_text(&e),
            "--outlier-min-mm: 5 is greater than --outlier-max-mm 2"
        );
        // Fields that are not settings, and words that only look like one, stay.
        let e = robocal_core::Error::invalid("calibration data", "no robot points");
        assert_eq!(cli_text(&e), "calibration data: no robot points");
        assert_eq!(with_flags("robot `kr` and `d2`"), "robot `kr` and `d2`");
        assert_eq!(
            with_flags(
                "choose another `plane_z_mm` or leave the plane points out (`plane_points`)"
            ),
            "choose another --plane-z-mm or leave the plane points out (--no-plane)"
        );
        // A file's fields keep their names, even where a setting has the same one.
        let e =
            robocal_core::Error::parse("r.json", Some(3), None, "missing field `tracker_frame`");
        assert_eq!(cli_text(&e), "r.json:3: missing field `tracker_frame`");
        let e = robocal_core::Error::parse("r.json", None, None, "wrong nominal robot or file");
        assert_eq!(cli_text(&e), "r.json: wrong --robot or file");
    }

    #[test]
    fn every_setting_and_flag_is_listed_once() {
        for (i, (s, f)) in FLAGS.iter().enumerate() {
            assert!(f.starts_with("--") && !s.contains("--"), "{s} {f}");
            assert!(FLAGS[..i].iter().all(|(t, _)| t != s), "{s} twice");
        }
    }
}
