//! End to end with errors that vary with a shaft angle (issue 22): the calibration sees a
//! different error at each test position.
//!
//! The turntable's errors are expanded into coefficients ([`tt_kinematics::Expansion`]: one
//! group per error, constant, harmonics of a joint or any function of it). To first order the
//! error vectors are linear in the coefficients, $\Delta\hat{\boldsymbol\omega} \approx
//! \mathbf M_c\,c$ ([`crate::AngleQuestions::linearization_expanded`], one column per coefficient: the
//! error's first-order effect at each position scaled by the coefficient's basis value there).
//! The worst case of a row $r$ over the bounds $\lvert\chi_j(\phi)\rvert \le \mathrm{UB}_j$ is
//! $\sum_j \mathrm{UB}_j\,d_j(\mathbf M_{c,rj})$ with $d_j$ the dual norm of error $j$'s bound
//! set. The *reduced* linearisation holds $d_j(\mathbf M_{c,rj})$ in place of $\lvert
//! M_{rj}\rvert$ ([`AngleLinearization::reduced`]): every computation that uses only $\lvert
//! M\rvert$ (row worst cases, the direct and the certified allocation) takes it unchanged.
//! When every error is constant the reduced matrix is $\lvert\mathbf M\rvert$ exactly.
//!
//! The second-order bound $\tau_k(s)$, $s = \sum_j\mathrm{UB}_j$
//! ([`EndToEnd::second_order_bound`]) bounds the remainder per position from the size of the
//! rotation there, $\lvert\boldsymbol\delta_i\rvert \le \sum_j\lvert\chi_j(\phi_i)\rvert \le s$,
//! which holds whatever the errors do between positions: the linear bound plus $\tau$ stays a
//! rigorous bound of the exact chain.

use crate::error::E2eError;
use crate::linear::{DerivativeTerms, Linearization, directional, rounding_level};
use crate::simulate::EndToEnd;
use calib_lsq::ReadingWork;
use nalgebra::{DMatrix, Vector3};
use rand_core::Rng;
use tt_kinematics::{Expansion, LinearModel};

/// The first-order model in the coefficients and its reduction to one column per error.
#[derive(Debug, Clone, PartialEq)]
pub struct AngleLinearization {
    /// $\mathbf M_c$: rows output-major as [`Linearization`], one column per coefficient.
    pub expanded: Linearization,
    /// $d_j(\mathbf M_{c,rj})$: rows as above, one non-negative column per error.
    pub reduced: Linearization,
}

/// The worst case of one output over the bounds under the angle-dependent model
/// ([`crate::AngleQuestions::angle_worst_case`]): `linear_bound` is $\max_r \sum_j \mathrm{UB}_j\,d_j$
/// over the output's rows, rigorous for the linearised model (harmonic dual norms are
/// certified upper bounds); `exact_at_vertex` the exact chain at $\pm$ the worst
/// coefficients found (a turntable within the bounds, so a lower bound of the exact worst
/// case).
pub type AngleOutputWorstCase = crate::OutputWorstCase<AngleDetail>;

/// What the worst case under the angle-dependent model adds ([`AngleOutputWorstCase`]).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[non_exhaustive]
pub struct AngleDetail {
    /// The same with every error constant (the paper's model) and the same bounds.
    pub(crate) constant_linear_bound: f64,
    /// The worst coefficients found (rad; the expansion's order).
    pub(crate) worst_coefficients: Vec<f64>,
    /// $\tau$ ([`EndToEnd::second_order_bound`]); `None` for readings without one.
    pub(crate) second_order_bound: Option<f64>,
    /// The verdict against the output's accuracy, as [`crate::Verdict`].
    pub(crate) verdict: crate::Verdict,
}

/// Read access to the angle-dependent model's data.
impl AngleOutputWorstCase {
    /// The linear bound with every error constant (the paper's model) and the same bounds.
    #[must_use]
    pub fn constant_linear_bound(&self) -> f64 {
        self.detail.constant_linear_bound
    }

    /// The worst coefficients found (rad; the expansion's order).
    #[must_use]
    pub fn worst_coefficients(&self) -> &[f64] {
        &self.detail.worst_coefficients
    }

    /// $\tau$ ([`EndToEnd::second_order_bound`]); `None` for readings without one.
    #[must_use]
    pub fn second_order_bound(&self) -> Option<f64> {
        self.detail.second_order_bound
    }

