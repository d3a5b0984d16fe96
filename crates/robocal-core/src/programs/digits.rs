//! How numbers are written into a program: as precisely as the controller keeps them.
//!
//! - KUKA KRL `REAL` and ABB RAPID `num` are 32-bit floats: a written number is the shortest
//!   decimal that reads back as the 32-bit float nearest the compensated value, so the printed
//!   text adds no rounding to the controller's own. A 32-bit float keeps 24 bits: at 2048 to
//!   4096 mm a coordinate is kept to 2.4e-4 mm (half of that by rounding), an angle of 128 to
//!   256 deg to 1.5e-5 deg; no text can be more precise on these controllers.
//! - URScript numbers are 64-bit floats: written with 9 decimals (m and rad: 5e-7 mm, 3e-8 deg).
//!
//! A number the compensation leaves as it was (the same value once stored) keeps its text.

/// A 32-bit value below this is written 0 (1e-8 mm, deg, or of a quaternion: 1e-6 deg), not
/// with the dozens of digits a tiny float prints.
const F32_ZERO: f64 = 1e-8;

/// How a controller stores a number.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Precision {
    /// A 32-bit float (KRL `REAL`, RAPID `num`).
    F32,
    /// A 64-bit float, written with this many decimals.
    Decimals(usize),
}

impl Precision {
    /// The value the controller keeps of `v`.
    pub fn stored(self, v: f64) -> f64 {
        match self {
            Precision::F32 if v.abs() < F32_ZERO => 0.0,
            Precision::F32 => f64::from(v as f32),
            Precision::Decimals(_) => v,
        }
    }

    /// `v` as written: the shortest text of the 32-bit float, or fixed decimals (`-0` written as
    /// `0`).
    pub fn write(self, v: f64) -> String {
        let s = match self {
            Precision::F32 => format!("{}", self.stored(v) as f32),
            Precision::Decimals(d) => format!("{v:.d$}"),
        };
        if s.trim_start_matches('-')
            .bytes()
            .all(|c| c == b'0' || c == b'.')
        {
            s.trim_start_matches('-').to_owned()
        } else {
            s
        }
    }

    /// The value the controller keeps of the text `v` is written as.
    pub fn written(self, v: f64) -> f64 {
        self.stored(self.write(v).parse().unwrap_or(v))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f32_text_reads_back_as_the_nearest_f32() {
        for v in [2500.123456789, -0.000012345, 179.99999, 1.0 / 3.0, -1234.5] {
            let s = Precision::F32.write(v);
            assert_eq!(s.parse::<f32>().unwrap(), v as f32, "{v} {s}");
            assert!(!s.contains('e'), "{s}");
        }
        assert_eq!(Precision::F32.write(-1e-50), "0");
        assert_eq!(Precision::F32.write(-90.0), "-90");
        // The spacing of 32-bit floats at 3 m: 2.4e-4 mm.
        let x = 3000.0f32;
        let next = f32::from_bits(x.to_bits() + 1);
        assert!((f64::from(next - x) - 2.44140625e-4).abs() < 1e-12);
        assert_eq!(Precision::Decimals(9).write(-0.0000000001), "0.000000000");
        assert_eq!(Precision::Decimals(9).write(0.5), "0.500000000");
    }
}
