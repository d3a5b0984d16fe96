//! Number formatting for tables: fixed decimals for values that are compared down a column,
//! significant digits for standard deviations, a dash for what is missing.

/// The dash shown for a missing or non-finite figure.
pub const DASH: &str = "–";

/// Numbers joined by `sep` in the shortest form that reads back exactly (small ones in scientific
/// notation, e.g. `1e-8`): for settings shown to a reader and for command lines.
pub fn number_list(v: &[f64], sep: &str) -> String {
    v.iter()
        .map(|x| {
            if *x != 0.0 && x.abs() < 1e-3 {
                format!("{x:e}")
            } else {
                format!("{x}")
            }
        })
        .collect::<Vec<_>>()
        .join(sep)
}

/// `v` with `d` decimals; a dash when not finite. Uses a true minus sign.
pub fn fixed(v: f64, d: usize) -> String {
    if !v.is_finite() {
        return DASH.into();
    }
    let s = format!("{v:.d$}");
    minus(if is_negative_zero_text(&s) {
        s[1..].to_string()
    } else {
        s
    })
}

/// An error figure in mm: three decimals, or scientific notation from 1e5 mm on (a gross
/// error must not blow up a table).
pub fn mm(v: f64) -> String {
    if v.is_finite() && v.abs() >= 1e5 {
        minus(format!("{v:.3e}"))
    } else {
        fixed(v, 3)
    }
}

/// Like [`fixed`] with an explicit `+` for positive values (differences).
pub fn signed(v: f64, d: usize) -> String {
    let s = fixed(v, d);
    if v.is_finite() && !s.starts_with('\u{2212}') && !s.trim_start_matches(['0', '.']).is_empty() {
        format!("+{s}")
    } else {
        s
    }
}

/// `v` with two significant digits (standard deviations), in scientific notation below 1e-4 or
/// at 1e6 and above; a dash when not finite.
pub fn sig2(v: f64) -> String {
    if !v.is_finite() {
        return DASH.into();
    }
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if !(1e-4..1e6).contains(&a) {
        return minus(format!("{v:.1e}"));
    }
    let mag = a.log10().floor() as i32;
    let d = (1 - mag).max(0) as usize;
    fixed(v, d)
}

/// A condition number or other large positive figure: 3 significant digits, scientific above
/// 1e5.
pub fn magnitude(v: f64) -> String {
    if !v.is_finite() {
        return if v.is_nan() {
            DASH.into()
        } else {
            "∞".into()
        };
    }
    if v.abs() >= 1e5 || (v != 0.0 && v.abs() < 1e-3) {
        return minus(format!("{v:.2e}"));
    }
    let mag = v.abs().max(1e-300).log10().floor() as i32;
    fixed(v, (2 - mag).max(0) as usize)
}

fn is_negative_zero_text(s: &str) -> bool {
    s.starts_with('-') && s[1..].chars().all(|c| c == '0' || c == '.')
}

fn minus(s: String) -> String {
    s.replace('-', "\u{2212}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats() {
        assert_eq!(fixed(1.61949, 3), "1.619");
        assert_eq!(fixed(-0.00001, 3), "0.000");
        assert_eq!(fixed(-89.99521, 4), "\u{2212}89.9952");
        assert_eq!(fixed(f64::NAN, 3), DASH);
        assert_eq!(signed(0.0786, 4), "+0.0786");
        assert_eq!(signed(-0.763, 4), "\u{2212}0.7630");
        assert_eq!(signed(0.0, 4), "0.0000");
        assert_eq!(sig2(0.002134), "0.0021");
        assert_eq!(sig2(0.0376), "0.038");
        assert_eq!(sig2(1.26), "1.3");
        assert_eq!(sig2(12.6), "13");
        assert_eq!(sig2(3.1e-6), "3.1e\u{2212}6");
        assert_eq!(magnitude(1234.6), "1235");
        assert_eq!(magnitude(12.345), "12.3");
        assert_eq!(magnitude(2.5e7), "2.50e7");
        assert_eq!(magnitude(f64::INFINITY), "∞");
        assert_eq!(mm(1.61949), "1.619");
        assert_eq!(mm(1.0e9), "1.000e9");
    }
}
