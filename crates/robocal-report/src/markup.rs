//! HTML pieces every section uses: key/value lines and figures with captions. Sections depend on
//! this module, never on each other or on the page ([`crate::html`]), so the page can list them.

use crate::escape::xml as esc;
use std::fmt::Write;

/// One `<dt>`/`<dd>` pair, escaped.
pub(crate) fn kv(h: &mut String, k: &str, v: &str) {
    let _ = writeln!(h, "<dt>{}</dt><dd>{}</dd>", esc(k), esc(v));
}

/// An SVG document without its XML declaration, for inlining.
pub(crate) fn strip_xml_decl(svg: &str) -> &str {
    match svg.strip_prefix("<?xml") {
        Some(rest) => rest.split_once("?>").map_or(svg, |(_, r)| r.trim_start()),
        None => svg,
    }
}

/// A `<figure>` with an inline SVG and its caption (escaped).
pub(crate) fn figure(h: &mut String, svg: &str, caption: &str) {
    let _ = write!(
        h,
        "<figure>\n{}<figcaption>{}</figcaption>\n</figure>\n",
        strip_xml_decl(svg),
        esc(caption)
    );
}
