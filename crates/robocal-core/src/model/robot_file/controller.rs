//! The `[controller]` section of a robot file: the signs, offsets and couplings between the
//! model's joint values and the controller's axis values, each checked where it stands (line and
//! entry in errors).

use super::fields::FileText;
use super::{ControllerEntry, Numbers};
use crate::error::{Error, Result};
use crate::model::controller::{Controller, Coupling};
use toml::Spanned;

/// The section for a robot of `n` joints: each field checked, then the map built (an error on
/// the coupling's line if it cannot be inverted).
pub(super) fn section(c: &Spanned<ControllerEntry>, n: usize, at: &FileText) -> Result<Controller> {
    let entry = c.get_ref();
    let sign = per_joint(&entry.sign, "sign", 1.0, n, at)?;
    if let Some(v) = &entry.sign {
        for (k, x) in v.get_ref().iter().enumerate() {
            let s = *x.get_ref();
            if s != 1.0 && s != -1.0 {
                return Err(at.error(
                    x.span(),
                    format!("controller.sign[{}]", k + 1),
                    format!("{s} is not 1 or -1"),
                ));
            }
        }
    }
    let offset = per_joint(&entry.offset, "offset", 0.0, n, at)?;
    let mut coupling = Vec::new();
    if let Some(rows) = &entry.coupling {
        for (r, row) in rows.get_ref().iter().enumerate() {
            coupling.push(coupling_row(row, r, n, at)?);
        }
    }
    Controller::new(sign, offset, coupling).map_err(|e| {
        let span = entry
            .coupling
            .as_ref()
            .map_or_else(|| c.span(), |x| x.span());
        let (field, message) = match &e {
            Error::Invalid { field, message } => (field.clone(), message.clone()),
            other => ("controller".to_owned(), other.to_string()),
        };
        at.error(span, field, message)
    })
}

/// One finite value per joint of `controller.NAME`, or `default` for every joint without it.
fn per_joint(
    v: &Option<Numbers>,
    name: &str,
    default: f64,
    n: usize,
    at: &FileText,
) -> Result<Vec<f64>> {
    let Some(v) = v else {
        return Ok(vec![default; n]);
    };
    if v.get_ref().len() != n {
        return Err(at.error(
            v.span(),
            format!("controller.{name}"),
            format!(
                "expected {n} values (one per joint), got {}",
                v.get_ref().len()
            ),
        ));
    }
    v.get_ref()
        .iter()
        .enumerate()
        .map(|(k, x)| {
            let val = *x.get_ref();
            if val.is_finite() {
                Ok(val)
            } else {
                Err(at.error(
                    x.span(),
                    format!("controller.{name}[{}]", k + 1),
                    format!("{val} is not a finite number"),
                ))
            }
        })
        .collect()
}

/// Row `r` of `controller.coupling`: `[i, j, k]`, joint i gets k times axis j (two different
/// joints of `n`, a finite factor).
fn coupling_row(row: &Numbers, r: usize, n: usize, at: &FileText) -> Result<Coupling> {
    let field = format!("controller.coupling[{}]", r + 1);
    let v = row.get_ref();
    if v.len() != 3 {
        return Err(at.error(
            row.span(),
            field,
            format!(
                "expected [i, j, k] (joint i gets k times axis j), got {} numbers",
                v.len()
            ),
        ));
    }
    let index = |x: &Spanned<f64>, what: &str| -> Result<usize> {
        let val = *x.get_ref();
        if val.fract() == 0.0 && val >= 1.0 && val <= n as f64 {
            Ok(val as usize - 1)
        } else {
            Err(at.error(
                x.span(),
                field.clone(),
                format!("{what} {val} is not a joint number 1..{n}"),
            ))
        }
    };
    let joint = index(&v[0], "i")?;
    let axis = index(&v[1], "j")?;
    let factor = *v[2].get_ref();
    if !factor.is_finite() {
        return Err(at.error(
            v[2].span(),
            field,
            format!("factor {factor} is not a finite number"),
        ));
    }
    if joint == axis {
        return Err(at.error(
            row.span(),
            field,
            format!(
                "couples joint {} with its own axis; use sign (and offset) for that",
                joint + 1
            ),
        ));
    }
    Ok(Coupling {
        joint,
        axis,
        factor,
    })
}
