//! An independent time-domain simulation of the whole calibration, to check the analytic
//! noise answer ([`crate::noise`], calib-lsq's covariance) against what a lab would record.
//!
//! # What it simulates
//! For every calibration: a turntable $\chi$ drawn in a box (mc-verify's streams, exactly the
//! turntables of [`crate::MonteCarloQuestions::rate_distribution`] with the same seed) and, for every output with
//! noise, the samples a lab records: at every position, in the schedule's order with the
//! timing's dwell and move times, $n_i = \mathrm{round}(f_sT_i)$ samples at the sample rate
//! $f_s$, each the sum of
//! - white noise of variance $N^2f_s$ (a density $N$ per $\sqrt{\mathrm{Hz}}$),
//! - the Gauss-Markov bias $b$, propagated exactly from sample to sample and across the moves,
//!   $b_{t+\Delta} = e^{-\Delta/T_c}b_t + \sigma_b\sqrt{1 - e^{-2\Delta/T_c}}\,w$, started
//!   stationary,
//! - quantization, uniform on $[-q/2, q/2]$;
//! - the rate random walk $K\,W(t)$ from the test's start $t = 0$, each sample the mean of
//!   $W$ over its interval $h$ drawn exactly with the step: $W(t + h) = W(t) + \sqrt h\,z_1$,
//!   mean $W(t) + \sqrt h\,(z_1/2 + z_2/\sqrt{12})$, and $W$ carried across the moves;
//! - the rate ramp $\rho\,t$, $\rho \sim N(0, R^2)$ drawn once per calibration, each sample
//!   $\rho$ times its interval's midpoint;
//! - the flicker bias instability as gw-model's [`gw_model::noise::FlickerBank`] over the
//!   timing's windows: every Gauss-Markov term of the bank, each sample its exact mean over
//!   the sample interval (two normals per term and sample from the process's conditional
//!   law, started stationary, carried across the moves);
//! - angle quantization $Q$: an error uniform of standard deviation $Q$ in the integrated
//!   output at each window's first and last reading (one reading where a window starts as
//!   the previous one ends), the position average moved by $(e_{end} - e_{start})/T$;
//!
//! (normal draws by the 32-bit ziggurat, [`crate::ziggurat`], one per white and one per
//! Gauss-Markov term of a sample, and the quantization's uniform from one more word: three
//! 32-bit words per sample on the fast path, read from the stream a block at a time,
//! [`WordBlock`]); every sample is drawn and summed, no shortcut of a position's average;
//!
//! the position averages $\boldsymbol\nu$; the estimator run on them (the calibration's own
//! pseudo-inverse: the coefficients move by $\mathbf A^+\boldsymbol\nu$) and the rate error at
//! the test positions, the table's error vector plus $\mathbf A\mathbf A^+\boldsymbol\nu$.
//! Nothing here uses the covariance formulas: the agreement of
//! [`OutputMoments::coefficient_covariance`] with calib-lsq's prediction is a test of both.
//!
//! Noise comes from ChaCha stream `chunk | ``TIME_DOMAIN_STREAM` of the run's key; chunks
//! run on rayon threads and their sums merge in chunk order, so every result is identical for
//! any thread count; memory does not depend on the number of calibrations.

use crate::error::E2eError;
use crate::montecarlo::{McSettings, YieldCount};
use crate::simulate::EndToEnd;
use crate::ziggurat::{WordBlock, Ziggurat};
use calib_lsq::Timing;
use gw_model::noise::NoiseModel;
use mc_verify::driver::run_chunks;
use mc_verify::{ErrorBox, McRng, TurntableSampler, chunk_rng};
use nalgebra::{DMatrix, DVector};

/// The bit that turns chunk $c$'s turntable stream into its time-domain noise stream.
pub(crate) const TIME_DOMAIN_STREAM: u64 = 1 << 62;

/// Chunks evaluated per wave (bounds the partial sums held at once).
const WAVE_CHUNKS: u64 = 64;

