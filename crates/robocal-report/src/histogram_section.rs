//! The "Histogram" section: the error histogram before and after calibration (the paper's
//! Fig. 2, drawn by [`crate::histogram`]) with a caption that states its binning rule.

use crate::page::Page;
use robocal_core::Result;

/// The histogram section of the page.
pub(crate) fn section(page: &Page, h: &mut String) -> Result<bool> {
    let (data, fig) = (page.data, page.histogram);
    h.push_str("<section id=\"histogram\">\n<h2>Distribution of the displacement error</h2>\n");

    let mut cap = String::from(
        "Histogram of the displacement error before and after calibration (cf. the paper’s \
         Fig. 2). Bars: number of points per bin; dashed lines: means.",
    );
    for n in fig.notes(&data.histogram) {
        cap.push(' ');
        cap.push_str(&n);
    }
    crate::markup::figure(h, &fig.svg, &cap);
    h.push_str("</section>\n");
    Ok(true)
}
