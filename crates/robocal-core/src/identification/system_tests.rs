//! Tests of the parent module (`identification::system`).

use super::*;
use crate::model::presets::preset;
use crate::simulation::{random_poses, PoseSampler};
use rand::SeedableRng;

/// The normal-equation right-hand side is minus the objective's gradient: check it against
/// central finite differences of the objective, for every loss.
#[test]
fn gradient_matches_finite_differences() {
    let truth = preset("kuka-kr480-r3330-table3").unwrap();
    let nominal = preset("kuka-kr480-r3330").unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let qs = random_poses(&truth, 30, &PoseSampler::default(), &mut rng).unwrap();
    let mut obs = Observations::new(6);
    for q in &qs {
        obs.push(q, truth.tool_position(q), 0).unwrap();
    }
    let params: Vec<Param> = nominal.params();
    let p = Problem::new(&nominal, &params, &obs, &TrackerFrame::identity());
    for loss in [
        Loss::SumOfNorms { delta: 1e-6 },
        Loss::Squared,
        Loss::Huber { k: 0.8 },
        Loss::Cauchy { c: 0.5 },
    ] {
        let acc = p.accumulate(&nominal, &loss, Level::Full);
        let x0 = p.values(&nominal);
        for (j, param) in params.iter().enumerate() {
            let h = if param.unit() == crate::model::Unit::Deg {
                1e-7
            } else {
                1e-5
            };
            let mut r = nominal.clone();
            let mut x = x0.clone();
            x[j] += h;
            p.apply(&mut r, &x);
            let fp = p.objective(&r, &loss);
            x[j] -= 2.0 * h;
            p.apply(&mut r, &x);
            let fm = p.objective(&r, &loss);
            let fd = (fp - fm) / (2.0 * h);
            let an = -acc.b[j];
            let scale = acc.a[(j, j)].sqrt() * acc.weighted_sq.sqrt() + 1e-12;
            assert!(
                (fd - an).abs() <= 1e-6 * scale + 1e-9,
                "{loss:?} {param}: fd {fd} vs analytic {an}"
            );
        }
        // The Hessian is symmetric positive semi-definite and never above A radially.
        let h = acc.h.unwrap();
        assert!((&h - h.transpose()).amax() <= 1e-9 * h.amax());
    }
}

fn kr480_problem_data(n: usize, noise_mm: f64) -> (Robot, Observations) {
    use rand_distr::{Distribution, Normal};
    let truth = preset("kuka-kr480-r3330-table3").unwrap();
    let nominal = preset("kuka-kr480-r3330").unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let qs = random_poses(&truth, n, &PoseSampler::default(), &mut rng).unwrap();
    let noise = Normal::new(0.0, noise_mm).unwrap();
    let mut obs = Observations::new(6);
    for q in &qs {
        let p = truth.tool_position(q);
        let m = p + Vector3::from_fn(|_, _| noise.sample(&mut rng));
        obs.push(q, m, 0).unwrap();
    }
    (nominal, obs)
}

/// `S` (the full pass's unweighted Gram matrix, accumulated as `A` plus the down-weighted
/// points' share) equals `sum J^T J` formed directly, with a loss that leaves some points at
/// full weight and down-weights the others.
#[test]
fn full_pass_gram_matrix_is_the_unweighted_sum() {
    let (nominal, obs) = kr480_problem_data(200, 0.0);
    let params = nominal.params();
    let p = Problem::new(&nominal, &params, &obs, &TrackerFrame::identity());
    let norms = p.fit_norms(&nominal);
    let mut sorted = norms.clone();
    sorted.sort_by(f64::total_cmp);
    let loss = Loss::Huber {
        k: sorted[sorted.len() / 2],
    };
    let full_weight = norms.iter().filter(|&&r| loss.weight(r) == 1.0).count();
    assert!(full_weight > 50 && full_weight < 150, "{full_weight}");
    let acc = p.accumulate(&nominal, &loss, Level::Full);
    let k = params.len();
    let (mut jp, mut jr) = (
        vec![Vector3::zeros(); nominal.param_count()],
        vec![0.0; 3 * k],
    );
    let mut want = DMatrix::<f64>::zeros(k, k);
    for i in 0..obs.len() {
        let mut e = [0.0; 3];
        p.observation_rows(&nominal, i, &mut jp, None, &mut e, &mut jr);
        let j = DMatrix::from_row_slice(3, k, &jr);
        want += j.transpose() * j;
    }
    let s = acc.s.unwrap();
    assert!(
        (&s - &want).amax() <= 1e-10 * want.amax(),
        "{}",
        (&s - &want).amax()
    );
}

