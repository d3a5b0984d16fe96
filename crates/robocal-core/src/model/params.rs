//! Parameter identities, names and units.
//!
//! A [`Param`] is an open identity: the [family](crate::model::family) it belongs to, which of the
//! family's name templates it instantiates, and an index (a 0-based joint, or a frame-vector
//! component `x, y, z, a, b, c` = 0..6). Its name and unit come from the family, so a new family
//! adds its parameters without touching this file.

use crate::model::family::{self, FamilyId, ParameterFamily};
pub use crate::unit::Unit;

/// One model parameter. Joint indices are 0-based here and 1-based in names (`Param::d(0)` is
/// `d1`). Frame-vector components are indexed 0..6 as `x, y, z, a, b, c`.
///
/// Ordered by family (in [`family::all`] order), then template, then index: the order of
/// [`Robot::params`](crate::model::Robot::params).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Param {
    family: FamilyId,
    template: u8,
    index: u16,
}

impl Param {
    /// The parameter of `family` that instantiates its template number `template` at `index`.
    /// For family implementations; users name parameters with [`Param::parse`] or the shorthands
    /// below.
    pub const fn new(family: FamilyId, template: u8, index: u16) -> Param {
        Param {
            family,
            template,
            index,
        }
    }

    /// Twist alpha_i (joint `i`, 0-based).
    pub const fn alpha(i: usize) -> Param {
        family::link::param(family::link::ALPHA, i)
    }

    /// Offset d_i.
    pub const fn d(i: usize) -> Param {
        family::link::param(family::link::D, i)
    }

    /// Length a_i.
    pub const fn a(i: usize) -> Param {
        family::link::param(family::link::A, i)
    }

    /// Joint offset phi_i.
    pub const fn phi(i: usize) -> Param {
        family::link::param(family::link::PHI, i)
    }

    /// Hayati tilt beta_i (a parameter only when enabled on the robot).
    pub const fn beta(i: usize) -> Param {
        family::beta::param(i)
    }

    /// Component `k` (0..6 = x, y, z, a, b, c) of the base frame vector B.
    pub const fn base(k: usize) -> Param {
        family::base::param(k)
    }

    /// Component `k` (0..6 = x, y, z, a, b, c) of the tool correction T.
    pub const fn tool(k: usize) -> Param {
        family::tool::param(k)
    }

    /// The family this parameter belongs to.
    pub fn family(self) -> &'static dyn ParameterFamily {
        family::get(self.family)
    }

    /// The family's identity.
    pub fn family_id(self) -> FamilyId {
        self.family
    }

    /// Which of the family's name templates this parameter instantiates.
    pub fn template(self) -> usize {
        self.template as usize
    }

    /// The index: a 0-based joint, or a frame-vector component (0..6).
    pub fn index(self) -> usize {
        self.index as usize
    }

    /// The DESIGN.md name: `alpha1`, `d3`, `base_x`, `tool_c`, ...
    pub fn name(self) -> String {
        let template = self.family().templates().get(self.template()).copied();
        family::instantiate(template.unwrap_or("?{j}"), self.index())
    }

    /// Parses a name (the inverse of [`Param::name`]) against every family's templates; `None` if
    /// it is not a parameter name. Whether the robot has that parameter is checked by
    /// `Robot::param_by_name`.
    pub fn parse(name: &str) -> Option<Param> {
        let name = name.trim();
        family::all().iter().enumerate().find_map(|(f, fam)| {
            fam.templates()
                .iter()
                .enumerate()
                .find_map(|(t, tpl)| family::match_template(tpl, name).map(|i| (t, i)))
                .and_then(|(t, i)| {
                    Some(Param::new(
                        FamilyId::new(f),
                        u8::try_from(t).ok()?,
                        u16::try_from(i).ok()?,
                    ))
                })
        })
    }

    /// The display unit of this parameter.
    pub fn unit(self) -> Unit {
        self.family().unit(self)
    }
}

impl std::fmt::Display for Param {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_roundtrip() {
        let all = [
            Param::alpha(0),
            Param::d(5),
            Param::a(2),
            Param::phi(6),
            Param::beta(1),
            Param::base(0),
            Param::base(5),
            Param::tool(3),
        ];
        for p in all {
            assert_eq!(Param::parse(&p.name()), Some(p), "{}", p.name());
        }
        assert_eq!(Param::parse("d0"), None);
        assert_eq!(Param::parse("base_q"), None);
        assert_eq!(Param::parse("alpha"), None);
        assert_eq!(Param::parse("x1"), None);
        assert_eq!(Param::parse("a1x"), None);
        assert_eq!(Param::parse("d+1"), None);
        assert_eq!(Param::parse("d99999999"), None);
    }

    #[test]
    fn names_and_units_of_the_geometric_families() {
        assert_eq!(Param::alpha(0).name(), "alpha1");
        assert_eq!(Param::d(2).name(), "d3");
        assert_eq!(Param::beta(1).name(), "beta2");
        assert_eq!(Param::base(3).name(), "base_a");
        assert_eq!(Param::tool(2).name(), "tool_z");
        assert_eq!(Param::d(0).unit(), Unit::Mm);
        assert_eq!(Param::phi(0).unit(), Unit::Deg);
        assert_eq!(Param::base(2).unit(), Unit::Mm);
        assert_eq!(Param::tool(5).unit(), Unit::Deg);
    }

    /// Sorting follows the model order: families, then templates, then indices.
    #[test]
    fn order_is_the_model_order() {
        let mut v = vec![
            Param::tool(0),
            Param::base(5),
            Param::beta(2),
            Param::phi(0),
            Param::a(3),
            Param::d(1),
            Param::alpha(4),
        ];
        v.sort();
        assert_eq!(
            v,
            vec![
                Param::alpha(4),
                Param::d(1),
                Param::a(3),
                Param::phi(0),
                Param::beta(2),
                Param::base(5),
                Param::tool(0),
            ]
        );
    }
}
