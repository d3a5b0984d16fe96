//! A simulated session (the measurement CSV `simulate` writes) written as trackers and
//! controllers write their files: the layouts `robocal import` reads. The shipped examples under
//! `examples/import/` are made by these writers, and the round-trip tests use them.

/// The simulator's CSV as text fields: header and rows.
pub struct Session {
    pub header: Vec<String>,
    pub rows: Vec<Vec<String>>,
}

/// KUKA's controller signs of the KR 480 presets: A = sign * q.
pub const KUKA_SIGNS: [bool; 6] = [true, false, false, true, false, true];

impl Session {
    pub fn read(path: &std::path::Path) -> Session {
        let (header, rows) = crate::util::read_csv(path);
        Session { header, rows }
    }

    fn col(&self, name: &str) -> Option<usize> {
        self.header.iter().position(|h| h == name)
    }

    /// A row's text field of a column.
    pub fn get<'a>(&self, row: &'a [String], name: &str) -> &'a str {
        &row[self.col(name).unwrap_or_else(|| panic!("column {name}"))]
    }

    pub fn q<'a>(&self, row: &'a [String]) -> Vec<&'a str> {
        (1..=6).map(|k| self.get(row, &format!("q{k}"))).collect()
    }

    pub fn xyz<'a>(&self, row: &'a [String]) -> [&'a str; 3] {
        [self.get(row, "x"), self.get(row, "y"), self.get(row, "z")]
    }

    pub fn id<'a>(&self, row: &'a [String]) -> &'a str {
        self.get(row, "id")
    }

    /// The probe quaternion (scalar first) of a row's a,b,c, if it has them.
    pub fn quaternion(&self, row: &[String]) -> Option<[f64; 4]> {
        self.col("a")?;
        let v: Vec<f64> = ["a", "b", "c"]
            .iter()
            .map(|c| crate::util::num(self.get(row, c)).to_radians())
            .collect();
        let f = robocal_core::frame::pose(&[0.0, 0.0, 0.0, v[0], v[1], v[2]]);
        let q = nalgebra::UnitQuaternion::from_rotation_matrix(&f.rotation);
        Some([q.w, q.i, q.j, q.k])
    }
}

/// `-v` of a number written as text, exactly.
pub fn negate(v: &str) -> String {
    match v.strip_prefix('-') {
        Some(rest) => rest.to_owned(),
        None => format!("-{v}"),
    }
}

/// A length in mm (6 decimals) in another unit: metres with 9 decimals (exact), inches as the
/// shortest text that reads back as the same number.
fn scaled(v: &str, per_unit_mm: f64) -> String {
    let x = crate::util::num(v) / per_unit_mm;
    if per_unit_mm == 1000.0 {
        format!("{x:.9}")
    } else {
        format!("{x}")
    }
}

/// `dd.mm.yyyy HH:MM:SS.fff` of seconds after 11.10.2022 00:00:00 (less than a day).
pub fn leica_time(s: f64) -> String {
    let ms = (s * 1000.0).round() as i64;
    let (h, m, sec, milli) = (ms / 3_600_000, ms / 60_000 % 60, ms / 1000 % 60, ms % 1000);
    assert!(h < 24);
    format!("'11.10.2022 {h:02}:{m:02}:{sec:02}.{milli:03}")
}

/// A Leica tracker software CSV: mm, U(95), the probe's quaternion when the session has a,b,c,
/// weather, and time stamps (`times`: seconds after midnight, one per row).
pub fn leica(s: &Session, times: &[f64], u95: bool) -> String {
    let mut out = String::from(
        "X  [mm],Y  [mm],Z  [mm],U(95)  [mm],U(95) X/Y/Z [mm],Tilt [deg],Q0,Q1,Q2,Q3,\
         Image RMS [\u{b5}m],Target,Temperature [C],Pressure [mBar],Humidity [%],Time Stamp,\
         OTG Applied,Delete\n",
    );
    for (k, r) in s.rows.iter().enumerate() {
        let [x, y, z] = s.xyz(r);
        let q = s
            .quaternion(r)
            .map(|q| q.map(|v| v.to_string()))
            .unwrap_or_else(|| [(); 4].map(|_| String::new()));
        let target = if q[0].is_empty() {
            "RRR 1.5in"
        } else {
            "T-Mac"
        };
        out.push_str(&format!(
            "{x},{y},{z},{},0.012/0.011/0.015,0.0,{},{},{},{},14,{target},{:.1},1013.2,45,{},No,\n",
            if u95 { "0.021" } else { "" },
            q[0],
            q[1],
            q[2],
            q[3],
            20.0 + 0.1 * (k % 7) as f64,
            leica_time(times[k]),
        ));
    }
    out
}

