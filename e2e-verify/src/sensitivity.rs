//! The noise answers' sensitivity to the noise model's uncertainty (issue 35, item 2).
//!
//! A noise model's parameters come from a log (`allan` fits them with standard uncertainties)
//! or a datasheet; the answers move with them. For every output and every parameter with a
//! standard uncertainty $u_p$ ([`NoiseModel::uncertainty`]), the worst-position noise sigma
//! is evaluated with that parameter at $p - u_p$ and at $p + u_p$ (the others at their
//! values): the spread names the parameter the answer depends on most. The **pessimistic
//! corner** moves every parameter of every output by one uncertainty in the direction that
//! raised its output's sigma, the **optimistic corner** in the other; the shortest dwell at
//! which some table suffices ([`crate::NoiseQuestions::tradeoff`]) is given at both corners. This is a
//! stated propagation (one-at-a-time spreads and two corners of the $\pm1\,u$ box), not a
//! confidence interval of the answer.

use crate::error::E2eError;
use crate::noise::TradeoffInputs;
use calib_lsq::Timing;
use gw_model::noise::{NoiseModel, NoiseParameter};

/// One parameter's effect on its output's worst-position noise sigma.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct ParameterSpread {
    pub(crate) output: usize,
    pub(crate) parameter: NoiseParameter,
    pub(crate) value: f64,
    pub(crate) uncertainty: f64,
    pub(crate) sigma_minus: f64,
    pub(crate) sigma_plus: f64,
}

/// Read access to the fields.
impl ParameterSpread {
    /// The output's index.
    #[must_use]
    pub fn output(&self) -> usize {
        self.output
    }
    /// The parameter.
    #[must_use]
    pub fn parameter(&self) -> NoiseParameter {
        self.parameter
    }
    /// Its value, in its unit ([`NoiseParameter`]).
    #[must_use]
    pub fn value(&self) -> f64 {
        self.value
    }
    /// Its standard uncertainty, same unit.
    #[must_use]
    pub fn uncertainty(&self) -> f64 {
        self.uncertainty
    }
    /// The output's worst-position noise sigma with the parameter at value $- u$ (clipped at
    /// 0), output unit.
    #[must_use]
    pub fn sigma_minus(&self) -> f64 {
        self.sigma_minus
    }
    /// The same at value $+ u$, output unit.
    #[must_use]
    pub fn sigma_plus(&self) -> f64 {
        self.sigma_plus
    }
    /// $|\sigma_+ - \sigma_-|$, output unit.
    #[must_use]
    pub(crate) fn spread(&self) -> f64 {
        (self.sigma_plus - self.sigma_minus).abs()
    }
}

/// The answers at the noise parameters' $\pm 1\,u$ (see the [module](self)).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct NoiseSensitivity {
    pub(crate) nominal_sigma: Vec<Option<f64>>,
    pub(crate) spreads: Vec<ParameterSpread>,
    pub(crate) pessimistic_sigma: Vec<Option<f64>>,
    pub(crate) optimistic_sigma: Vec<Option<f64>>,
    pub(crate) min_dwell_pessimistic_s: Option<f64>,
    pub(crate) min_dwell_optimistic_s: Option<f64>,
}

/// Read access to the fields.
impl NoiseSensitivity {
    /// Each output's worst-position noise sigma at the parameters' values (`None`: no
    /// noise), output unit.
    #[must_use]
    pub fn nominal_sigma(&self) -> &[Option<f64>] {
        &self.nominal_sigma
    }
    /// Every parameter with an uncertainty, by output then [`NoiseParameter::ALL`]'s order.
    #[must_use]
    pub fn spreads(&self) -> &[ParameterSpread] {
        &self.spreads
    }
    /// The parameter output `k`'s sigma depends on most (largest spread), if any.
    #[must_use]
    pub fn dominant(&self, k: usize) -> Option<&ParameterSpread> {
        self.spreads
            .iter()
            .filter(|s| s.output == k)
            .max_by(|a, b| a.spread().total_cmp(&b.spread()))
    }
    /// Each output's sigma at the pessimistic corner, output unit.
    #[must_use]
    pub fn pessimistic_sigma(&self) -> &[Option<f64>] {
        &self.pessimistic_sigma
    }
    /// Each output's sigma at the optimistic corner, output unit.
    #[must_use]
    pub fn optimistic_sigma(&self) -> &[Option<f64>] {
        &self.optimistic_sigma
    }
    /// The shortest dwell at which some table suffices at the pessimistic corner, s
    /// (`None`: none in the range).
    #[must_use]
    pub fn min_dwell_pessimistic_s(&self) -> Option<f64> {
        self.min_dwell_pessimistic_s
    }
    /// The same at the optimistic corner, s.
    #[must_use]
    pub fn min_dwell_optimistic_s(&self) -> Option<f64> {
        self.min_dwell_optimistic_s
    }
}

