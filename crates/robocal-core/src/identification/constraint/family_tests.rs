//! Families beyond geometry in the constraint fit and the model choice on constraint data: the
//! Jacobian's family columns against finite differences, noise-free recovery of geometry and
//! compliance on a sagging KR 480, the scale's refusal with a family, and the automatic choice
//! over seeds (geometry on a geometric robot, compliance on a sagging one).

use super::tests::{check_poses, nominal, simulate, spec, truth};
use super::*;
use crate::experiment::{PAPER_LINK_MASSES_KG, PAPER_PAYLOAD_KG};
use crate::identification::AutoFamilies;
use crate::model::family::{compliance, transmission};
use crate::observations::constraint::ConstraintKind;
use crate::simulation::constraint::{aligned_model_error, ConstraintSimulation};
use crate::simulation::GravityModel;

/// The selection tests' sag: joints 2 and 3 compliant, the paper's masses and payload.
fn sag() -> GravityModel {
    GravityModel::new(
        vec![0.0, 2e-8, 2e-8, 0.0, 0.0, 0.0],
        PAPER_LINK_MASSES_KG.to_vec(),
        PAPER_PAYLOAD_KG,
    )
}

/// The random geometric truth of `seed`, sagging under gravity (the compliance family set to the
/// simulator's physics on joints 2 and 3).
fn sagging_truth(seed: u64) -> Robot {
    sag().equivalent(&truth(seed), false).unwrap()
}

/// The nominal robot with the compliance family on joints 2 and 3 (the truth's), at zero.
fn compliant_nominal() -> Robot {
    let mut r = nominal();
    compliance::enable(&mut r, &[1, 2], None).unwrap();
    r
}

#[test]
fn the_constraint_jacobian_with_compliance_and_harmonics_matches_finite_differences() {
    // The model away from the solution, its compliance and harmonics non-zero: the family
    // columns and the geometric ones under the deflection.
    let t = sagging_truth(1);
    let data = simulate(&t, &spec(ConstraintKind::Point, 0.01, 1)).data;
    let mut robot = sag().equivalent(&nominal(), false).unwrap();
    transmission::enable(&mut robot, &(0..6).collect::<Vec<_>>(), 1).unwrap();
    for (k, p) in robot.params().into_iter().enumerate() {
        if p.family().key() == transmission::KEY {
            robot.set(p, 1e-4 * (k as f64 % 5.0 - 2.0));
        }
    }
    let features = start_values(&robot, &data).unwrap();
    let params: Vec<Param> = robot
        .param_list()
        .iter()
        .filter(|p| p.family_id() != Param::base(0).family_id())
        .copied()
        .collect();
    assert!(params.iter().any(|p| p.family().key() == compliance::KEY));
    let layout = Layout::new(&robot, &params, &features);
    let (_, j) = fit::evaluate(&robot, &layout, &data, &features, None, true);
    let j = j.unwrap();
    // The family columns are exact; a geometric column leaves out how the deflection changes
    // with the geometry (a lever arm grows with a length: about c M g / 1000 * reach, 6e-4 of the
    // column here), as the seam's screws do for tracker data (Gauss-Newton's approximation; the
    // residuals are exact, so the minimum is: see the noise-free recovery).
    let mut worst = [(0.0, String::new()), (0.0, String::new())];
    for (c, p) in params.iter().enumerate() {
        // A step that moves the tool by about 1e-4 mm (the units differ by decades).
        let h = 1e-4 / j.column(c).amax().max(1e-9);
        let shifted = |s: f64| {
            let mut r = robot.clone();
            r.set(*p, r.get(*p) + s);
            fit::evaluate(&r, &layout, &data, &features, None, false).0
        };
        let fd = (shifted(h) - shifted(-h)) / (2.0 * h);
        let err = (&fd - j.column(c)).amax() / fd.amax().max(1e-12);
        let key = p.family().key();
        let w = &mut worst[usize::from(key != compliance::KEY && key != transmission::KEY)];
        if err > w.0 {
            *w = (err, p.name());
        }
    }
    assert!(
        worst[0].0 < 1e-5,
        "family columns: largest relative error {:e} ({})",
        worst[0].0,
        worst[0].1
    );
    assert!(
        worst[1].0 < 2e-3,
        "geometric columns: largest relative error {:e} ({})",
        worst[1].0,
        worst[1].1
    );
}