    /// The verdict against the output's accuracy, as [`crate::Verdict`].
    #[must_use]
    pub fn verdict(&self) -> crate::Verdict {
        self.detail.verdict
    }
}

/// The yield of a Monte Carlo over turntables with angle-dependent errors: its count (only
/// all outputs together are counted) and the worst ratio drawn.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct AngleYield {
    /// The turntables drawn, their seed and those meeting every output's accuracy.
    pub(crate) count: crate::YieldCount,
    /// Largest $\max_k \Delta\omega_k/\omega_{m,k}$ drawn.
    pub(crate) worst_ratio: f64,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl AngleYield {
    /// The turntables drawn, their seed and those meeting every output's accuracy (the
    /// fraction and its 95% interval).
    #[must_use]
    pub fn count(&self) -> &crate::YieldCount {
        &self.count
    }

    /// Largest $\max_k \Delta\omega_k/\omega_{m,k}$ drawn.
    #[must_use]
    pub fn worst_ratio(&self) -> f64 {
        self.worst_ratio
    }
}

/// The dual norm of a magnitude (disc) bound $\sqrt{\chi_a(\phi)^2 + \chi_b(\phi)^2} \le 1$
/// on two errors at the functional `s` (the expansion's coefficients): both constant,
/// $\lVert(s_a, s_b)\rVert_2$; both `any` of the same joint, $\sum_{\text{angles}}
/// \lVert(s_{a,k}, s_{b,k})\rVert_2$; otherwise the square's $d_a + d_b$ (the disc lies in the
/// square, so this is a rigorous, conservative bound).
/// (A harmonic pair is bounded tighter by [`crate::disc::PairModel`], which has the schedule's
/// angles: [`crate::disc::disc_dual`].)
#[must_use]
pub fn disc_dual_norm(expansion: &Expansion, s: &[f64], a: usize, b: usize) -> f64 {
    crate::disc::disc_dual(expansion, s, None, a, b).upper
}

/// The linearised worst case of every output (output unit) over the bounds `ub_rad` with the
/// magnitude bounds `discs` (`(errors, w)`, rad): $\max_r \sum_{j \notin \text{discs}}
/// \mathrm{UB}_j d_j + \sum_{\text{discs}} w\,D(s_r)$ ([`disc_dual_norm`]), `expanded` the
/// expansion's linearisation.
#[must_use]
pub fn disc_worst_case(
    expansion: &Expansion,
    expanded: &Linearization,
    ub_rad: &[f64],
    discs: &[([usize; 2], f64)],
) -> Vec<f64> {
    let n = expanded.positions();
    (0..expanded.outputs())
        .map(|k| {
            (0..n)
                .map(|i| {
                    let s = expanded.row(k, i);
                    let d = expansion.dual_norms(&s);
                    let mut in_disc = vec![false; d.len()];
                    let mut total = 0.0;
                    for &([a, b], w) in discs {
                        in_disc[a] = true;
                        in_disc[b] = true;
                        total += w * disc_dual_norm(expansion, &s, a, b);
                    }
                    total
                        + d.iter()
                            .zip(ub_rad)
                            .zip(&in_disc)
                            .filter(|(_, skip)| !**skip)
                            .map(|((d, u), _)| if u.is_finite() { d * u } else { 0.0 })
                            .sum::<f64>()
                })
                .fold(0.0, f64::max)
        })
        .collect()
}

/// The box that matters once measured errors are compensated: each measured error's bound
/// replaced by its measurement uncertainty (`uncertainty_rad[j]`, `None` where not measured),
/// $\lvert\chi_j(\phi) - m_j(\phi)\rvert \le u_j$.
#[must_use]
pub fn compensated_box(ub_rad: &[f64], uncertainty_rad: &[Option<f64>]) -> Vec<f64> {
    ub_rad
        .iter()
        .zip(uncertainty_rad)
        .map(|(u, m)| m.unwrap_or(*u))
        .collect()
}

