//! The sections of the report page, in order: the one list a new panel is added to.
//!
//! A section is a file with one function, `fn(&Page, &mut String) -> Result<bool>`, that writes
//! its `<section id="...">` (with an `<h2>`) and returns whether it wrote anything (a section
//! with nothing to show writes nothing and is left out of the navigation). Adding a panel is
//! writing that file and adding one line to [`SECTIONS`]. Sections use [`crate::page`], [`crate::markup`]
//! and the figure modules, never [`crate::html`], this list or each other.

use crate::page::Page;
use robocal_core::Result;

/// One section of the page.
pub struct Section {
    /// Its anchor (`id` of the `<section>`).
    pub id: &'static str,
    /// Its link text in the navigation.
    pub nav: &'static str,
    /// Writes the section; `Ok(false)` when it has nothing to show (and wrote nothing).
    pub render: fn(&Page, &mut String) -> Result<bool>,
}

/// The sections, in page order.
pub const SECTIONS: &[Section] = &[
    Section {
        id: "summary",
        nav: "Summary",
        render: crate::summary::section,
    },
    Section {
        id: "errors",
        nav: "Error statistics",
        render: crate::tables::errors_section,
    },
    Section {
        id: "orientation",
        nav: "Orientation",
        render: crate::orientation::section,
    },
    Section {
        id: "histogram",
        nav: "Histogram",
        render: crate::histogram_section::section,
    },
    Section {
        id: "components",
        nav: "x, y, z",
        render: crate::components::section,
    },
    Section {
        id: "workspace",
        nav: "Reach",
        render: crate::scatter::section,
    },
    Section {
        id: "joints",
        nav: "Joints",
        render: crate::joints::section,
    },
    Section {
        id: "map",
        nav: "Workspace map",
        render: crate::map::section,
    },
    Section {
        id: "iso9283",
        nav: "ISO 9283",
        render: crate::iso9283::section,
    },
    Section {
        id: "parameters",
        nav: "Parameters",
        render: crate::tables::parameters_section,
    },
    Section {
        id: "identification",
        nav: "Identifiability & solver",
        render: crate::identification::section,
    },
    Section {
        id: "settings",
        nav: "Settings",
        render: crate::tables::settings_section,
    },
    Section {
        id: "points",
        nav: "Points",
        render: crate::points_table::section,
    },
];

#[cfg(test)]
mod tests {
    #[test]
    fn ids_are_unique() {
        let mut ids: Vec<&str> = super::SECTIONS.iter().map(|s| s.id).collect();
        ids.sort_unstable();
        let n = ids.len();
        ids.dedup();
        assert_eq!(ids.len(), n);
    }
}
