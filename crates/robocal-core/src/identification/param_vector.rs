//! The parameter vector of a calibration: every model parameter with its name, unit, family,
//! nominal and calibrated values, whether it was identified (or fixed, and why), its standard
//! deviation and how strongly the poses see it. One place to look a parameter up (by identity in
//! O(log n), by name) instead of searching the robot's, the analysis' and the covariance's lists.

use crate::identification::covariance::Covariance;
use crate::identification::identifiability::{FixedParam, Identifiability};
use crate::model::{Param, Robot, Unit};

/// One parameter of a calibration. Values in internal units (mm or rad).
#[derive(Debug, Clone, PartialEq)]
pub struct ParamEntry {
    /// The parameter.
    pub param: Param,
    /// Its DESIGN.md name (`d3`, `base_x`, ...).
    pub name: String,
    /// Its display unit.
    pub unit: Unit,
    /// Its family's key (`link`, `beta`, `base`, `tool`, ...).
    pub family: &'static str,
    /// The nominal value.
    pub nominal: f64,
    /// The calibrated value (the nominal one when fixed).
    pub value: f64,
    /// `None` when identified; else why it is held at its nominal value.
    pub fixed: Option<FixedParam>,
    /// The standard deviation when identified and available.
    pub std: Option<f64>,
    /// When identified: the column's independence when it was accepted (see
    /// [`Identifiability::independence`]).
    pub independence: Option<f64>,
    /// RMS effect on the measured rows of a unit change (mm per internal unit), if analysed.
    pub rms_effect: Option<f64>,
}

impl ParamEntry {
    /// Whether the parameter was identified.
    pub fn identified(&self) -> bool {
        self.fixed.is_none()
    }

    /// A value in internal units shown in this parameter's unit.
    pub fn display(&self, internal: f64) -> f64 {
        self.unit.from_internal(internal)
    }
}

/// Every parameter of a model, in model order (see the module docs).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ParamVector {
    entries: Vec<ParamEntry>,
}

impl ParamVector {
    /// The parameters of `calibrated` (whose list includes every parameter of `nominal` the
    /// calibration enabled) with the analysis' and the covariance's verdicts. A parameter the
    /// nominal model lacks (an enabled Hayati tilt) has nominal value zero.
    pub fn of_calibration(
        nominal: &Robot,
        calibrated: &Robot,
        identifiability: &Identifiability,
        covariance: &Covariance,
    ) -> ParamVector {
        let mut cov_pos: Vec<(Param, usize)> = covariance
            .params
            .iter()
            .enumerate()
            .map(|(j, p)| (*p, j))
            .collect();
        cov_pos.sort();
        let std = covariance.std();
        let mut independence: Vec<(Param, f64)> = identifiability
            .identified
            .iter()
            .copied()
            .zip(identifiability.independence.iter().copied())
            .collect();
        independence.sort_by_key(|(p, _)| *p);
        let mut fixed: Vec<&FixedParam> = identifiability.fixed.iter().collect();
        fixed.sort_by_key(|f| f.param);
        let mut rms = identifiability.column_rms.clone();
        rms.sort_by_key(|(p, _)| *p);
        let find = |v: &[(Param, f64)], p: Param| -> Option<f64> {
            v.binary_search_by_key(&p, |(q, _)| *q).ok().map(|k| v[k].1)
        };
        let entries = calibrated
            .param_list()
            .iter()
            .map(|&p| {
                let cov_j = cov_pos
                    .binary_search_by_key(&p, |(q, _)| *q)
                    .ok()
                    .map(|k| cov_pos[k].1);
                // The analysis gives every parameter a verdict: identified (then the covariance
                // has it) or fixed with a reason. A parameter it never saw can only have been
                // held back by the caller, which is what `User` says.
                let fixed_why = match cov_j {
                    Some(_) => None,
                    None => Some(
                        fixed
                            .binary_search_by_key(&p, |f| f.param)
                            .ok()
                            .map_or_else(
                                || FixedParam {
                                    param: p,
                                    reason: crate::identification::FixReason::User,
                                },
                                |k| fixed[k].clone(),
                            ),
                    ),
                };
                ParamEntry {
                    param: p,
                    name: p.name(),
                    unit: p.unit(),
                    family: p.family().key(),
                    nominal: if nominal.has_param(p) {
                        nominal.get(p)
                    } else {
                        0.0
                    },
                    value: calibrated.get(p),
                    fixed: fixed_why,
                    std: cov_j.map(|j| std[j]).filter(|v| v.is_finite()),
                    independence: find(&independence, p),
                    rms_effect: find(&rms, p),
                }
            })
            .collect();
        ParamVector { entries }
    }

    /// Number of parameters.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// The entries in model order.
    pub fn iter(&self) -> std::slice::Iter<'_, ParamEntry> {
        self.entries.iter()
    }

    /// The position of `p` (a binary search: entries are in `Param` order).
    pub fn position(&self, p: Param) -> Option<usize> {
        self.entries.binary_search_by_key(&p, |e| e.param).ok()
    }

    /// The entry of `p`.
    pub fn get(&self, p: Param) -> Option<&ParamEntry> {
        self.position(p).map(|k| &self.entries[k])
    }

    /// The entry named `name`.
    pub fn by_name(&self, name: &str) -> Option<&ParamEntry> {
        Param::parse(name).and_then(|p| self.get(p))
    }

    /// The identified parameters' entries.
    pub fn identified(&self) -> impl Iterator<Item = &ParamEntry> {
        self.entries.iter().filter(|e| e.identified())
    }
}

impl<'a> IntoIterator for &'a ParamVector {
    type Item = &'a ParamEntry;
    type IntoIter = std::slice::Iter<'a, ParamEntry>;
    fn into_iter(self) -> Self::IntoIter {
        self.entries.iter()
    }
}