/// A pass gives the same bits on one thread and on four.
#[test]
fn passes_are_deterministic_across_thread_counts() {
    let (nominal, obs) = kr480_problem_data(3 * CHUNK + 17, 0.05);
    let params = nominal.params();
    let p = Problem::new(&nominal, &params, &obs, &TrackerFrame::identity());
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let acc = p.accumulate(&nominal, &Loss::SumOfNorms { delta: 1e-6 }, Level::Full);
            let f = p.objective(&nominal, &Loss::Squared);
            (
                acc.a,
                acc.b,
                acc.s.unwrap(),
                acc.h.unwrap(),
                acc.objective,
                f,
            )
        })
    };
    let one = run(1);
    for _ in 0..3 {
        let four = run(4);
        assert!(one.0 == four.0 && one.1 == four.1 && one.2 == four.2 && one.3 == four.3);
        assert_eq!(one.4.to_bits(), four.4.to_bits());
        assert_eq!(one.5.to_bits(), four.5.to_bits());
    }
}

/// A pass gives the same bits with AVX as with the baseline instructions (on a processor
/// without AVX both runs are the baseline). Fewer points than a parallel pass takes, so the
/// chunks run on this thread, where the baseline is forced.
#[test]
fn passes_give_the_same_bits_with_and_without_avx() {
    let (nominal, obs) = kr480_problem_data(CHUNK + 45, 0.05);
    let params = nominal.params();
    let p = Problem::new(&nominal, &params, &obs, &TrackerFrame::identity());
    for loss in [
        Loss::SumOfNorms { delta: 1e-6 },
        Loss::Cauchy { c: 0.05 },
        Loss::Squared,
    ] {
        let run = |baseline: bool| {
            crate::identification::simd::force_baseline(baseline);
            let acc = p.accumulate(&nominal, &loss, Level::Full);
            let f = p.objective(&nominal, &loss);
            crate::identification::simd::force_baseline(false);
            (acc, f)
        };
        let (wide, fw) = run(false);
        let (base, fb) = run(true);
        assert!(wide.a == base.a && wide.b == base.b, "{loss:?}");
        assert!(wide.s == base.s && wide.h == base.h, "{loss:?}");
        assert_eq!(wide.objective.to_bits(), base.objective.to_bits());
        assert_eq!(fw.to_bits(), fb.to_bits());
    }
}

/// The solver keeps its last full pass only when it is the pass at the final parameters, and
/// then it is exactly the pass the covariance would make there: a solve that moves keeps nothing
/// stale, one that starts at its minimum keeps its first pass.
#[test]
fn the_kept_pass_is_the_full_pass_at_the_solution() {
    use crate::identification::solver::{solve_keeping, SolverOptions};
    let (nominal, obs) = kr480_problem_data(120, 0.02);
    let names = ["a2", "a3", "d4", "phi2", "phi3", "alpha2", "alpha3"];
    let params: Vec<Param> = nominal
        .params()
        .into_iter()
        .filter(|p| names.contains(&p.name().as_str()))
        .collect();
    assert_eq!(params.len(), names.len());
    let p = Problem::new(&nominal, &params, &obs, &TrackerFrame::identity());
    let loss = Loss::Huber { k: 0.05 };
    let opts = SolverOptions::default();
    let same = |kept: &Accumulated, robot: &Robot| {
        let fresh = p.accumulate(robot, &loss, Level::Full);
        assert_eq!(kept.objective.to_bits(), fresh.objective.to_bits());
        assert_eq!(kept.a, fresh.a);
        assert_eq!(kept.b, fresh.b);
        assert_eq!(kept.h, fresh.h);
        assert_eq!(kept.s, fresh.s);
    };
    let mut robot = nominal.clone();
    let (moved, kept) = solve_keeping(&p, &mut robot, &loss, &opts, &(), None);
    assert!(
        moved.termination.converged() && moved.iterations > 1,
        "{moved:?}"
    );
    if let Some(k) = &kept {
        same(k, &robot);
    }
    let at_minimum = robot.clone();
    let (again, kept) = solve_keeping(&p, &mut robot, &loss, &opts, &(), None);
    assert!(again.termination.converged(), "{again:?}");
    let kept = kept.expect("a solve that stops at its start keeps its full pass");
    same(&kept, &robot);
    assert_eq!(p.values(&robot), p.values(&at_minimum));
}

