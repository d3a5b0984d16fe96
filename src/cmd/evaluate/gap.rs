//! A verification's gap to the calibration's prediction, split in quadrature (RMS error norms)
//! into what the fresh tracker station's registration adds (with `--refit-frame`), what is left
//! for the cell's conditions the model lacks or that changed since the calibration, and the
//! repeatability's size beside the prediction's noise, which already holds it (see
//! [`robocal_core::evaluation::gap`]). What the model's condition families explain (the data's
//! temperature, approach directions) is printed beside it by `conditions`.

use robocal_core::evaluation::gap::Gap;

/// Prints the split.
pub(super) fn print(g: &Gap) -> anyhow::Result<()> {
    outln!(
        "the gap to the prediction, in quadrature (RMS error norm): verification {:.4} mm, \
         predicted {:.4} mm, gap {:.4} mm, of which",
        g.verified_rms_mm,
        g.predicted_rms_mm,
        g.total_mm()
    )?;
    if let Some(s) = &g.station {
        outln!(
            "  {:.4} mm  the fresh station's registration ({} points, residual {:.4} mm per axis: \
             sigma sqrt(6/n))",
            s.rms_mm,
            s.points,
            s.residual_sigma_mm
        )?;
    }
    outln!(
        "  {:.4} mm  left: the conditions the model lacks or that changed since the calibration \
         (temperature, approach directions, load, ...)",
        g.left_mm()
    )?;
    outln!(
        "repeatability ({}): {:.4} mm RMS at these poses, inside the prediction's noise ({:.4} mm \
         RMS): the calibration's residuals hold it",
        g.repeatability_source,
        g.repeatability_mm,
        g.predicted_noise_mm
    )?;
    Ok(())
}