impl<S: tt_kinematics::ScheduleErrorModel + Sync> crate::NoiseQuestions<'_, S> {
    /// Each output's worst-position noise sigma over `timing`, output unit (`None` where an
    /// output has no noise).
    ///
    /// # Errors
    /// As calib-lsq's `noise_covariances`.
    pub fn worst_noise_sigma(
        &self,
        noise: &[Option<NoiseModel>],
        timing: &Timing,
    ) -> Result<Vec<Option<f64>>, E2eError> {
        Ok(self
            .calibration()
            .noise_covariances(noise, timing)?
            .iter()
            .map(|c| {
                c.as_ref()
                    .map(|c| c.rate_error().sigma().iter().copied().fold(0.0, f64::max))
            })
            .collect())
    }

    /// The answers' sensitivity to the noise parameters' uncertainties (see the
    /// [module](self)); `None` when no parameter has one. The inputs are those of
    /// [`crate::NoiseQuestions::tradeoff`].
    ///
    /// # Errors
    /// As [`crate::NoiseQuestions::tradeoff`] and [`crate::NoiseQuestions::worst_noise_sigma`].
    pub fn noise_sensitivity(
        &self,
        inputs: &TradeoffInputs<'_>,
    ) -> Result<Option<NoiseSensitivity>, E2eError> {
        let (noise, timing) = (inputs.noise, inputs.timing);
        let nominal_sigma = self.worst_noise_sigma(noise, timing)?;
        let mut spreads = Vec::new();
        let mut pessimistic: Vec<Option<NoiseModel>> = noise.to_vec();
        let mut optimistic: Vec<Option<NoiseModel>> = noise.to_vec();
        for (k, model) in noise.iter().enumerate() {
            let Some(model) = model else { continue };
            for p in NoiseParameter::ALL {
                let (Some(lo), Some(hi)) = (model.perturbed(p, -1.0), model.perturbed(p, 1.0))
                else {
                    continue;
                };
                let sigma_of = |m: NoiseModel| -> Result<f64, E2eError> {
                    let mut one = vec![None; noise.len()];
                    one[k] = Some(m);
                    Ok(self.worst_noise_sigma(&one, timing)?[k].unwrap_or(0.0))
                };
                let (sigma_minus, sigma_plus) = (sigma_of(lo)?, sigma_of(hi)?);
                let up = if sigma_plus >= sigma_minus { 1.0 } else { -1.0 };
                for (corner, sign) in [(&mut pessimistic, up), (&mut optimistic, -up)] {
                    if let Some(m) = corner[k].as_ref().and_then(|m| m.perturbed(p, sign)) {
                        corner[k] = Some(m);
                    }
                }
                spreads.push(ParameterSpread {
                    output: k,
                    parameter: p,
                    value: model.value(p),
                    uncertainty: model.uncertainty(p),
                    sigma_minus,
                    sigma_plus,
                });
            }
        }
        if spreads.is_empty() {
            return Ok(None);
        }
        let dwell = |n: &[Option<NoiseModel>]| -> Result<Option<f64>, E2eError> {
            let corner = TradeoffInputs {
                noise: n,
                ..*inputs
            };
            Ok(self.tradeoff(&corner)?.min_dwell_s())
        };
        Ok(Some(NoiseSensitivity {
            nominal_sigma,
            spreads,
            pessimistic_sigma: self.worst_noise_sigma(&pessimistic, timing)?,
            optimistic_sigma: self.worst_noise_sigma(&optimistic, timing)?,
            min_dwell_pessimistic_s: dwell(&pessimistic)?,
            min_dwell_optimistic_s: dwell(&optimistic)?,
        }))
    }
}