/// Streaming sums of one output's simulated errors.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct OutputMoments {
    /// Calibrations.
    pub(crate) n: u64,
    /// $\sum\delta\boldsymbol\beta$ (coefficient errors from the noise).
    pub(crate) sum: DVector<f64>,
    /// $\sum\delta\boldsymbol\beta\,\delta\boldsymbol\beta^T$.
    pub(crate) sum_outer: DMatrix<f64>,
    /// $\sum e_i$ per position (noise part of the rate error).
    pub(crate) rate_sum: Vec<f64>,
    /// $\sum e_i^2$ per position.
    pub(crate) rate_sum_sq: Vec<f64>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl OutputMoments {
    /// Calibrations.
    #[must_use]
    pub fn n(&self) -> u64 {
        self.n
    }

    /// $\sum\delta\boldsymbol\beta$ (coefficient errors from the noise).
    #[must_use]
    pub fn sum(&self) -> &DVector<f64> {
        &self.sum
    }

    /// $\sum\delta\boldsymbol\beta\,\delta\boldsymbol\beta^T$.
    #[must_use]
    pub fn sum_outer(&self) -> &DMatrix<f64> {
        &self.sum_outer
    }

    /// $\sum e_i$ per position (noise part of the rate error).
    #[must_use]
    pub fn rate_sum(&self) -> &[f64] {
        &self.rate_sum
    }

    /// $\sum e_i^2$ per position.
    #[must_use]
    pub fn rate_sum_sq(&self) -> &[f64] {
        &self.rate_sum_sq
    }
}

impl OutputMoments {
    fn new(k: usize, n_pos: usize) -> Self {
        Self {
            n: 0,
            sum: DVector::zeros(k),
            sum_outer: DMatrix::zeros(k, k),
            rate_sum: vec![0.0; n_pos],
            rate_sum_sq: vec![0.0; n_pos],
        }
    }

    fn merge(&mut self, o: &Self) {
        self.n += o.n;
        self.sum += &o.sum;
        self.sum_outer += &o.sum_outer;
        for (a, b) in self.rate_sum.iter_mut().zip(&o.rate_sum) {
            *a += b;
        }
        for (a, b) in self.rate_sum_sq.iter_mut().zip(&o.rate_sum_sq) {
            *a += b;
        }
    }

    /// The sample covariance of the coefficient errors ($k\times k$).
    #[must_use]
    pub fn coefficient_covariance(&self) -> DMatrix<f64> {
        let n = self.n as f64;
        (&self.sum_outer - &self.sum * self.sum.transpose() / n) / (n - 1.0)
    }

    /// The sample standard deviation of the noise part of the rate error at every position.
    #[must_use]
    pub fn rate_sigma(&self) -> Vec<f64> {
        let n = self.n as f64;
        self.rate_sum
            .iter()
            .zip(&self.rate_sum_sq)
            .map(|(s, q)| ((q - s * s / n) / (n - 1.0)).max(0.0).sqrt())
            .collect()
    }
}

/// The result of a time-domain run.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct TimeDomainRun {
    /// Calibrations simulated and meeting every accuracy (table error plus simulated noise),
    /// with the seed.
    pub(crate) count: YieldCount,
    /// Per output with noise, its streaming sums.
    pub(crate) outputs: Vec<Option<OutputMoments>>,
    /// Noise samples generated.
    pub(crate) noise_samples: u64,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl TimeDomainRun {
    /// Calibrations simulated and meeting every accuracy (table error plus simulated noise),
    /// with the seed.
    #[must_use]
    pub fn count(&self) -> &YieldCount {
        &self.count
    }

    /// Per output with noise, its streaming sums.
    #[must_use]
    pub fn outputs(&self) -> &[Option<OutputMoments>] {
        &self.outputs
    }

    /// Noise samples generated.
    #[must_use]
    pub fn noise_samples(&self) -> u64 {
        self.noise_samples
    }
}

/// $1/\sqrt{12}$: the standard deviation of a Wiener process's mean over a unit interval
/// about the mean of its end points' line, dimensionless.
const INV_SQRT_12: f64 = 0.288_675_134_594_812_9;

