//! The robot's parameters: the list in the DESIGN.md order, each family's stored values, and
//! reading and writing them by [`Param`] (every write keeps the link cache valid).

use super::{family, FamilyId, Param, Robot};
use crate::error::{Error, Result};

impl Robot {
    /// Every parameter of the model, in the DESIGN.md order: `alpha1..n, d1..n, a1..n, phi1..n`,
    /// then enabled `beta`s, then `base_x..base_c`, `tool_x..tool_c` (36 for six joints without
    /// beta, as in the paper), then the parameters of any further family (see [`family`]).
    pub fn params(&self) -> Vec<Param> {
        self.param_list.clone()
    }

    /// The parameters as a slice (see [`Robot::params`]).
    pub fn param_list(&self) -> &[Param] {
        &self.param_list
    }

    /// Number of parameters ([`Robot::params`]`.len()`).
    pub fn param_count(&self) -> usize {
        self.param_list.len()
    }

    /// The position of `p` in [`Robot::params`] (a binary search: the list is in `Param`
    /// order), or `None` when this model lacks it.
    pub fn param_position(&self, p: Param) -> Option<usize> {
        self.param_list.binary_search(&p).ok()
    }

    /// The families with parameters on this robot and each one's range in [`Robot::params`].
    pub fn family_spans(&self) -> &[(FamilyId, std::ops::Range<usize>)] {
        &self.family_spans
    }

    /// Whether some family deflects the joints (forward kinematics then evaluates `q + dq`).
    pub fn deflects_joints(&self) -> bool {
        self.deflects
    }

    /// The values a family keeps in the robot's family store (families beyond the link table
    /// and the frames), if it has any.
    pub fn family_values(&self, key: &str) -> Option<&[f64]> {
        self.family_store.get(key).map(Vec::as_slice)
    }

    /// Stores (or, with `None`, removes) a family's values (internal units); the family then
    /// derives its parameters from them. Checks that the values are finite.
    pub fn set_family_values(&mut self, key: &str, values: Option<Vec<f64>>) -> Result<()> {
        match values {
            Some(v) => {
                if let Some(k) = v.iter().position(|x| !x.is_finite()) {
                    return Err(Error::invalid(
                        format!("{key} value {}", k + 1),
                        "not a finite number",
                    ));
                }
                self.family_store.insert(key.to_owned(), v);
            }
            None => {
                self.family_store.remove(key);
            }
        }
        self.refresh_params();
        Ok(())
    }

    /// This robot without the families that deflect the joints or grow with the temperature (its
    /// geometric model): what a simulated cell's nominal robot and a truth file's parameters
    /// describe.
    pub fn geometric(&self) -> Robot {
        let mut r = self.clone();
        for fam in family::all() {
            if fam.beyond_geometry(&r) {
                r.family_store.remove(fam.key());
            }
        }
        r.refresh_params();
        r
    }

    /// A mutable view of a family's stored values, for the family's own `set`. The number of
    /// values must not change (the parameter list is derived from it).
    pub fn family_values_mut(&mut self, key: &str) -> Option<&mut [f64]> {
        self.family_store.get_mut(key).map(Vec::as_mut_slice)
    }

    /// Looks a parameter up by its name (`alpha1`, `d2`, `beta3`, `base_x`, `tool_c`, ...).
    pub fn param_by_name(&self, name: &str) -> Result<Param> {
        match Param::parse(name) {
            Some(p) if self.has_param(p) => Ok(p),
            _ => Err(Error::UnknownParameter {
                name: name.to_owned(),
                known: self
                    .param_list
                    .iter()
                    .map(|p| p.name())
                    .collect::<Vec<_>>()
                    .join(", "),
            }),
        }
    }

    /// Makes `p` a parameter of this model if its family allows (a Hayati tilt of an existing
    /// joint; see [`crate::model::family::ParameterFamily::enable`]); else does nothing.
    pub fn enable_param(&mut self, p: Param) -> Result<()> {
        p.family().enable(self, p)
    }

    /// Whether the parameter exists in this model.
    pub fn has_param(&self, p: Param) -> bool {
        self.param_position(p).is_some()
    }

    /// A parameter's value in internal units (mm or radians). For `tool_*` this is the correction
    /// T, not T0 + T. (A Hayati tilt that is not enabled reads as its value in the link table,
    /// zero unless set.)
    pub fn get(&self, p: Param) -> f64 {
        p.family().get(self, p)
    }

    /// Sets a parameter in internal units (mm or radians). Panics if `p` is not a parameter of
    /// this robot (a programming error; names from users go through [`Robot::param_by_name`]).
    pub fn set(&mut self, p: Param, value: f64) {
        debug_assert!(self.has_param(p), "{p} is not a parameter of this robot");
        p.family().set(self, p, value)
    }

    /// A parameter's value in display units (mm or degrees).
    pub fn get_display(&self, p: Param) -> f64 {
        p.unit().from_internal(self.get(p))
    }

    /// A parameter's value in display units, or zero when this model lacks it (a Hayati tilt
    /// that is not enabled is zero by definition): for comparing two models of the same shape
    /// whose parameter lists differ only in such extensions.
    pub fn get_display_or_zero(&self, p: Param) -> f64 {
        if self.has_param(p) {
            self.get_display(p)
        } else {
            0.0
        }
    }

    /// Sets a parameter from display units (mm or degrees).
    pub fn set_display(&mut self, p: Param, value: f64) {
        self.set(p, p.unit().to_internal(value))
    }

    /// All parameter values in internal units, in [`Robot::params`] order.
    pub fn values(&self) -> Vec<f64> {
        self.param_list.iter().map(|p| self.get(*p)).collect()
    }

    /// Sets all parameters from `values` (internal units, [`Robot::params`] order).
    pub fn set_values(&mut self, values: &[f64]) -> Result<()> {
        let ps = self.params();
        if ps.len() != values.len() {
            return Err(Error::invalid(
                "parameters",
                format!("{} values for {} parameters", values.len(), ps.len()),
            ));
        }
        for (p, v) in ps.into_iter().zip(values) {
            p.family().set(self, p, *v);
        }
        Ok(())
    }
}