/// A joint CSV: `id,q1..q6` (degrees, model values).
pub fn joints_q(s: &Session) -> String {
    let mut out = String::from("id,q1,q2,q3,q4,q5,q6\n");
    for r in &s.rows {
        out.push_str(&format!("{},{}\n", s.id(r), s.q(r).join(",")));
    }
    out
}

/// A SpatialAnalyzer ASCII export in metres: `//` header, `Collection Group Target X Y Z`.
pub fn sa(s: &Session) -> String {
    let mut out = String::from(
        "// SpatialAnalyzer ASCII export\n// Frame: A::Tracker\n// Units: Meters\n\
         Collection Group Target X Y Z\n",
    );
    for r in &s.rows {
        let p = s.xyz(r).map(|v| scaled(v, 1000.0));
        out.push_str(&format!("A Cal {} {} {} {}\n", s.id(r), p[0], p[1], p[2]));
    }
    out
}

/// A controller's joint log with its own names: `Point;A1..A6` (KUKA's axis signs), semicolon
/// separated with decimal commas.
pub fn joints_kuka(s: &Session) -> String {
    let mut out = String::from("Point;A1;A2;A3;A4;A5;A6\r\n");
    for r in &s.rows {
        let a: Vec<String> = s
            .q(r)
            .iter()
            .zip(KUKA_SIGNS)
            .map(|(v, neg)| {
                let v = if neg { negate(v) } else { v.to_string() };
                v.replace('.', ",")
            })
            .collect();
        out.push_str(&format!("{};{}\r\n", s.id(r), a.join(";")));
    }
    out
}

/// Semicolon xyz lines `NAME;X;Y;Z;;;;` in inches.
pub fn xyz(s: &Session) -> String {
    let mut out = String::new();
    for r in &s.rows {
        let p = s.xyz(r).map(|v| scaled(v, 25.4));
        out.push_str(&format!("{};{};{};{};;;;\n", s.id(r), p[0], p[1], p[2]));
    }
    out
}

/// Headerless text `x y z` (mm).
pub fn text(s: &Session) -> String {
    s.rows.iter().map(|r| s.xyz(r).join(" ") + "\n").collect()
}

/// A headerless joint file: `q1 .. q6` (degrees).
pub fn joints_text(s: &Session) -> String {
    s.rows.iter().map(|r| s.q(r).join(" ") + "\n").collect()
}

/// A CSV in a European spreadsheet's dialect: a BOM, CRLF, `;` with decimal commas, upper-case
/// names, metres.
pub fn csv(s: &Session) -> String {
    let mut out = String::from("\u{feff}ID;X [m];Y [m];Z [m]\r\n");
    for r in &s.rows {
        let p = s.xyz(r).map(|v| scaled(v, 1000.0).replace('.', ","));
        out.push_str(&format!("{};{};{};{}\r\n", s.id(r), p[0], p[1], p[2]));
    }
    out
}

/// A motion profile: where the robot is, a fraction `u` of the way from `a` to `b`.
fn blend(a: f64, b: f64, u: f64) -> f64 {
    a + (b - a) * 0.5 * (1.0 - (std::f64::consts::PI * u).cos())
}

/// A UR RTDE recorder log at `hz` of a robot that moves between the poses (cosine profiles of
/// `moves[k]` s) and dwells at each (`dwells[k]` s), starting at `t0` on its clock. `poses` are
/// degrees; the log holds radians. Returns the text and the middle of each dwell.
pub fn rtde(
    poses: &[Vec<f64>],
    moves: &[f64],
    dwells: &[f64],
    hz: f64,
    t0: f64,
) -> (String, Vec<f64>) {
    let mut out = String::from(
        "timestamp target_q_0 actual_q_0 actual_q_1 actual_q_2 actual_q_3 actual_q_4 actual_q_5 \
         robot_mode\n",
    );
    let dt = 1.0 / hz;
    let mut n: u64 = 0;
    let mut mids = Vec::new();
    let row = |out: &mut String, q: &[f64], n: &mut u64| {
        let t = t0 + *n as f64 * dt;
        let rad: Vec<String> = q.iter().map(|v| v.to_radians().to_string()).collect();
        out.push_str(&format!("{t:.6} {} {} 7\n", rad[0], rad.join(" ")));
        *n += 1;
    };
    let mut prev = poses[0].clone();
    for (k, p) in poses.iter().enumerate() {
        let steps = (moves[k] * hz).round() as u64;
        for s in 0..steps {
            let u = s as f64 / steps as f64;
            let q: Vec<f64> = prev.iter().zip(p).map(|(a, b)| blend(*a, *b, u)).collect();
            row(&mut out, &q, &mut n);
        }
        let first = n;
        let steps = (dwells[k] * hz).round() as u64;
        for _ in 0..steps {
            row(&mut out, p, &mut n);
        }
        mids.push(t0 + 0.5 * (first + n - 1) as f64 * dt);
        prev = p.clone();
    }
    (out, mids)
}