impl crate::AngleQuestions<'_> {
    /// $\Delta\omega_k$ of every output (output unit) for a compensated calibration: the lab
    /// has measured the errors (coefficients `measured` of `expansion`) and takes the
    /// orientation they give, $\mathbf R_t(m(\phi_i))$, as known; the table's true errors are
    /// `actual`. The calibration sees the residual rotation $\mathbf R_t(m)^T\mathbf
    /// R_t(\chi)$ at each position (exact chains, reference path). The regression keeps the
    /// nominal poses (their change by $m$ acts on the residual at second order,
    /// $O(\lvert m\rvert\,\lvert\chi - m\rvert)$). With $m = \chi$ the residual is the identity
    /// and the calibration error vanishes; to first order it is the uncompensated error of
    /// $\chi - m$, so the box that matters is the measurement's uncertainty
    /// ([`compensated_box`]).
    ///
    /// # Errors
    /// Lengths, non-finite values; as [`EndToEnd::run_with_delta_r`].
    pub fn delta_omega_compensated(
        &self,
        expansion: &Expansion,
        measured: &[f64],
        actual: &[f64],
    ) -> Result<Vec<f64>, E2eError> {
        check_expansion(self, expansion)?;
        let zero = vec![0.0; self.turntable().n_translation_errors()];
        let dr = self
            .poses()
            .iter()
            .enumerate()
            .map(|(i, pose)| {
                let m = expansion.errors_at(measured, i, &zero)?;
                let x = expansion.errors_at(actual, i, &zero)?;
                let rm =
                    self.turntable()
                        .actual_rotation(pose, &m, tt_kinematics::ChainKind::Exact)?;
                let rx =
                    self.turntable()
                        .actual_rotation(pose, &x, tt_kinematics::ChainKind::Exact)?;
                Ok(rm.transpose() * rx)
            })
            .collect::<Result<Vec<_>, tt_kinematics::KinematicsError>>()?;
        Ok(self.run_with_delta_r(&dr)?.delta_omega())
    }
}

/// Draws per random stream of [`crate::AngleQuestions::angle_yield`] (chunk $c$ uses
/// [`mc_verify::chunk_rng`]`(seed, c)`; fixed, so results do not depend on the thread count).
pub(crate) const ANGLE_CHUNK: u64 = 1024;
/// Chunks of the angle-dependent Monte Carlo evaluated per wave (memory: one wave's counts).
const ANGLE_WAVE_CHUNKS: u64 = 64;

/// Largest first-order model in the coefficients ([`crate::AngleQuestions::expanded_values`]): $2.5\times
/// 10^7$ values, 200 MB. An `any` error has one coefficient per distinct angle of its shaft,
/// so the model grows as positions times distinct angles: 10,000 positions on a grid of 100
/// angles per shaft fit (the paper's table: $2 \times 10^4 \times 602$), about 1,400 at
/// distinct angles.
pub const MAX_EXPANDED_VALUES: usize = 25_000_000;

pub(crate) fn check_expansion(e2e: &EndToEnd, e: &Expansion) -> Result<(), E2eError> {
    tt_core::length("expansion positions", e2e.len(), e.positions())
        .and_then(|()| tt_core::length("expansion errors", e2e.n_errors(), e.groups().len()))
        .map_err(|err| E2eError::Kinematics(err.into()))
}

