//! The pipeline's third step: which parameters these poses identify (paper, section II.B),
//! including those independent in principle that the data cannot pin.

use super::shared::CandidateStart;
use super::start::StartModel;
use crate::error::{Error, Result};
use crate::identification::identifiability::{
    analyze_reduced, jacobian_r, FixReason, Identifiability, IdentifiabilityOptions,
    MAX_CONDITION_NUMBER,
};
use crate::identification::plausibility;
use crate::identification::precision;
use crate::identification::system::Problem;
use crate::model::Robot;
use crate::progress::{self, Observer};

/// The identifiable parameters, and why the covariance will be unavailable if it will.
pub(crate) struct Identified {
    /// Which parameters are identified, which fixed and why.
    pub identifiability: Identifiability,
    /// Set when the identified parameters are too nearly dependent for the covariance to have
    /// reliable digits (allowed only by `allow_ill_conditioned`).
    pub ill_conditioned: Option<String>,
    /// The full pass at the start model with the squared loss over the identified parameters,
    /// when the precision analysis computed it (a least-squares solve's first pass).
    pub start_pass: Option<crate::identification::system::Accumulated>,
}

/// Analyzes identifiability at the start model: rank and conditioning of the scaled Jacobian,
/// then the precision each parameter would have ([`precision::undetermined`]), fixing those the
/// data cannot determine. Fails when the problem is too ill-conditioned (unless allowed) or has
/// fewer points than parameters. `shared`: the reduced Jacobian and the precision pass taken
/// from a model selection's shared start (see [`super::shared`]) instead of computed.
pub(super) fn identifiable(
    nominal: &Robot,
    start: &StartModel,
    opts: &IdentifiabilityOptions,
    observer: &dyn Observer,
    shared: Option<CandidateStart>,
) -> Result<Identified> {
    observer.progress(progress::Stage::Identifiability, 0, 1);
    let cal = &start.observations;
    let own;
    let reduced = match &shared {
        Some(s) => &s.reduced,
        None => {
            own = jacobian_r(&start.robot, cal);
            &own
        }
    };
    let mut ident = analyze_reduced(&start.robot, cal, opts, reduced)?;
    let sigma0 = start.noise_bound();
    let analyzed = ident.identified.clone();
    let shared_pass = shared
        .as_ref()
        .filter(|_| sigma0 > 0.0 && sigma0.is_finite() && !analyzed.is_empty())
        .and_then(|s| s.pass(&analyzed));
    let (undetermined, pass) = match shared_pass {
        Some(acc) => (
            precision::undetermined_from(&start.robot, &analyzed, &acc, sigma0, &opts.free),
            Some(acc),
        ),
        None => precision::undetermined_keeping(
            &start.robot,
            &Problem::new(&start.robot, &analyzed, cal, &start.frame),
            sigma0,
            &opts.free,
        ),
    };
    if !undetermined.is_empty() {
        let mut opts = opts.clone();
        opts.fix.extend(undetermined.iter().map(|u| u.param));
        ident = analyze_reduced(&start.robot, cal, &opts, reduced)?;
        for f in &mut ident.fixed {
            if let Some(u) = undetermined.iter().find(|u| u.param == f.param) {
                f.reason = FixReason::Undetermined {
                    std: u.std,
                    limit: u.limit,
                };
            }
        }
    }
    let ill_conditioned = ill_conditioned(&ident);
    if let Some(why) = &ill_conditioned {
        if !ident.condition_number.is_finite() || !opts.allow_ill_conditioned {
            let hint = if plausibility::joints_look_like_radians(nominal, cal) {
                " (but first check the joint values: they all lie within ±2π while the joint \
                 limits span far more, as if they were radians)"
            } else {
                ""
            };
            return Err(Error::Numerical(format!(
                "{why}. Raise the rank tolerance above {:.1e} to fix it{hint}",
                ident.least_independent().map_or(0.0, |(_, i)| i)
            )));
        }
    }
    let k = ident.identified.len();
    if cal.len() < k {
        return Err(Error::Numerical(format!(
            "{} calibration points for {k} identifiable parameters: at least {k} points are \
             needed (the paper uses 75)",
            cal.len()
        )));
    }
    // The pass over the parameters finally identified, when they are among those analyzed.
    let cols: Option<Vec<usize>> = ident
        .identified
        .iter()
        .map(|p| analyzed.iter().position(|a| a == p))
        .collect();
    let start_pass = pass.zip(cols).map(|(pass, cols)| pass.restricted(&cols));
    Ok(Identified {
        identifiability: ident,
        ill_conditioned,
        start_pass,
    })
}

/// Why the identified parameters are too nearly dependent for double precision, if they are.
pub(super) fn ill_conditioned(ident: &Identifiability) -> Option<String> {
    ident.ill_conditioned().then(|| {
        let (p, ind) = ident
            .least_independent()
            .expect("analyze identifies at least one parameter");
        format!(
            "the identified parameters are too nearly dependent for double precision: the \
             condition number of their scaled Jacobian is {:.3e}, above {MAX_CONDITION_NUMBER:e}, \
             where the normal equations (condition {:.1e}) leave the estimates' uncertainty \
             without reliable digits; the least independent is {} ({ind:.1e}, rank tolerance \
             {:e})",
            ident.condition_number,
            ident.condition_number * ident.condition_number,
            p.name(),
            ident.rank_tolerance
        )
    })
}
