//! The quick parse of a plain decimal cell (`-12.345`), the same bits as `str::parse`.

/// The exact powers of ten of a double, 1e0..=1e22.
const POWERS_OF_TEN: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// A plain decimal (`-12.345`: an optional sign, digits, at most one point, at most 15 digits in
/// all) the quick way, `None` for anything else: its digits as an integer and ten to the number
/// of decimals are both exact doubles, so their quotient is the correctly rounded value, the
/// same bits as `str::parse` gives (Clinger's fast path); the standard parser (a few hundred
/// instructions a cell) then reads only what this does not.
#[inline]
pub(crate) fn plain_decimal(s: &str) -> Option<f64> {
    let b = s.as_bytes();
    let (neg, digits) = match b.first()? {
        b'-' => (true, &b[1..]),
        b'+' => (false, &b[1..]),
        _ => (false, b),
    };
    // The digits before the point, then those after it: one test a byte. (Wrapping: a number
    // of more than 15 digits is refused below, whatever its value.)
    let mut mantissa = 0u64;
    let mut k = 0;
    while let Some(d) = digits
        .get(k)
        .map(|c| c.wrapping_sub(b'0'))
        .filter(|d| *d <= 9)
    {
        mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(d));
        k += 1;
    }
    let mut count = k;
    let mut decimals = 0;
    if k < digits.len() {
        if digits[k] != b'.' {
            return None;
        }
        for &c in &digits[k + 1..] {
            let d = c.wrapping_sub(b'0');
            if d > 9 {
                return None;
            }
            mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(d));
        }
        decimals = digits.len() - k - 1;
        count += decimals;
    }
    if count == 0 || count > 15 {
        return None;
    }
    let v = mantissa as f64 / POWERS_OF_TEN[decimals];
    Some(if neg { -v } else { v })
}

#[cfg(test)]
mod tests {
    use super::plain_decimal;

    /// The quick parse gives the standard parser's bits wherever it answers, and answers for the
    /// decimals files hold.
    #[test]
    fn plain_decimals_are_the_standard_parse() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0x2545_f491);
        for _ in 0..100_000 {
            let (r, decimals) = (rng.gen::<u64>(), rng.gen_range(0..16usize));
            let v = (r % 10_000_000_000) as f64 / 1000.0 - 5e6;
            let s = format!("{v:.decimals$}");
            let want: f64 = s.parse().unwrap();
            match plain_decimal(&s) {
                Some(got) => assert_eq!(got.to_bits(), want.to_bits(), "{s}"),
                None => assert!(s.trim_start_matches('-').len() > 16, "{s}"),
            }
        }
        for s in [
            "0",
            "-0",
            "-0.0",
            "+5",
            "5.",
            ".5",
            "-37.953953735",
            "123456789012345",
            "+.5",
            "-0.00000000000001",
        ] {
            let want: f64 = s.parse().unwrap();
            assert_eq!(
                plain_decimal(s).map(f64::to_bits),
                Some(want.to_bits()),
                "{s}"
            );
        }
        for s in [
            "",
            "-",
            ".",
            "1e5",
            "1.2.3",
            "inf",
            "NaN",
            "1,5",
            "1234567890123456",
            " 1",
            "123456789012345678901234567",
            "1..2",
            "1.-2",
            "-.",
            "1.2e3",
            "12 ",
        ] {
            assert_eq!(plain_decimal(s), None, "{s}");
        }
    }
}