#[test]
fn noise_free_geometry_and_compliance_are_recovered_exactly() {
    let nom = compliant_nominal();
    let opts = ConstraintOptions::default();
    let s = spec(ConstraintKind::Point, 0.0, 3);
    let mut t = sagging_truth(3);
    // What the data cannot identify is held at nominal in the truth (found by a first fit).
    let first = calibrate_constraints(&nom, &simulate(&t, &s).data, &opts).unwrap();
    for f in &first.fixed {
        t.set(f.param, nom.get(f.param));
    }
    let sim = simulate(&t, &s);
    let cal = calibrate_constraints(&nom, &sim.data, &opts).unwrap();
    assert!(cal.fit.converged);
    assert!(cal.residual_rms_mm < 1e-7, "rms {}", cal.residual_rms_mm);
    let fitted: Vec<&Param> = cal
        .identified
        .iter()
        .filter(|p| p.family().key() == compliance::KEY)
        .collect();
    assert!(fitted.len() >= 4, "compliance identified: {fitted:?}");
    for p in &cal.identified {
        let (got, want) = (cal.robot.get(*p), t.get(*p));
        let tol = if p.family().key() == compliance::KEY {
            // rad per mm of lever: a 1e-6 mm move at a 3 m lever.
            1e-12
        } else {
            1e-6
        };
        assert!(
            (got - want).abs() < tol,
            "{}: {got:e} against {want:e}",
            p.name()
        );
    }
    let (mean, _) = aligned_model_error(&cal.robot, &t, &check_poses(3)).unwrap();
    assert!(mean < 1e-6, "aligned model error {mean}");
    // The result records the family like a tracker result: its parameters, identified.
    let res = cal.to_result(&nom, &sim.data).unwrap();
    for p in fitted {
        let e = &res.parameters[&p.name()];
        assert!(!e.fixed, "{}", p.name());
    }
}

#[test]
fn with_a_family_the_scale_is_still_refused() {
    let s = ConstraintSimulation {
        distances: false,
        ..spec(ConstraintKind::Point, 0.01, 1)
    };
    let data = simulate(&sagging_truth(1), &s).data;
    let check = |e: Error| {
        let e = e.to_string();
        assert!(
            e.contains("scale is not determined") && e.contains("known distance"),
            "{e}"
        );
    };
    check(
        calibrate_constraints(&compliant_nominal(), &data, &ConstraintOptions::default())
            .unwrap_err(),
    );
    check(
        calibrate_constraints_auto(
            &nominal(),
            &data,
            &ConstraintOptions::default(),
            AutoFamilies::default(),
        )
        .unwrap_err(),
    );
}

#[test]
fn thermal_expansion_needs_temperatures_and_backlash_directions() {
    let data = simulate(&truth(1), &spec(ConstraintKind::Point, 0.01, 1)).data;
    let mut warm = nominal();
    thermal::enable(&mut warm, thermal::DEFAULT_REFERENCE_C).unwrap();
    let e = calibrate_constraints(&warm, &data, &ConstraintOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("temperature_c"), "{e}");
    let mut play = nominal();
    backlash::enable(&mut play, &[0, 1, 2]).unwrap();
    let e = calibrate_constraints(&play, &data, &ConstraintOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("dir1..dirN"), "{e}");
}