impl crate::AngleQuestions<'_> {
    /// The values of the first-order model in the coefficients of `expansion`
    /// ([`crate::AngleQuestions::linearization_expanded`]): outputs times positions times coefficients
    /// (at most [`MAX_EXPANDED_VALUES`] is meant to be formed).
    #[must_use]
    pub fn expanded_values(&self, expansion: &Expansion) -> usize {
        self.n_outputs()
            .saturating_mul(self.len())
            .saturating_mul(expansion.n_coefficients())
    }

    /// The Jacobian $\mathbf M_c$ of the error vectors with respect to the coefficients of
    /// `expansion` at zero: column $(j, c)$ is the analytic column of error $j$
    /// ([`EndToEnd::linearization`]) with the error's first-order effect at position $i$
    /// scaled by the coefficient's basis value $b_{jc}(\phi_i)$. For a constant error it is
    /// that column exactly.
    ///
    /// # Errors
    /// A length error when the expansion is not of this schedule and turntable.
    pub fn linearization_expanded(&self, expansion: &Expansion) -> Result<Linearization, E2eError> {
        check_expansion(self, expansion)?;
        let model = LinearModel::new(self.turntable());
        let n = self.len();
        let outputs = self.n_outputs();
        let vectors: Vec<Vec<Vector3<f64>>> = self
            .poses()
            .iter()
            .map(|p| model.rotation_vectors(p))
            .collect::<Result<_, _>>()?;
        let nc = expansion.n_coefficients();
        let mut m = DMatrix::zeros(outputs * n, nc);
        let mut noise = DMatrix::zeros(outputs, nc);
        let mut work = ReadingWork::default();
        let mut col = vec![0.0; n];
        for (k, cal) in self.calibration().outputs().iter().enumerate() {
            let o = cal.output();
            for g in expansion.groups() {
                let j = g.error;
                let (mut de, mut dg) = (Vec::with_capacity(n), Vec::with_capacity(n));
                for (i, u) in cal.nominal_values().iter().enumerate() {
                    let delta = vectors[i][j];
                    let da = u.specific_force_g().cross(&delta);
                    let dw = u.rate_deg_per_h().cross(&delta);
                    let du = [da.x, da.y, da.z, dw.x, dw.y, dw.z];
                    de.push(directional(o, true, u, &du));
                    dg.push(directional(o, false, u, &du));
                }
                for (c, basis) in g.basis.iter().enumerate() {
                    let scale = |v: &[f64]| -> Vec<f64> {
                        v.iter().zip(basis).map(|(a, b)| a * b).collect()
                    };
                    let (de_c, dg_c) = (scale(&de), scale(&dg));
                    noise[(k, g.first + c)] =
                        rounding_level(&de_c, &dg_c, cal.regression().condition_number());
                    let terms = DerivativeTerms {
                        a: cal.regression().matrix(),
                        pinv: cal.regression().pinv(),
                        de: de_c,
                        dg: dg_c,
                    };
                    self.reading().error_vector(&terms, &mut work, &mut col);
                    for (i, v) in col.iter().enumerate() {
                        m[(k * n + i, g.first + c)] = *v;
                    }
                }
            }
        }
        Ok(Linearization::from_parts(m, n, outputs, noise))
    }

    /// The expanded and the reduced linearisation (see the [module](self)). The rounding
    /// level of a reduced entry is that of the group's coefficients summed, twice (a dual norm
    /// is at most $\lvert s_0\rvert + 2\sum_{k\ge1}\lvert s_k\rvert$).
    ///
    /// # Errors
    /// As [`crate::AngleQuestions::linearization_expanded`].
    pub fn angle_linearization(
        &self,
        expansion: &Expansion,
    ) -> Result<AngleLinearization, E2eError> {
        let expanded = self.linearization_expanded(expansion)?;
        Ok(self.reduce_expanded(expansion, expanded))
    }

    /// The reduction of an expanded model to one column per error (dual norms; see
    /// [`crate::AngleQuestions::angle_linearization`]).
    pub(crate) fn reduce_expanded(
        &self,
        expansion: &Expansion,
        expanded: Linearization,
    ) -> AngleLinearization {
        let (rows, errors) = (expanded.matrix().nrows(), expansion.groups().len());
        let mut reduced = DMatrix::zeros(rows, errors);
        for r in 0..rows {
            let s: Vec<f64> = expanded.matrix().row(r).iter().copied().collect();
            for (j, d) in expansion.dual_norms(&s).into_iter().enumerate() {
                reduced[(r, j)] = d;
            }
        }
        let mut noise = DMatrix::zeros(self.n_outputs(), errors);
        for k in 0..self.n_outputs() {
            for g in expansion.groups() {
                let sum: f64 = (g.first..g.first + g.len())
                    .map(|c| expanded.rounding()[(k, c)])
                    .sum();
                noise[(k, g.error)] = if g.len() == 1 { sum } else { 2.0 * sum };
            }
        }
        let reduced = Linearization::from_parts(reduced, self.len(), self.n_outputs(), noise);
        AngleLinearization { expanded, reduced }
    }

    /// $\Delta\omega_k$ of every output (output unit) for the coefficients `c` of
    /// `expansion`, on the exact chain (segmented, per position at $\chi(\phi_i)$).
    ///
    /// # Errors
    /// As [`EndToEnd::delta_omega_into`]; a length error.
    pub fn delta_omega_expanded(
        &self,
        expansion: &Expansion,
        c: &[f64],
        work: &mut crate::DrawWork,
    ) -> Result<(), E2eError> {
        check_expansion(self, expansion)?;
        tt_core::length("coefficients", expansion.n_coefficients(), c.len())
            .map_err(|err| E2eError::Kinematics(err.into()))?;
        let mut chi = vec![0.0; self.n_errors()];
        self.delta_omega_varying_into(|i, x| expansion.chi_at(c, i, x), &mut chi, work)
    }

    /// The worst case of every output over the bounds `ub_rad` (one per error, over the whole
    /// revolution) under the angle-dependent model, beside the constant model's linear worst
    /// case, with a verdict as [`crate::VendorQuestions::check_tolerances`] gives: fails when the exact chain
    /// at the worst coefficients misses the accuracy, guaranteed when the linear bound plus
    /// $\tau$ meets it, likely otherwise.
    ///
    /// # Errors
    /// Bad bounds (as [`EndToEnd::worst_case`]); as [`crate::AngleQuestions::delta_omega_expanded`].
    pub fn angle_worst_case(
        &self,
        expansion: &Expansion,
        al: &AngleLinearization,
        constant: &Linearization,
        ub_rad: &[f64],
    ) -> Result<Vec<AngleOutputWorstCase>, E2eError> {
        self.check_bounds(&al.reduced, ub_rad)?;
        let rows = al.reduced.row_worst_cases(ub_rad);
        let const_rows = constant.row_worst_cases(ub_rad);
        let n = self.len();
        let s: f64 = ub_rad.iter().filter(|u| u.is_finite()).sum();
        let acc = self.accuracies();
        let mut work = self.work();
        let mut out = Vec::with_capacity(self.n_outputs());
        for k in 0..self.n_outputs() {
            let precision = self.precisions()[k];
            let (position, bound) = (0..n)
                .map(|i| (i, rows[k * n + i]))
                .fold((0, f64::NEG_INFINITY), |b, v| if v.1 > b.1 { v } else { b });
            let const_bound = (0..n).map(|i| const_rows[k * n + i]).fold(0.0, f64::max);
            let row: Vec<f64> = al.expanded.row(k, position);
            let c = expansion.worst_point(&row, ub_rad);
            self.delta_omega_expanded(expansion, &c, &mut work)?;
            let plus = work.delta_omega[k];
            let neg: Vec<f64> = c.iter().map(|v| -v).collect();
            self.delta_omega_expanded(expansion, &neg, &mut work)?;
            let minus = work.delta_omega[k];
            let exact = crate::resolved(plus.max(minus), precision);
            let tau = self.second_order_bound(k, s)?;
            let linear_bound = crate::resolved(bound, precision);
            let verdict = if exact > acc[k] {
                crate::Verdict::Fails
            } else {
                match tau {
                    Some(t) if linear_bound + t <= acc[k] => crate::Verdict::Guaranteed,
                    _ => crate::Verdict::Likely,
                }
            };
            out.push(AngleOutputWorstCase {
                output: k,
                linear_bound,
                position,
                exact_at_vertex: exact,
                detail: AngleDetail {
                    constant_linear_bound: crate::resolved(const_bound, precision),
                    worst_coefficients: if plus >= minus { c } else { neg },
                    second_order_bound: tau,
                    verdict,
                },
            });
        }
        Ok(out)
    }

    /// Monte Carlo of the exact chain over turntables whose errors vary with the shaft angle,
    /// drawn inside the bounds by [`Expansion::draw`] (its law), `samples` turntables from
    /// `seed`: the yield against every accuracy. Chunks of [`ANGLE_CHUNK`] draws, chunk $c$
    /// from [`mc_verify::chunk_rng`]`(seed, c)`, run on rayon threads and summed in chunk
    /// order: identical for any thread count; memory independent of `samples`.
    ///
    /// # Errors
    /// As [`crate::AngleQuestions::delta_omega_expanded`]; bad bounds.
    pub fn angle_yield(
        &self,
        expansion: &Expansion,
        ub_rad: &[f64],
        samples: u64,
        seed: u64,
    ) -> Result<AngleYield, E2eError> {
        self.angle_yield_with_discs(expansion, ub_rad, &[], samples, seed)
    }

    /// [`crate::AngleQuestions::angle_yield`] with each pair `discs[i] = (errors, w)` (rad) drawn inside
    /// its disc ([`Expansion::draw_with_discs`]); with no disc it is
    /// [`crate::AngleQuestions::angle_yield`] exactly. Same chunks and streams: identical for any thread
    /// count.
    ///
    /// # Errors
    /// As [`crate::AngleQuestions::angle_yield`].
    pub fn angle_yield_with_discs(
        &self,
        expansion: &Expansion,
        ub_rad: &[f64],
        discs: &[([usize; 2], f64)],
        samples: u64,
        seed: u64,
    ) -> Result<AngleYield, E2eError> {
        check_expansion(self, expansion)?;
        let acc = self.accuracies();
        let ub: Vec<f64> = ub_rad
            .iter()
            .map(|u| if u.is_finite() { *u } else { 0.0 })
            .collect();
        let chunks = samples.div_ceil(ANGLE_CHUNK);
        let chunk = |chunk: u64| -> Result<(u64, u64, f64), E2eError> {
            let mut rng = mc_verify::chunk_rng(seed, chunk);
            let mut uniform = move || (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64);
            let mut work = self.work();
            let mut c = vec![0.0; expansion.n_coefficients()];
            let mut chi = vec![0.0; self.n_errors()];
            let count = ANGLE_CHUNK.min(samples - chunk * ANGLE_CHUNK);
            let (mut meeting, mut worst) = (0, 0.0_f64);
            for _ in 0..count {
                expansion.draw_with_discs(&ub, discs, &mut uniform, &mut c);
                self.delta_omega_varying_into(
                    |i, x| expansion.chi_at(&c, i, x),
                    &mut chi,
                    &mut work,
                )?;
                let ratio = work
                    .delta_omega
                    .iter()
                    .zip(&acc)
                    .map(|(v, a)| v / a)
                    .fold(0.0, f64::max);
                if ratio <= 1.0 {
                    meeting += 1;
                }
                worst = worst.max(ratio);
            }
            Ok((count, meeting, worst))
        };
        // sums of counts and a maximum, merged in chunk order: any thread count agrees
        let (mut n, mut meeting, mut worst) = (0, 0, 0.0_f64);
        mc_verify::driver::run_chunks(chunks, ANGLE_WAVE_CHUNKS, chunk, |(c, m, w)| {
            n += c;
            meeting += m;
            worst = worst.max(w);
            Ok(())
        })?;
        Ok(AngleYield {
            count: crate::YieldCount::new(n, seed, meeting, Vec::new()),
            worst_ratio: worst,
        })
    }
}

