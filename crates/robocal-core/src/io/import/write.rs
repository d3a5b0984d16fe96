//! The measurement CSV an import writes: the joint columns (`q1..qn`, or `axis1..axisN` for
//! controller values; 9 decimals of a degree, as `simulate` writes them), `x,y,z` (mm, 6
//! decimals), and where every paired point has them `a,b,c` (deg, 9 decimals), `sigma_mm`,
//! `temperature_c`, `time_s` (seconds since the export's first point) and `id` (the point name).

use super::joints::JointKind;
use super::points::PointTable;

/// The CSV, its columns, and the optional columns left out with the reason.
pub fn csv(
    table: &PointTable,
    matched: &[(usize, &[f64])],
    kind: JointKind,
    dof: usize,
) -> std::io::Result<(Vec<u8>, Vec<String>, Vec<String>)> {
    let rows: Vec<_> = matched.iter().map(|(i, q)| (&table.rows[*i], *q)).collect();
    let n = rows.len();
    let mut left_out = Vec::new();
    let mut all = |what: &str, count: usize| {
        if count > 0 && count < n {
            left_out.push(format!(
                "{what}: only {count} of the {n} paired points have it"
            ));
        }
        count == n
    };
    let abc = all(
        "a,b,c",
        rows.iter().filter(|r| r.0.abc_deg.is_some()).count(),
    );
    let sigma = all(
        "sigma_mm",
        rows.iter().filter(|r| r.0.sigma_mm.is_some()).count(),
    );
    let temp = all(
        "temperature_c",
        rows.iter().filter(|r| r.0.temperature_c.is_some()).count(),
    );
    let time = all(
        "time_s",
        rows.iter().filter(|r| r.0.time_s.is_some()).count(),
    );
    let id = all("id", rows.iter().filter(|r| r.0.name.is_some()).count());
    let t0 = table
        .rows
        .iter()
        .filter_map(|r| r.time_s)
        .next()
        .unwrap_or(0.0);
    let prefix = match kind {
        JointKind::Model => "q",
        JointKind::Axis => "axis",
    };
    let mut header: Vec<String> = (1..=dof).map(|k| format!("{prefix}{k}")).collect();
    header.extend(["x", "y", "z"].map(String::from));
    if abc {
        header.extend(["a", "b", "c"].map(String::from));
    }
    for (on, name) in [
        (sigma, "sigma_mm"),
        (temp, "temperature_c"),
        (time, "time_s"),
        (id, "id"),
    ] {
        if on {
            header.push(name.into());
        }
    }
    let mut w = csv::Writer::from_writer(Vec::with_capacity(n * 120));
    w.write_record(&header)?;
    let mut f: Vec<String> = Vec::with_capacity(header.len());
    for (r, q) in rows {
        f.clear();
        f.extend(q.iter().map(|v| format!("{v:.9}")));
        f.extend(r.p.iter().map(|v| format!("{v:.6}")));
        if let (true, Some(a)) = (abc, r.abc_deg) {
            f.extend(a.iter().map(|v| format!("{v:.9}")));
        }
        if let (true, Some(s)) = (sigma, r.sigma_mm) {
            f.push(format!("{s:.6}"));
        }
        if let (true, Some(t)) = (temp, r.temperature_c) {
            f.push(format!("{t}"));
        }
        if let (true, Some(t)) = (time, r.time_s) {
            f.push(format!("{:.6}", t - t0));
        }
        if let (true, Some(name)) = (id, &r.name) {
            f.push(name.clone());
        }
        w.write_record(&f)?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| std::io::Error::other(e.to_string()))?;
    Ok((bytes, header, left_out))
}