/// $\sqrt{12}$: the width of a uniform error of unit standard deviation, dimensionless.
const SQRT_12: f64 = 3.464_101_615_137_754_6;

/// One output's sample generator (its noise and the windows of the timing).
struct Generator {
    white_sd: f64,
    quantization: f64,
    bias: Option<(f64, f64)>,
    /// Rate random walk $K$, output unit per $\sqrt{\mathrm s}$ (0: none).
    rate_random_walk: f64,
    /// Rate ramp $R$, output unit per s (0: none).
    rate_ramp: f64,
    /// The flicker bank's terms, each drawn as its exact average over every sample interval.
    flicker: Vec<IntegratedGm>,
    /// Angle quantization $Q$, output unit times s (0: none).
    angle_quantization: f64,
    /// (start, samples) per position in the schedule's order.
    windows: Vec<(f64, u64)>,
    dt: f64,
}

/// One Gauss-Markov term $(\sigma, T_c)$ drawn exactly over a sample interval $h$: from the
/// state $b_0$, the state $b_h = \varphi b_0 + \varepsilon_1$ and the interval's mean
/// $\bar b = g b_0 + \varepsilon_2$, $\varphi = e^{-h/T_c}$, $g = T_c(1 - \varphi)/h$,
/// with $\mathrm{Var}\,\varepsilon_1 = \sigma^2(1 - \varphi^2)$,
/// $\mathrm{Var}\,\varepsilon_2 = V_h - \sigma^2 g^2$ ($V_h$ the stationary variance of an
/// $h$-second mean) and $\mathrm{Cov}(\varepsilon_1, \varepsilon_2) = \sigma^2 g(1 - \varphi)$
/// (the conditional covariances of the Ornstein-Uhlenbeck process given $b_0$).
struct IntegratedGm {
    sigma: f64,
    tc: f64,
    phi: f64,
    gain: f64,
    /// $\sqrt{\mathrm{Var}\,\varepsilon_1}$.
    s1: f64,
    /// $\mathrm{Cov}/s_1$: the part of $\varepsilon_2$ along $\varepsilon_1$'s normal.
    along: f64,
    /// The rest of $\varepsilon_2$'s standard deviation.
    rest: f64,
}

impl IntegratedGm {
    fn new(term: &gw_model::noise::GaussMarkov, dt: f64) -> Self {
        let (sigma, tc) = (term.sigma(), term.correlation_s());
        let phi = (-dt / tc).exp();
        let gain = -tc * (-dt / tc).exp_m1() / dt;
        let v_mean = term.variance_of_average(
            &gw_model::noise::Window::new(0.0, dt)
                .unwrap_or_else(|_| unreachable!("a sample interval is positive and finite")),
        );
        let s1 = sigma * (1.0 - phi * phi).max(0.0).sqrt();
        let cov = sigma * sigma * gain * (1.0 - phi);
        let along = if s1 > 0.0 { cov / s1 } else { 0.0 };
        let rest = (v_mean - sigma * sigma * gain * gain - along * along)
            .max(0.0)
            .sqrt();
        Self {
            sigma,
            tc,
            phi,
            gain,
            s1,
            along,
            rest,
        }
    }
}

impl Generator {
    fn new(noise: &NoiseModel, timing: &Timing) -> Self {
        let fs = timing.sample_rate_hz();
        let q = noise.quantization();
        Self {
            white_sd: (noise.white_sample_variance(fs) - q * q / 12.0)
                .max(0.0)
                .sqrt(),
            quantization: q,
            bias: noise.bias().map(|b| (b.sigma(), b.correlation_s())),
            rate_random_walk: noise.rate_random_walk(),
            rate_ramp: noise.rate_ramp(),
            flicker: noise
                .flicker_bank(&timing.windows())
                .map_or_else(Vec::new, |bank| {
                    bank.terms()
                        .iter()
                        .map(|t| IntegratedGm::new(t, 1.0 / fs))
                        .collect()
                }),
            angle_quantization: noise.angle_quantization(),
            windows: timing
                .windows()
                .iter()
                .map(|w| (w.start_s(), ((w.duration_s() * fs).round() as u64).max(1)))
                .collect(),
            dt: 1.0 / fs,
        }
    }

