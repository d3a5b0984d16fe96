//! Acceptance limits of an ISO 9283 test ([`Spec`]) and the uncertainty of the instrument that
//! measured it ([`TrackerMpe`]).

use crate::error::{Error, Result};
use serde::Serialize;

/// Acceptance limits: a pose passes when its AP and RP are at most these (mm). A limit left out
/// is not checked.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct Spec {
    /// Largest accepted position accuracy AP (mm).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ap_mm: Option<f64>,
    /// Largest accepted position repeatability RP (mm).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rp_mm: Option<f64>,
}

impl Spec {
    /// Parses `ap=MM,rp=MM` (either or both, any order). Errors name the field `spec`.
    pub fn parse(text: &str) -> Result<Spec> {
        let mut s = Spec::default();
        for part in text.split(',') {
            let part = part.trim();
            let Some((k, v)) = part.split_once('=') else {
                return Err(Error::invalid(
                    "spec",
                    format!("`{part}` is not KEY=MM (keys: ap, rp)"),
                ));
            };
            let v: f64 = v.trim().parse().map_err(|_| {
                Error::invalid("spec", format!("`{part}`: `{}` is not a number", v.trim()))
            })?;
            let slot = match k.trim() {
                "ap" => &mut s.ap_mm,
                "rp" => &mut s.rp_mm,
                other => {
                    return Err(Error::invalid(
                        "spec",
                        format!("unknown limit `{other}` (known: ap, rp)"),
                    ))
                }
            };
            if slot.is_some() {
                return Err(Error::invalid(
                    "spec",
                    format!("`{}` given twice", k.trim()),
                ));
            }
            *slot = Some(v);
        }
        s.validate()?;
        Ok(s)
    }

    /// Checks the limits: positive and finite, at least one given.
    pub fn validate(&self) -> Result<()> {
        if self.ap_mm.is_none() && self.rp_mm.is_none() {
            return Err(Error::invalid("spec", "no limit given (ap=MM, rp=MM)"));
        }
        for (k, v) in [("ap", self.ap_mm), ("rp", self.rp_mm)] {
            if let Some(v) = v {
                if !(v.is_finite() && v > 0.0 && v <= 1e3) {
                    return Err(Error::invalid(
                        "spec",
                        format!("{k}={v}: not a limit in (0, 1000] mm"),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Whether `ap` and `rp` (mm) are within the limits.
    pub fn passes(&self, ap: f64, rp: f64) -> bool {
        self.ap_mm.map_or(true, |l| ap <= l) && self.rp_mm.map_or(true, |l| rp <= l)
    }
}

/// The measuring instrument's maximum permissible error (MPE) for a point, `mpe_mm + per_m_mm *
/// distance_m` (ASME B89.4.19-style figures).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TrackerMpe {
    /// Constant part (mm).
    pub mpe_mm: f64,
    /// Distance-proportional part (mm per metre from the tracker).
    pub per_m_mm: f64,
}

impl Default for TrackerMpe {
    /// 0.015 mm + 0.006 mm/m: a laser tracker's typical MPE (DESIGN.md, "Facts").
    fn default() -> Self {
        TrackerMpe {
            mpe_mm: 0.015,
            per_m_mm: 0.006,
        }
    }
}

impl TrackerMpe {
    /// Parses `MM` or `MM,MM_PER_M`. Errors name the field `tracker_mpe`.
    pub fn parse(text: &str) -> Result<TrackerMpe> {
        let v: Vec<f64> = text
            .split(',')
            .map(|p| p.trim().parse::<f64>())
            .collect::<std::result::Result<_, _>>()
            .map_err(|_| {
                Error::invalid("tracker_mpe", format!("`{text}` is not MM or MM,MM_PER_M"))
            })?;
        let t = match v[..] {
            [a] => TrackerMpe {
                mpe_mm: a,
                per_m_mm: 0.0,
            },
            [a, b] => TrackerMpe {
                mpe_mm: a,
                per_m_mm: b,
            },
            _ => {
                return Err(Error::invalid(
                    "tracker_mpe",
                    format!("{} values: give MM or MM,MM_PER_M", v.len()),
                ))
            }
        };
        t.validate()?;
        Ok(t)
    }

    /// Checks the figures: finite, not negative, at most 1 mm (+ 1 mm/m).
    pub fn validate(&self) -> Result<()> {
        for (k, v) in [("mpe_mm", self.mpe_mm), ("per_m_mm", self.per_m_mm)] {
            if !(v.is_finite() && (0.0..=1.0).contains(&v)) {
                return Err(Error::invalid(
                    "tracker_mpe",
                    format!("{k} = {v}: not an uncertainty in [0, 1] mm"),
                ));
            }
        }
        Ok(())
    }

    /// The MPE (mm) at `distance_mm` from the tracker.
    pub fn at_distance_mm(&self, distance_mm: f64) -> f64 {
        self.mpe_mm + self.per_m_mm * distance_mm / 1000.0
    }
}