/// The model chosen on the fixed-point set-up (4 points x 20 configurations, 6
/// distances, 0.01 mm noise) of `t`, and the aligned model errors (mm, mean over 300 random
/// poses) of the geometric calibration and of the chosen one.
fn chosen(t: &Robot, seed: u64) -> (Vec<String>, f64, f64) {
    let data = simulate(t, &spec(ConstraintKind::Point, 0.01, seed)).data;
    let opts = ConstraintOptions::default();
    let cal =
        calibrate_constraints_auto(&nominal(), &data, &opts, AutoFamilies::default()).unwrap();
    let sel = cal.model_selection.as_ref().unwrap();
    assert_eq!(sel.candidates.iter().filter(|c| c.chosen).count(), 1);
    let geometric = calibrate_constraints(&nominal(), &data, &opts).unwrap();
    let poses = check_poses(seed);
    let err = |r: &Robot| aligned_model_error(r, t, &poses).unwrap().0;
    for c in &sel.candidates {
        eprintln!(
            "seed {seed}: {:<28} {:>3} params, cv {:?} +- {:?}{}{}",
            c.name(),
            c.identified,
            c.cv_mean_mm,
            c.cv_std_error_mm,
            if c.chosen { " (chosen)" } else { "" },
            c.rejected.as_deref().unwrap_or("")
        );
    }
    // The chosen model is the one calibrated, and the result records the choice.
    assert_eq!(
        crate::identification::selection::families(&cal.robot),
        sel.chosen().families
    );
    let res = cal.to_result(&nominal(), &data).unwrap();
    assert!(res.model_selection.is_some());
    (
        sel.chosen().families.clone(),
        err(&geometric.robot),
        err(&cal.robot),
    )
}

#[test]
fn on_a_geometric_robot_the_choice_keeps_geometry() {
    for seed in [1, 2, 3] {
        let (families, geometric, selected) = chosen(&truth(seed), seed);
        eprintln!("seed {seed}: geometric {geometric:.4} mm, selected {selected:.4} mm");
        assert!(families.is_empty(), "seed {seed}: {families:?}");
        assert_eq!(geometric, selected);
    }
}

#[test]
fn on_a_sagging_robot_the_choice_takes_compliance_and_the_model_error_drops() {
    for seed in [1, 2, 3] {
        let t = sagging_truth(seed);
        let (families, geometric, selected) = chosen(&t, seed);
        eprintln!(
            "seed {seed}: {families:?}; model error geometric {geometric:.4} mm, selected \
             {selected:.4} mm"
        );
        assert!(
            families.iter().any(|f| f == "compliance"),
            "seed {seed}: {families:?}"
        );
        assert!(
            selected < 0.5 * geometric,
            "seed {seed}: {selected} against {geometric}"
        );
    }
}

/// Few rows for many unknowns (3 spheres of unknown radius x 12 configurations, the scale held):
/// a candidate with a family more could follow the rows' noise exactly, and its cross-validation
/// from the full fit would then read about zero; it is rejected for its unknowns instead, and no
/// family is chosen.
#[test]
fn a_candidate_with_more_unknowns_than_the_rows_bear_is_rejected() {
    let s = ConstraintSimulation {
        features: 3,
        per_feature: 12,
        radius_known: false,
        radius_mm: 150.0,
        distances: false,
        ..spec(ConstraintKind::Sphere, 0.01, 1)
    };
    let data = simulate(&truth(1), &s).data;
    let opts = ConstraintOptions {
        accept_unknown_scale: true,
        ..ConstraintOptions::default()
    };
    let cal =
        calibrate_constraints_auto(&nominal(), &data, &opts, AutoFamilies::default()).unwrap();
    let sel = cal.model_selection.as_ref().unwrap();
    assert!(sel.chosen().families.is_empty(), "{:?}", sel.chosen());
    for c in sel.candidates.iter().filter(|c| !c.families.is_empty()) {
        let why = c.rejected.as_deref().unwrap_or_default();
        assert!(why.contains("unknowns for"), "{}: {why:?}", c.name());
    }
}