/// A pass restricted to some of its parameters equals the pass over those parameters alone; a
/// solve given the pass at its start (as the precision analysis hands it over) ends where the
/// solve computing it ends, bit for bit.
#[test]
fn a_restricted_start_pass_is_the_subsets_own_and_the_solve_from_it_the_same() {
    let (nominal, obs) = kr480_problem_data(40, 0.02);
    let all: Vec<Param> = nominal
        .params()
        .into_iter()
        .filter(|p| {
            ["a2", "a3", "d4", "phi2", "phi3", "alpha2", "alpha3"].contains(&p.name().as_str())
        })
        .collect();
    let some: Vec<Param> = vec![all[4], all[0], all[2]];
    let cols: Vec<usize> = some
        .iter()
        .map(|p| all.iter().position(|a| a == p).unwrap())
        .collect();
    let frame = TrackerFrame::identity();
    let big = Problem::new(&nominal, &all, &obs, &frame);
    let small = Problem::new(&nominal, &some, &obs, &frame);
    let restricted = big
        .accumulate(&nominal, &Loss::Squared, Level::Full)
        .restricted(&cols);
    let own = small.accumulate(&nominal, &Loss::Squared, Level::Full);
    assert_same_sums(&restricted, &own);
    assert_eq!(restricted.objective.to_bits(), own.objective.to_bits());
    use crate::identification::solver::{solve_keeping, SolverOptions};
    let opts = SolverOptions::default();
    let (mut r1, mut r2) = (nominal.clone(), nominal.clone());
    let (a, _) = solve_keeping(&small, &mut r1, &Loss::Squared, &opts, &(), None);
    let (b, _) = solve_keeping(&small, &mut r2, &Loss::Squared, &opts, &(), Some(own));
    assert_eq!(a.iterations, b.iterations);
    assert_eq!(a.evaluations, b.evaluations);
    assert_eq!(small.values(&r1), small.values(&r2));
}

/// A grouped pass gives each group's share of the Hessian and gradient: the pass over that
/// group's observations alone (unweighted points here: a subset's own pass weighs its points by
/// its own mean uncertainty), the shares summing to the whole, which is the ungrouped pass's
/// (to rounding: the sums are taken in another order). Over enough points for parallel chunks.
#[test]
fn a_grouped_pass_gives_each_groups_share() {
    let (nominal, obs) = kr480_problem_data(700, 0.02);
    let group: Vec<usize> = (0..obs.len()).map(|i| (i * 7) % 3).collect();
    for loss in [
        Loss::Huber { k: 0.03 },
        Loss::Adaptive { k: 0.04 },
        Loss::Squared,
    ] {
        grouped_pass_case(&nominal, &obs, &group, &loss);
    }
}

fn grouped_pass_case(nominal: &Robot, obs: &Observations, group: &[usize], loss: &Loss) {
    let (nominal, loss) = (nominal.clone(), *loss);
    let params = nominal.params();
    let frame = TrackerFrame::identity();
    let plain =
        Problem::new(&nominal, &params, obs, &frame).accumulate(&nominal, &loss, Level::Full);
    let grouped_problem = Problem::new(&nominal, &params, obs, &frame).grouped(group, 3);
    let grouped = grouped_problem.accumulate(&nominal, &loss, Level::Full);
    assert_same_sums(&grouped, &plain);
    let close = |a: &DMatrix<f64>, b: &DMatrix<f64>| (a - b).amax() <= 1e-12 * b.amax();
    assert!((grouped.objective - plain.objective).abs() <= 1e-12 * plain.objective);
    assert!(plain.groups.is_none());
    let shares = grouped.groups.expect("the groups' shares");
    assert_eq!(shares.len(), 3);
    let mut sum = DMatrix::zeros(params.len(), params.len());
    for (g, (h, b)) in shares.iter().enumerate() {
        let sub = obs.rows_where(|i| group[i] == g).unwrap();
        let own = Problem::new(&nominal, &params, &sub, &frame).accumulate(
            &nominal,
            &loss,
            Level::Newton,
        );
        assert!(close(h, own.h.as_ref().unwrap()), "group {g}");
        assert!((b - &own.b).amax() <= 1e-12 * own.b.amax(), "group {g}");
        sum += h;
    }
    assert!(close(&sum, plain.h.as_ref().unwrap()));
    // Below the Newton level there is no Hessian to share.
    assert!(grouped_problem
        .accumulate(&nominal, &loss, Level::Normal)
        .groups
        .is_none());
}

