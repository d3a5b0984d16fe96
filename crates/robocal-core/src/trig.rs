//! Sine and cosine of every joint angle of a chain in one branch-free pass: the forward
//! kinematics of a million points spent a fifth of a calibration in the C library's `sincos`,
//! one call per joint and pass. Here each angle is reduced by the nearest multiple of pi/2 (a
//! three-part Cody-Waite reduction, exact in its first step for the angles robocal accepts) and
//! the sine and cosine of the remainder in [-pi/4, pi/4] are their Taylor series, to the
//! terms below a unit in the last place there (x^17/17! and x^16/16!), summed so that the large
//! terms come last; then rotated into the angle's quadrant without a branch, so the loop over
//! the joints vectorises. Written here rather than taken from a crate because the point is
//! that loop: the libm ports evaluate one angle at a time, with branches. The result is within
//! about one unit in the last place of `f64::sin_cos` (a test holds it to 2 ulp over many turns).

/// pi/2 in three parts: the first two with 33 significant bits, so that their products with a
/// quadrant count below 2^20 are exact, the third the rest (pi/2 = sum to about 1e-37).
const PIO2_1: f64 = 1.5707963267341256;
const PIO2_2: f64 = 6.077100506303966e-11;
const PIO2_2T: f64 = 2.0222662487959506e-21;

/// 1.5 * 2^52: adding and subtracting it rounds a double of magnitude below 2^51 to the nearest
/// integer (ties to even) without a call to the C library's `round` (baseline x86-64 has no
/// rounding instruction).
const ROUNDER: f64 = 6_755_399_441_055_744.0;

/// `1 / n!`.
const fn inv_factorial(n: u32) -> f64 {
    let mut f = 1.0;
    let mut k = 2;
    while k <= n {
        f *= k as f64;
        k += 1;
    }
    1.0 / f
}

/// The sine's Taylor coefficients: `(-1)^k / (2k+1)!`, k = 1..8.
const S1: f64 = -inv_factorial(3);
const S2: f64 = inv_factorial(5);
const S3: f64 = -inv_factorial(7);
const S4: f64 = inv_factorial(9);
const S5: f64 = -inv_factorial(11);
const S6: f64 = inv_factorial(13);
const S7: f64 = -inv_factorial(15);
const S8: f64 = inv_factorial(17);

/// The cosine's Taylor coefficients beyond `1 - x^2/2`: `(-1)^k / (2k)!`, k = 2..8.
const C1: f64 = inv_factorial(4);
const C2: f64 = -inv_factorial(6);
const C3: f64 = inv_factorial(8);
const C4: f64 = -inv_factorial(10);
const C5: f64 = inv_factorial(12);
const C6: f64 = -inv_factorial(14);
const C7: f64 = inv_factorial(16);

/// Beyond this magnitude (rad) the reduction is no longer accurate and the standard library's
/// `sin_cos` is used instead (joint angles are far smaller: see [`crate::ranges::JOINT`]).
const REDUCTION_LIMIT: f64 = 1.0e5;

/// `(sin x, cos x)` of one angle, without a branch on `x` for finite `|x| <= 1e5`.
#[inline(always)]
pub fn sin_cos(x: f64) -> (f64, f64) {
    // NaN and infinities fail the test too.
    if x.abs() <= REDUCTION_LIMIT {
        reduced_sin_cos(x)
    } else {
        x.sin_cos()
    }
}

