//! Tests of the eager selector: its incremental updates against direct computation, and its
//! designs against random ones.

mod d_tests {
    use super::super::*;
    use rand::{Rng, SeedableRng};

    fn random_blocks(n: usize, k: usize, seed: u64) -> Blocks {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        Blocks::new(
            k,
            (0..n * ROWS * k)
                .map(|_| rng.gen_range(-1.0..1.0))
                .collect(),
        )
    }

    /// The incremental `D_i` agree with a direct computation after many updates, the exchange
    /// never lowers `det M`, and the result beats random sets of the same size.
    #[test]
    fn updates_match_direct_computation_and_exchange_improves() {
        let (n, k) = (400, 8);
        let b = random_blocks(n, k, 1);
        let ridge = DMatrix::identity(k, k) * 1e-6;
        let mut s = Selector::new(&b, ridge.clone(), Criterion::DOptimal, None);
        s.greedy(12);
        let greedy = s.log_det();
        let m = &ridge + b.information(s.selected());
        assert!((greedy - log_det(&m)).abs() < 1e-8);
        let minv = m.clone().try_inverse().unwrap();
        for i in [0, 17, 399] {
            let j = DMatrix::from_row_slice(ROWS, k, b.block(i));
            let d = &j * &minv * j.transpose();
            for r in 0..ROWS {
                for c in 0..ROWS {
                    assert!((d[(r, c)] - s.variance(i)[r * ROWS + c]).abs() < 1e-9 * d.amax());
                }
            }
        }
        let (_, gain) = s.exchange_pass(&());
        assert!(gain >= 0.0);
        assert!(s.log_det() >= greedy - 1e-9);
        let mut sel = s.selected().to_vec();
        sel.sort_unstable();
        sel.dedup();
        assert_eq!(sel.len(), 12, "no candidate twice");
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(2);
        for _ in 0..20 {
            let idx: Vec<usize> = rand::seq::index::sample(&mut rng, n, 12).into_vec();
            assert!(log_det(&(&ridge + b.information(&idx))) < s.log_det());
        }
    }
}

mod i_tests {
    use super::super::*;
    use rand::{Rng, SeedableRng};

    /// The incrementally updated `E_i` agree with a direct computation, and the I-optimal
    /// exchange lowers `tr(W M^-1)` below that of random sets.
    #[test]
    fn i_optimal_updates_match_and_beat_random_sets() {
        let (n, k) = (300, 6);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        // Uneven columns: what a candidate adds differs between the criteria.
        let b = Blocks::new(
            k,
            (0..n * ROWS * k)
                .map(|i| rng.gen_range(-1.0..1.0) * (1.0 + (i % k) as f64))
                .collect(),
        );
        let ridge = DMatrix::identity(k, k) * 1e-6;
        let mut s = Selector::new(&b, ridge.clone(), Criterion::IOptimal, None);
        s.greedy(5);
        // Before any refresh inside the greedy loop: 5 Woodbury updates, then a refresh;
        // do 3 more updates by hand and compare.
        let free: Vec<usize> = (0..n).filter(|&i| !s.in_set[i]).take(2).collect();
        let (x, y) = (free[0], free[1]);
        s.add(x);
        s.add(y);
        s.update(x, -1.0);
        s.in_set[x] = false;
        let mut idx = s.selected().to_vec();
        idx.retain(|&i| i != x);
        let m = &ridge + b.information(&idx);
        let minv = m.clone().try_inverse().unwrap();
        let all: Vec<usize> = (0..n).collect();
        let w = b.information(&all) / n as f64;
        for i in [0, x, y, 123, 299] {
            let j = DMatrix::from_row_slice(ROWS, k, b.block(i));
            let e = &j * &minv * &w * &minv * j.transpose();
            for r in 0..ROWS {
                for c in 0..ROWS {
                    let got = s.weighted_variance(i)[r * ROWS + c];
                    assert!(
                        (e[(r, c)] - got).abs() <= 1e-8 * e.amax(),
                        "{i}: {e} vs {got}"
                    );
                }
            }
        }
        let mut s = Selector::new(&b, ridge.clone(), Criterion::IOptimal, None);
        s.greedy(10);
        let greedy = s.value();
        s.exchange_pass(&());
        let planned = s.value();
        assert!(planned <= greedy * (1.0 + 1e-9));
        let trace = |idx: &[usize]| {
            let m = &ridge + b.information(idx);
            (&w * m.try_inverse().unwrap()).trace()
        };
        assert!((trace(s.selected()) - planned).abs() < 1e-9 * planned);
        for _ in 0..20 {
            let idx: Vec<usize> = rand::seq::index::sample(&mut rng, n, 10).into_vec();
            assert!(trace(&idx) > planned);
        }
    }
}
