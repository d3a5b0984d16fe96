//! Time stamps of tracker exports, as seconds: a plain number of seconds, a day-first date and
//! time `dd.mm.yyyy HH:MM:SS(.fff)` (Leica, often with a leading apostrophe that keeps
//! spreadsheets from reformatting it), or ISO `yyyy-mm-dd[T ]HH:MM:SS(.fff)`. Dates become
//! seconds since 1970-01-01 in the file's own (unstated) time zone: only differences and the
//! clock offset to the joint log matter.

/// The seconds a time stamp stands for, or a description of the formats it could be.
pub fn seconds(text: &str) -> Result<f64, String> {
    let t = text.trim().trim_start_matches('\'').trim();
    if let Ok(v) = t.parse::<f64>() {
        if v.is_finite() {
            return Ok(v);
        }
    }
    let bad = || {
        format!(
            "`{text}` is not a time stamp (seconds, `dd.mm.yyyy HH:MM:SS.fff` or \
             `yyyy-mm-dd HH:MM:SS.fff`)"
        )
    };
    let (date, time) = t
        .split_once(['T', ' '])
        .map(|(d, t)| (d, t.trim()))
        .ok_or_else(bad)?;
    let (y, mo, d) = if date.contains('.') {
        let p: Vec<&str> = date.split('.').collect();
        let [d, m, y] = p[..] else { return Err(bad()) };
        (int(y), int(m), int(d))
    } else {
        let p: Vec<&str> = date.split('-').collect();
        let [y, m, d] = p[..] else { return Err(bad()) };
        (int(y), int(m), int(d))
    };
    let (Some(y), Some(mo), Some(d)) = (y, mo, d) else {
        return Err(bad());
    };
    let p: Vec<&str> = time.split(':').collect();
    let [h, mi, s] = p[..] else { return Err(bad()) };
    let (Some(h), Some(mi)) = (int(h), int(mi)) else {
        return Err(bad());
    };
    let s: f64 = s
        .replace(',', ".")
        .parse()
        .ok()
        .filter(|s: &f64| (0.0..61.0).contains(s))
        .ok_or_else(bad)?;
    if !(1..=12).contains(&mo) || !(1..=31).contains(&d) || h > 23 || mi > 59 || y < 1900 {
        return Err(bad());
    }
    let days = days_from_civil(y, mo, d);
    Ok(days as f64 * 86400.0 + (h * 3600 + mi * 60) as f64 + s)
}

fn int(s: &str) -> Option<i64> {
    if s.is_empty() || !s.bytes().all(|b| b.is_ascii_digit()) || s.len() > 4 {
        return None;
    }
    s.parse().ok()
}

/// Days since 1970-01-01 of a proleptic Gregorian date (Howard Hinnant's algorithm).
fn days_from_civil(y: i64, m: i64, d: i64) -> i64 {
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let mp = (m + 9) % 12;
    let doy = (153 * mp + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146097 + doe - 719468
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn leica_iso_and_seconds() {
        // 2022-10-11 15:06:48.043 UTC is 1665500808.043 s after the epoch.
        let l = seconds("'11.10.2022 15:06:48.043").unwrap();
        assert!((l - 1665500808.043).abs() < 1e-6, "{l}");
        assert_eq!(seconds("2022-10-11T15:06:48.043").unwrap(), l);
        assert_eq!(seconds("2022-10-11 15:06:48.043").unwrap(), l);
        assert_eq!(seconds("12.5").unwrap(), 12.5);
        assert_eq!(days_from_civil(2000, 3, 1), 11017);
        assert!(seconds("10/11/2022 15:06:48").is_err());
        assert!(seconds("32.10.2022 15:06:48").is_err());
        assert!(seconds("'11.10.2022").is_err());
    }
}