/// [`sin_cos`] of an angle known to be within the reduction's limit.
#[inline(always)]
fn reduced_sin_cos(x: f64) -> (f64, f64) {
    let t = x * std::f64::consts::FRAC_2_PI + ROUNDER;
    let k = t - ROUNDER;
    let r = (x - k * PIO2_1) - k * PIO2_2 - k * PIO2_2T;
    let z = r * r;
    let w = z * z;
    // sin r = r + r z (S1 + z (S2 + ...)), cos r = 1 - z/2 + z^2 (C1 + z (C2 + ...)), z = r^2:
    // the small terms summed first, then added to the large ones.
    let sr = S2 + z * (S3 + z * S4) + z * w * (S5 + z * S6) + w * w * z * (S7 + z * S8);
    let s = r + z * r * (S1 + z * sr);
    let cr = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * (C6 + z * C7)));
    let hz = 0.5 * z;
    let one_minus = 1.0 - hz;
    let c = one_minus + (((1.0 - one_minus) - hz) + z * cr);
    // Quadrant k mod 4: (s, c), (c, -s), (-s, -c), (-c, s).
    let quadrant = t.to_bits() & 3;
    let swap = quadrant & 1 == 1;
    let (a, b) = if swap { (c, s) } else { (s, c) };
    let sin_neg = quadrant >= 2;
    let cos_neg = quadrant == 1 || quadrant == 2;
    (if sin_neg { -a } else { a }, if cos_neg { -b } else { b })
}

/// [`sin_cos`] of `angles[i]` into `s[i]`, `c[i]`, for every `i`: one loop without a branch
/// when every angle is within the reduction's limit (the joint angles always are).
#[inline(always)]
pub fn sin_cos_all(angles: &[f64], s: &mut [f64], c: &mut [f64]) {
    let within = angles
        .iter()
        .fold(true, |ok, a| ok & (a.abs() <= REDUCTION_LIMIT));
    let each = angles.iter().zip(s.iter_mut()).zip(c.iter_mut());
    if within {
        for ((a, s), c) in each {
            (*s, *c) = reduced_sin_cos(*a);
        }
    } else {
        for ((a, s), c) in each {
            (*s, *c) = sin_cos(*a);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distance in units in the last place (of the larger magnitude; exact zero counts as one
    /// ulp of the smallest normal).
    fn ulps(a: f64, b: f64) -> f64 {
        let scale = a.abs().max(b.abs()).max(f64::MIN_POSITIVE);
        let ulp = f64::from_bits(scale.to_bits() + 1) - scale;
        (a - b).abs() / ulp
    }

    /// Within 2 ulp of the standard library over joint angles of many turns, near the quadrant
    /// boundaries and at tiny angles; and the quadrant signs are right.
    #[test]
    fn matches_the_standard_library_to_two_ulp() {
        let mut worst = 0.0f64;
        let mut check = |x: f64| {
            let (s, c) = sin_cos(x);
            let (es, ec) = x.sin_cos();
            // Near a zero of sin or cos the absolute error counts, relative to the value 1.
            let es_err = ulps(s, es).min((s - es).abs() / f64::EPSILON);
            let ec_err = ulps(c, ec).min((c - ec).abs() / f64::EPSILON);
            worst = worst.max(es_err).max(ec_err);
            assert!(
                es_err <= 2.0 && ec_err <= 2.0,
                "x = {x:e}: {s:e} {c:e} vs {es:e} {ec:e}"
            );
        };
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..200_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let u = (state >> 11) as f64 / (1u64 << 53) as f64;
            check((u - 0.5) * 2.0 * 40.0 * std::f64::consts::PI);
        }
        for k in -64..=64 {
            let b = k as f64 * std::f64::consts::FRAC_PI_4;
            for d in [-1e-9, -1e-15, 0.0, 1e-15, 1e-9] {
                check(b + d);
            }
        }
        for x in [0.0, -0.0, 1e-300, -1e-8, 3e-5, 1.0e5, -99_999.5, 1e6, 1e12] {
            check(x);
        }
        assert!(worst > 0.0, "the comparison ran");
        let (s, c) = sin_cos(f64::NAN);
        assert!(s.is_nan() && c.is_nan());
    }

    #[test]
    fn all_at_once_is_one_at_a_time() {
        for a in [
            [0.3, -2.0, 7.5, 1e-3, -40.0, 3.0],
            [0.3, -2.0, 7.5, 1e-3, 4e7, f64::NAN],
        ] {
            let (mut s, mut c) = ([0.0; 6], [0.0; 6]);
            sin_cos_all(&a, &mut s, &mut c);
            for i in 0..6 {
                let (es, ec) = sin_cos(a[i]);
                assert_eq!(
                    (s[i].to_bits(), c[i].to_bits()),
                    (es.to_bits(), ec.to_bits())
                );
            }
        }
    }
}
