//! What the calibration's condition families explain of the data's errors: the calibrated
//! model's mean error with each family taken away (thermal expansion: the lengths at the
//! reference temperature whatever the row's; backlash: every joint in the middle of its play
//! whatever the row's approach), beside its error with all of them, for the families whose
//! conditions the data carry (`temperature_c`; `dir1..dirN`).

use robocal_core::io::row_conditions::{direction_column, TEMPERATURE_COLUMN};
use robocal_core::io::MeasurementSet;
use robocal_core::model::family::{backlash, thermal};
use robocal_core::Robot;

/// The calibrated model without one of its condition families.
pub(super) struct Without {
    /// The family's key in the JSON output (`thermal`, `backlash`).
    pub key: &'static str,
    /// What is taken away, in words.
    pub what: &'static str,
    /// The calibrated model without the family.
    pub model: Robot,
}

/// The calibrated model without each condition family whose condition `header`'s columns carry.
pub(super) fn models_without(cal: &Robot, header: &MeasurementSet) -> anyhow::Result<Vec<Without>> {
    let cols = &header.extra_columns;
    let mut out = Vec::new();
    if thermal::reference_c(cal).is_some() && cols.iter().any(|c| c == TEMPERATURE_COLUMN) {
        let mut model = cal.clone();
        model.set_family_values(thermal::KEY, None)?;
        out.push(Without {
            key: thermal::KEY,
            what: "the rows' temperature (thermal expansion)",
            model,
        });
    }
    let directions = (0..header.dof()).any(|j| cols.contains(&direction_column(j)));
    if !backlash::joints(cal).is_empty() && directions {
        let mut model = cal.clone();
        model.set_family_values(backlash::KEY, None)?;
        out.push(Without {
            key: backlash::KEY,
            what: "the rows' approach directions (backlash)",
            model,
        });
    }
    Ok(out)
}

/// Prints each family's share: the calibrated model's mean error `with_mm` and without it.
pub(super) fn print(without: &[Without], means: &[f64], with_mm: f64) -> anyhow::Result<()> {
    for (w, m) in without.iter().zip(means) {
        outln!(
            "without {}: calibrated mean {m:.4} mm against {with_mm:.4} mm with every condition \
             ({:+.4} mm explained by it)",
            w.what,
            m - with_mm
        )?;
    }
    Ok(())
}