    fn samples(&self) -> u64 {
        self.windows.iter().map(|w| w.1).sum()
    }

    /// The position averages of one calibration into `avg`.
    fn averages(&self, words: &mut WordBlock<McRng>, avg: &mut [f64]) {
        let (sigma_b, tc) = self.bias.unwrap_or((0.0, 1.0));
        let phi = (-self.dt / tc).exp();
        let innovation = sigma_b * (1.0 - phi * phi).max(0.0).sqrt();
        let has_bias = self.bias.is_some();
        let has_white = self.white_sd > 0.0;
        let has_quantization = self.quantization > 0.0;
        let z = Ziggurat::get();
        let mut b = if has_bias {
            sigma_b * z.sample(words)
        } else {
            0.0
        };
        let has_rrw = self.rate_random_walk > 0.0;
        let sqrt_dt = self.dt.sqrt();
        // the Wiener process of the rate random walk at time t (0 at the start) and the ramp
        let mut wiener = 0.0;
        let has_ramp = self.rate_ramp > 0.0;
        let rho = if has_ramp {
            self.rate_ramp * z.sample(words)
        } else {
            0.0
        };
        // the flicker bank's states, started stationary
        let mut flicker: Vec<f64> = self
            .flicker
            .iter()
            .map(|f| f.sigma * z.sample(words))
            .collect();
        let has_flicker = !flicker.is_empty();
        // angle quantization: the integrated output's error at the last reading, and its time
        let q_step = self.angle_quantization * SQRT_12;
        let mut last_reading: Option<(f64, f64)> = None;
        let mut t = 0.0;
        for (a, &(start, n)) in avg.iter_mut().zip(&self.windows) {
            if has_bias && start > t {
                let g = (-(start - t) / tc).exp();
                b = g * b + sigma_b * (1.0 - g * g).max(0.0).sqrt() * z.sample(words);
            }
            if has_flicker && start > t {
                for (f, x) in self.flicker.iter().zip(&mut flicker) {
                    let g = (-(start - t) / f.tc).exp();
                    *x = g * *x + f.sigma * (1.0 - g * g).max(0.0).sqrt() * z.sample(words);
                }
            }
            if has_rrw && start > t {
                wiener += (start - t).sqrt() * z.sample(words);
            }
            let mut sum = 0.0;
            for i in 0..n {
                let mut x = 0.0;
                if has_bias {
                    b = phi * b + innovation * z.sample(words);
                    x = b;
                }
                if has_rrw {
                    let (z1, z2) = (z.sample(words), z.sample(words));
                    x += self.rate_random_walk * (wiener + sqrt_dt * (0.5 * z1 + z2 * INV_SQRT_12));
                    wiener += sqrt_dt * z1;
                }
                if has_ramp {
                    x += rho * (start + (i as f64 + 0.5) * self.dt);
                }
                for (f, state) in self.flicker.iter().zip(&mut flicker) {
                    let z1 = z.sample(words);
                    let z2 = z.sample(words);
                    x += f.gain * *state + f.along * z1 + f.rest * z2;
                    *state = f.phi * *state + f.s1 * z1;
                }
                if has_white {
                    x += self.white_sd * z.sample(words);
                }
                if has_quantization {
                    x += self.quantization * (words.unit_32() - 0.5);
                }
                sum += x;
            }
            *a = sum / n as f64;
            t = start + n as f64 * self.dt;
            if q_step > 0.0 {
                // the readings at the window's ends: shared with the previous window where it
                // ended as this one starts
                let mut reading = || q_step * (words.unit_32() - 0.5);
                let e_start = match last_reading {
                    Some((at, e))
                        if (at - start).abs()
                            <= gw_model::noise::SAME_READING_RELATIVE * at.abs().max(1.0) =>
                    {
                        e
                    }
                    _ => reading(),
                };
                let e_end = reading();
                *a += (e_end - e_start) / (t - start);
                last_reading = Some((t, e_end));
            }
        }
    }
}

