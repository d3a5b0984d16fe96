//! Parameter identities, names and units.

pub use crate::unit::Unit;

/// One model parameter. Joint indices are 0-based here and 1-based in names (`Param::D(0)` is
/// `d1`). Frame-vector components are indexed 0..6 as `x, y, z, a, b, c`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Param {
    /// Twist alpha_i.
    Alpha(usize),
    /// Offset d_i.
    D(usize),
    /// Length a_i.
    A(usize),
    /// Joint offset phi_i.
    Phi(usize),
    /// Hayati tilt beta_i (only when enabled on the robot).
    Beta(usize),
    /// Component of the base frame vector B.
    Base(usize),
    /// Component of the tool correction T.
    Tool(usize),
}

const AXES: [&str; 6] = ["x", "y", "z", "a", "b", "c"];

impl Param {
    /// The DESIGN.md name: `alpha1`, `d3`, `base_x`, `tool_c`, ...
    pub fn name(self) -> String {
        match self {
            Param::Alpha(i) => format!("alpha{}", i + 1),
            Param::D(i) => format!("d{}", i + 1),
            Param::A(i) => format!("a{}", i + 1),
            Param::Phi(i) => format!("phi{}", i + 1),
            Param::Beta(i) => format!("beta{}", i + 1),
            Param::Base(k) => format!("base_{}", AXES[k]),
            Param::Tool(k) => format!("tool_{}", AXES[k]),
        }
    }

    /// Parses a name (the inverse of [`Param::name`]); `None` if it is not a parameter name.
    /// Whether the robot has that parameter is checked by `Robot::param_by_name`.
    pub fn parse(name: &str) -> Option<Param> {
        let name = name.trim();
        for (prefix, f) in [
            ("base_", Param::Base as fn(usize) -> Param),
            ("tool_", Param::Tool),
        ] {
            if let Some(ax) = name.strip_prefix(prefix) {
                return AXES.iter().position(|a| *a == ax).map(f);
            }
        }
        for (prefix, f) in [
            ("alpha", Param::Alpha as fn(usize) -> Param),
            ("beta", Param::Beta),
            ("phi", Param::Phi),
            ("d", Param::D),
            ("a", Param::A),
        ] {
            if let Some(num) = name.strip_prefix(prefix) {
                if num.is_empty() || !num.bytes().all(|b| b.is_ascii_digit()) {
                    continue;
                }
                return match num.parse::<usize>() {
                    Ok(i) if i >= 1 => Some(f(i - 1)),
                    _ => None,
                };
            }
        }
        None
    }

    /// The display unit of this parameter.
    pub fn unit(self) -> Unit {
        match self {
            Param::D(_) | Param::A(_) => Unit::Mm,
            Param::Alpha(_) | Param::Phi(_) | Param::Beta(_) => Unit::Deg,
            Param::Base(k) | Param::Tool(k) => {
                if k < 3 {
                    Unit::Mm
                } else {
                    Unit::Deg
                }
            }
        }
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
            Param::Alpha(0),
            Param::D(5),
            Param::A(2),
            Param::Phi(6),
            Param::Beta(1),
            Param::Base(0),
            Param::Base(5),
            Param::Tool(3),
        ];
        for p in all {
            assert_eq!(Param::parse(&p.name()), Some(p), "{}", p.name());
        }
        assert_eq!(Param::parse("d0"), None);
        assert_eq!(Param::parse("base_q"), None);
        assert_eq!(Param::parse("alpha"), None);
        assert_eq!(Param::parse("x1"), None);
        assert_eq!(Param::parse("a1x"), None);
    }
}
