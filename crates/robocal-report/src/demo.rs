//! The report of the paper's experiment in simulation ([`robocal_core::experiment`]): the run's
//! report with the paper's figures beside the tables, the true parameter values beside the
//! calibrated ones, and the settings of the simulated cell.

use crate::data::{Note, ReportData, Setting};
use crate::run::RunData;
use robocal_core::compensation::IkStatus;
use robocal_core::experiment::Experiment;
use robocal_core::Result;

impl ReportData {
    /// The report of a simulated experiment. `dir` names where its files are (shown in the
    /// settings).
    pub fn from_experiment(exp: &Experiment, dir: &str) -> Result<ReportData> {
        let cfg = &exp.config;
        let mut data = ReportData::from_run(&run_of(exp))?;
        data.title = format!(
            "{} – the paper’s experiment in simulation",
            cfg.nominal.name()
        );
        data.subtitle = Some(subtitle(exp));
        add_true_values(&mut data, exp);
        data.notes.push(simulation_note(exp));
        if let Some(warning) = compensation_warning(exp) {
            data.notes.push(warning);
        }

        let mut settings = cell_settings(exp);
        settings.extend(gravity_setting(exp));
        settings.push(seeds_setting(exp));
        settings.push(compensation_setting(exp));
        settings.push(Setting::new("Files", crate::file_name(dir)));
        // The result's own settings (data files, objective, registration) follow, without the
        // robot lines already given above.
        settings.extend(
            data.settings
                .drain(..)
                .filter(|x| x.key != "Robot" && x.key != "Model"),
        );
        data.settings = settings;
        Ok(data)
    }
}

/// The experiment as a calibration run: its result, models and the three measured data sets,
/// with the paper's figures.
fn run_of(exp: &Experiment) -> RunData<'_> {
    let cfg = &exp.config;
    RunData {
        result: &exp.result,
        nominal: &cfg.nominal,
        calibrated: &exp.calibrated,
        calibration: Some(&exp.data),
        validation: Some(&exp.validation),
        verification: Some(&exp.verify),
        with_paper: true,
    }
}

/// The line under the title: the paper's sections, the nominal and true robots, gravity and the
/// seed.
fn subtitle(exp: &Experiment) -> String {
    let cfg = &exp.config;
    let s = &cfg.session;
    format!(
        "Samak et al. (2019), sections II–V, on a virtual cell: nominal model {} (Table I), \
         true robot {} (the paper’s Table III){}, laser tracker with noise; seed {}.",
        cfg.nominal.name(),
        cfg.truth.name(),
        if s.gravity.is_some() {
            " sagging under gravity"
        } else {
            ""
        },
        s.seed
    )
}

/// Fills the parameter table's true values: the true robot in the identified parameters.
fn add_true_values(data: &mut ReportData, exp: &Experiment) {
    let eq = &exp.truth_comparison.equivalent;
    for row in &mut data.parameters {
        if let Ok(p) = eq.param_by_name(&row.name) {
            row.truth = Some(eq.get_display(p));
        }
    }
}

/// The note on what the simulation knows: how the true values are given and how far the
/// calibrated geometry is from the true one.
fn simulation_note(exp: &Experiment) -> Note {
    let tc = &exp.truth_comparison;
    Note::info(format!(
        "Simulation: the true robot is known. The parameter table gives its values in the \
         parameters the calibration identified (the paper’s Table III re-expressed: the \
         effect of a fixed parameter, e.g. d1 = 1044.237 mm, lands on the one that absorbs \
         it, here base_z; fitted to {:.0e} mm). The calibrated geometry is {:.3} mm from the \
         true one on average over the validation poses (max {:.3} mm){}.",
        tc.fit_max_mm.max(1e-12),
        tc.model_error.mean_mm,
        tc.model_error.max_mm,
        if exp.config.session.gravity.is_some() {
            ": the geometric model absorbs part of the gravity sag, which moves some \
             parameters by several standard deviations"
        } else {
            ""
        }
    ))
}

/// A warning when some compensations did not converge, or `None`.
fn compensation_warning(exp: &Experiment) -> Option<Note> {
    let failed = exp
        .compensation
        .iter()
        .filter(|c| !c.report.status.is_converged())
        .count();
    (failed > 0).then(|| {
        Note::warning(format!(
            "{failed} of {} compensations did not converge (see the status column of \
             commanded.csv); they are measured and counted as they are.",
            exp.compensation.len()
        ))
    })
}

/// The settings of the simulated cell: the experiment, the robots, the points, the tracker's
/// pose and noise.
fn cell_settings(exp: &Experiment) -> Vec<Setting> {
    let cfg = &exp.config;
    let s = &cfg.session;
    let t = &s.tracker_frame;
    vec![
        Setting::new(
            "Experiment",
            format!(
                "robocal demo --seed {}: measurement, calibration, validation, \
                 compensation, verification",
                s.seed
            ),
        ),
        Setting::new(
            "Nominal robot",
            format!("{} (Table I, tool T0 of eq. 7)", cfg.nominal.name()),
        ),
        Setting::new(
            "True robot",
            format!("{} (the paper’s Table III)", cfg.truth.name()),
        ),
        Setting::new(
            "Points",
            format!(
                "{} plane + {} calibration + {} validation; verification: the {} \
                 calibration poses, compensated",
                if s.plane_points { 3 } else { 0 },
                s.poses,
                s.validation_poses,
                exp.desired.rows.len()
            ),
        ),
        Setting::new(
            "Tracker (true pose)",
            format!(
                "x {}, y {}, z {} mm; A {}, B {}, C {} deg",
                t.x, t.y, t.z, t.a, t.b, t.c
            ),
        ),
        Setting::new(
            "Tracker noise (1σ per axis)",
            format!("{:.3} mm + {:.3} mm/m", s.noise_mm, s.noise_per_m),
        ),
    ]
}

/// The gravity deflection's setting (compliances, masses, payload and how far it moves the
/// tool), or `None` without gravity.
fn gravity_setting(exp: &Experiment) -> Option<Setting> {
    let g = exp.config.session.gravity.as_ref()?;
    let mut sag = String::new();
    if let Some(d) = &exp.session.deflection_mm {
        let st = robocal_core::ErrorStats::from_norms(d);
        sag = format!(
            "; it moves the tool by {:.3} mm on average, {:.3} mm at most",
            st.mean_mm, st.max_mm
        );
    }
    Some(Setting::new(
        "Gravity deflection",
        format!(
            "compliances {} rad/(N·m); link masses {} kg; payload {} kg{sag}",
            crate::numfmt::number_list(&g.compliance_rad_per_nm, ", "),
            crate::numfmt::number_list(&g.link_masses_kg, ", "),
            g.payload_kg
        ),
    ))
}

/// The seeds' setting: the poses' and first measurement's, and the verification's.
fn seeds_setting(exp: &Experiment) -> Setting {
    let cfg = &exp.config;
    Setting::new(
        "Seeds",
        format!(
            "{} (poses, noise of the first measurement), {} (noise of the verification)",
            cfg.session.seed, cfg.verification_seed
        ),
    )
}

/// The compensation's setting: the method, its tolerance and how many poses converged.
fn compensation_setting(exp: &Experiment) -> Setting {
    let converged = exp
        .compensation
        .iter()
        .filter(|c| c.report.status == IkStatus::Converged)
        .count();
    Setting::new(
        "Compensation (eq. 12–14)",
        format!(
            "damped least squares on the calibrated model, tolerance {:e} mm: {converged} of \
             {} converged",
            exp.config.ik.tolerance_mm,
            exp.compensation.len()
        ),
    )
}