impl<S: tt_kinematics::ScheduleErrorModel + Sync> EndToEnd<S> {
    /// The time-domain simulation of `settings.samples` calibrations (see the
    /// [module](self)): turntables drawn from `bounds`, noise `noise[k]` per output over
    /// `timing`.
    ///
    /// # Errors
    /// As [`McSettings::validate`]; [`E2eError::Calib`] unless `noise` has one entry per
    /// output and `timing` one dwell per position; [`E2eError::Draw`] naming the first
    /// calibration that fails.
    pub fn simulate_time_domain(
        &self,
        bounds: &ErrorBox,
        noise: &[Option<NoiseModel>],
        timing: &Timing,
        settings: &McSettings,
    ) -> Result<TimeDomainRun, E2eError> {
        settings.validate()?;
        // the same checks as the analytic answer (lengths), before any work
        self.calibration().noise_covariances(noise, timing)?;
        let n = self.len();
        let acc = self.accuracies();
        let outputs = acc.len();
        let gens: Vec<Option<Generator>> = noise
            .iter()
            .map(|m| m.as_ref().map(|m| Generator::new(m, timing)))
            .collect();
        let samples_per_calibration: u64 = gens.iter().flatten().map(Generator::samples).sum();
        let regressions: Vec<(&DMatrix<f64>, &DMatrix<f64>)> = self
            .calibration()
            .outputs()
            .iter()
            .map(|o| (o.regression().matrix(), o.regression().pinv()))
            .collect();
        let sampler = TurntableSampler::for_joint_ranges(bounds, &self.model().joint_ranges_rad());
        let cs = u64::from(settings.chunk_size);
        let chunks = settings.samples.div_ceil(cs);
        type Part = (Vec<Option<OutputMoments>>, u64, Vec<u64>);
        let new_part = || -> Part {
            (
                gens.iter()
                    .zip(&regressions)
                    .map(|(g, (a, _))| g.as_ref().map(|_| OutputMoments::new(a.ncols(), n)))
                    .collect(),
                0,
                vec![0; outputs],
            )
        };
        let mut acc_part = new_part();
        let chunk = |c: u64| -> Result<Part, E2eError> {
            let mut part = new_part();
            let mut noise = WordBlock::new(chunk_rng(settings.seed, c | TIME_DOMAIN_STREAM));
            let mut avg = vec![0.0; n];
            let draw = (settings.seed, settings.samples, cs);
            self.for_each_draw(&sampler, draw, c, |_, vectors| {
                let mut all = true;
                for (k, v) in vectors.iter_mut().enumerate() {
                    if let (Some(g), Some(mom)) = (&gens[k], &mut part.0[k]) {
                        g.averages(&mut noise, &mut avg);
                        let (a, pinv) = regressions[k];
                        let dbeta = pinv * DVector::from_column_slice(&avg);
                        let e = a * &dbeta;
                        mom.n += 1;
                        mom.sum += &dbeta;
                        mom.sum_outer += &dbeta * dbeta.transpose();
                        for (i, ei) in e.iter().enumerate() {
                            mom.rate_sum[i] += ei;
                            mom.rate_sum_sq[i] += ei * ei;
                            v[i] += ei;
                        }
                    }
                    let worst = crate::simulate::max_abs(v);
                    if worst <= acc[k] {
                        part.2[k] += 1;
                    } else {
                        all = false;
                    }
                }
                if all {
                    part.1 += 1;
                }
                Ok(())
            })?;
            Ok(part)
        };
        run_chunks(chunks, WAVE_CHUNKS, chunk, |p| {
            for (a, b) in acc_part.0.iter_mut().zip(&p.0) {
                if let (Some(a), Some(b)) = (a, b) {
                    a.merge(b);
                }
            }
            acc_part.1 += p.1;
            for (a, b) in acc_part.2.iter_mut().zip(&p.2) {
                *a += b;
            }
            Ok(())
        })?;
        Ok(TimeDomainRun {
            count: YieldCount::new(settings.samples, settings.seed, acc_part.1, acc_part.2),
            outputs: acc_part.0,
            noise_samples: samples_per_calibration * settings.samples,
        })
    }
}
