//! JSON has no NaN: serde_json writes a non-finite `f64` as `null`. These helpers read `null`
//! back as NaN so that a report's data survives a round trip through a file.

/// For an `f64` field.
pub mod one {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    /// Writes the value; NaN and infinities become `null`.
    pub fn serialize<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
        if v.is_finite() {
            v.serialize(s)
        } else {
            s.serialize_none()
        }
    }

    /// Reads a number, or `null` as NaN.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
    }
}

/// For a `Vec<f64>` field.
pub mod vec {
    use serde::{Deserialize, Deserializer, Serializer};

    /// Writes the values; NaN and infinities become `null`.
    pub fn serialize<S: Serializer>(v: &[f64], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(v.iter().map(|x| x.is_finite().then_some(*x)))
    }

    /// Reads numbers, `null` as NaN.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
        Ok(Vec::<Option<f64>>::deserialize(d)?
            .into_iter()
            .map(|x| x.unwrap_or(f64::NAN))
            .collect())
    }
}

/// For an `[f64; 3]` field.
pub mod arr3 {
    use serde::{Deserialize, Deserializer, Serializer};

    /// Writes the three values; NaN and infinities become `null`.
    pub fn serialize<S: Serializer>(v: &[f64; 3], s: S) -> Result<S::Ok, S::Error> {
        super::vec::serialize(v, s)
    }

    /// Reads three numbers, `null` as NaN.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 3], D::Error> {
        let [a, b, c] = <[Option<f64>; 3]>::deserialize(d)?;
        Ok([
            a.unwrap_or(f64::NAN),
            b.unwrap_or(f64::NAN),
            c.unwrap_or(f64::NAN),
        ])
    }
}