/// A pass of a problem keeping norms gives each observation's weighted residual norm, in
/// order: the problem's fit norms (to rounding), grouped or not, over parallel chunks.
#[test]
fn a_pass_keeps_the_fit_norms_in_order() {
    let (nominal, obs) = kr480_problem_data(700, 0.02);
    let params = nominal.params();
    let frame = TrackerFrame::identity();
    let group: Vec<usize> = (0..obs.len()).map(|i| (i * 7) % 3).collect();
    let plain = Problem::new(&nominal, &params, &obs, &frame);
    let want = plain.fit_norms(&nominal);
    let loss = Loss::Huber { k: 0.03 };
    assert!(plain
        .accumulate(&nominal, &loss, Level::Full)
        .norms
        .is_none());
    for p in [
        plain.clone().keeping_norms(),
        plain.grouped(&group, 3).keeping_norms(),
    ] {
        let got = p
            .accumulate(&nominal, &loss, Level::Full)
            .norms
            .expect("norms");
        assert_eq!(got.len(), want.len());
        for (g, w) in got.iter().zip(&want) {
            assert!((g - w).abs() <= 1e-12 * w.max(1.0), "{g} against {w}");
        }
    }
}

/// A pass whose residuals are all within the range where a loss is least squares (the adaptive
/// and Huber losses up to their thresholds) is the least-squares pass, bit for bit: the
/// adaptive stage after a least-squares fit without outliers takes that fit's last pass as its
/// own (`pipeline::stages`). Beyond the range it is not.
#[test]
fn a_pass_within_the_least_squares_range_is_the_least_squares_pass() {
    let (nominal, obs) = kr480_problem_data(300, 0.02);
    let params = nominal.params();
    let frame = TrackerFrame::identity();
    let group: Vec<usize> = (0..obs.len()).map(|i| (i * 5) % 4).collect();
    let p = Problem::new(&nominal, &params, &obs, &frame)
        .grouped(&group, 4)
        .keeping_norms();
    let squared = p.accumulate(&nominal, &Loss::Squared, Level::Full);
    let largest = squared
        .norms
        .as_ref()
        .unwrap()
        .iter()
        .fold(0.0, |m: f64, r| m.max(*r));
    for loss in [
        Loss::Adaptive { k: largest },
        Loss::Huber { k: 2.0 * largest },
    ] {
        let other = p.accumulate(&nominal, &loss, Level::Full);
        assert_eq!(other.objective.to_bits(), squared.objective.to_bits());
        assert_eq!(other.weighted_sq.to_bits(), squared.weighted_sq.to_bits());
        assert_eq!(other.psi_sq.to_bits(), squared.psi_sq.to_bits());
        assert_eq!(other.a, squared.a);
        assert_eq!(other.b, squared.b);
        assert_eq!(other.s, squared.s);
        assert_eq!(other.h, squared.h);
        assert_eq!(other.groups, squared.groups);
        assert_eq!(other.norms, squared.norms);
    }
    let beyond = p.accumulate(&nominal, &Loss::Adaptive { k: 0.5 * largest }, Level::Full);
    assert_ne!(beyond.a, squared.a);
}

/// Two full passes' sums `A`, `S`, `H` and `b` agree to 1e-12 of the largest entry.
fn assert_same_sums(got: &Accumulated, want: &Accumulated) {
    let close = |a: &DMatrix<f64>, b: &DMatrix<f64>| (a - b).amax() <= 1e-12 * b.amax();
    assert!(close(&got.a, &want.a));
    assert!(close(got.s.as_ref().unwrap(), want.s.as_ref().unwrap()));
    assert!(close(got.h.as_ref().unwrap(), want.h.as_ref().unwrap()));
    assert!((&got.b - &want.b).amax() <= 1e-12 * want.b.amax());
}
