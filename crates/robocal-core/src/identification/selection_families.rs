//! The non-geometric families of a model selection's candidate, as its forward search builds
//! them (see [`super`]).

use super::HARMONICS;
use crate::error::Result;
use crate::identification::model_choice::AutoFamilies;
use crate::model::family::{backlash, compliance, thermal, transmission};
use crate::model::Robot;

/// A candidate's non-geometric families, as the search builds them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(super) struct Families {
    compliance: bool,
    /// Order of the transmission harmonics (0: none).
    harmonics: usize,
    backlash: bool,
    thermal: bool,
}

impl Families {
    /// The sets with one family more (the next harmonic order for the harmonics), among those
    /// `auto` selects; `compliant`: whether the robot has joints compliance can take.
    pub(super) fn larger(self, auto: AutoFamilies, compliant: bool) -> Vec<Families> {
        let mut out = Vec::new();
        if auto.compliance && compliant && !self.compliance {
            out.push(Families {
                compliance: true,
                ..self
            });
        }
        if auto.harmonics && HARMONICS.contains(&(self.harmonics + 1)) {
            out.push(Families {
                harmonics: self.harmonics + 1,
                ..self
            });
        }
        if auto.backlash && !self.backlash {
            out.push(Families {
                backlash: true,
                ..self
            });
        }
        if auto.thermal && !self.thermal {
            out.push(Families {
                thermal: true,
                ..self
            });
        }
        out
    }

    /// Every family `auto` selects, the highest harmonic order: the widest candidate, whose
    /// parameters every candidate's are among.
    pub(super) fn widest(auto: AutoFamilies, compliant: bool) -> Families {
        Families {
            compliance: auto.compliance && compliant,
            harmonics: if auto.harmonics {
                HARMONICS[HARMONICS.len() - 1]
            } else {
                0
            },
            backlash: auto.backlash,
            thermal: auto.thermal,
        }
    }

    /// `nominal` with these families (their parameters at zero); thermal expansion referred to
    /// `reference_c`.
    pub(super) fn robot(self, nominal: &Robot, reference_c: Option<f64>) -> Result<Robot> {
        let mut r = nominal.clone();
        if self.compliance {
            compliance::enable(&mut r, &compliance::auto_joints(nominal), None)?;
        }
        if self.harmonics > 0 {
            let all: Vec<usize> = (0..nominal.dof()).collect();
            transmission::enable(&mut r, &all, self.harmonics)?;
        }
        if self.backlash {
            backlash::enable(&mut r, &(0..nominal.dof()).collect::<Vec<_>>())?;
        }
        if self.thermal {
            thermal::enable(&mut r, thermal::DEFAULT_REFERENCE_C)?;
        }
        if let Some(t) = reference_c {
            thermal::set_reference_c(&mut r, t)?;
        }
        Ok(r)
    }
}