impl crate::AngleQuestions<'_> {
    /// The direct allocation once measured errors are compensated: error $j$ with
    /// `fixed_rad[j] = Some(u_j)` is held at its measurement uncertainty ($\mathrm{UB}_j =
    /// u_j$, the bound that then matters), the others are allocated what remains. Each output
    /// keeps free the largest load of the fixed errors over its rows, $\max_r \sum_{j\,
    /// \text{fixed}} \lvert M_{rj}\rvert u_j$ (conservative: a row with a smaller fixed load
    /// gets no more), and the free errors are allocated as [`EndToEnd::allocate_direct`] does
    /// on the matrix without the fixed columns. The returned bounds hold $u_j$ for the fixed
    /// errors; the objective is that of the free errors. `Ok(Err(..))` when the fixed errors
    /// alone leave an output no room.
    ///
    /// # Errors
    /// As [`EndToEnd::allocate_direct`]; a length error.
    pub fn allocate_direct_compensated(
        &self,
        linear: &Linearization,
        lower_bounds_rad: &[f64],
        fixed_rad: &[Option<f64>],
    ) -> Result<Result<crate::DirectAllocation, Vec<crate::NoRoom>>, E2eError> {
        tt_core::length("measured errors", self.n_errors(), fixed_rad.len())
            .map_err(|e| E2eError::Kinematics(e.into()))?;
        let fixed_ub: Vec<f64> = fixed_rad.iter().map(|u| u.unwrap_or(0.0)).collect();
        let loads = linear.row_worst_cases(&fixed_ub);
        let n = self.len();
        let margins: Vec<f64> = (0..self.n_outputs())
            .map(|k| loads.rows(k * n, n).max())
            .collect();
        let mut m = linear.matrix().clone();
        let mut noise = linear.rounding().clone();
        let mut lb = lower_bounds_rad.to_vec();
        for (j, u) in fixed_rad.iter().enumerate() {
            if u.is_some() {
                m.column_mut(j).fill(0.0);
                noise.column_mut(j).fill(0.0);
                if let Some(l) = lb.get_mut(j) {
                    *l = 0.0;
                }
            }
        }
        let free = Linearization::from_parts(m, n, self.n_outputs(), noise);
        let blocked = self.noise().no_room(&free, &lb, &margins);
        if !blocked.is_empty() {
            return Ok(Err(blocked));
        }
        let mut d = self.allocate_direct_keeping(&free, &lb, &margins)?;
        for (j, u) in fixed_rad.iter().enumerate() {
            if let Some(u) = u {
                d.upper_bounds_rad[j] = *u;
                d.unconstrained.retain(|&x| x != j);
            }
        }
        Ok(Ok(d))
    }
}
