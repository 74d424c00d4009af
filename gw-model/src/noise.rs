//! The noise of a sensor output, and the statistics of its averages over the time windows
//! a calibration dwells at each test position.
//!
//! # Model
//! Around its value $y$ (the linear model of [`crate::Output`]) an output reads
//! $$\tilde y(t) = y + w(t) + b(t) + \varepsilon_q(t),$$
//! in the output's unit, with independent zero-mean parts:
//! - $w$, **white noise** of density $N$ (output unit per $\sqrt{\mathrm{Hz}}$): the angle
//!   random walk of a gyro, the velocity random walk of an accelerometer;
//! - $b$, the **bias instability** as a first-order Gauss-Markov process of stationary
//!   standard deviation $\sigma_b$ and correlation time $T_c$:
//!   $\dot b = -b/T_c + \sqrt{2\sigma_b^2/T_c}\,\eta(t)$, autocovariance
//!   $R_b(\Delta t) = \sigma_b^2 e^{-|\Delta t|/T_c}$ (Gelb, *Applied Optimal Estimation*, 1974,
//!   Table 3.4-1);
//! - $\varepsilon_q$, **quantization** of step $q$: an independent error uniform on
//!   $[-q/2, q/2]$ per sample, variance $q^2/12$ (Widrow's model), white at the sample rate;
//! - $b_K$, **rate random walk** of density $K$ (output unit per $\sqrt{\mathrm s}$): the
//!   bias wanders as $b_K(t) = K\,W(t)$ from the test's start $t_0 = 0$ (the time origin of
//!   the windows; $W$ a standard Wiener process, $W(0) = 0$: the bias at the start is the
//!   constant bias the calibration estimates), autocovariance $K^2\min(s, r)$, Allan
//!   deviation $\sigma(\tau) = K\sqrt{\tau/3}$ (IEEE Std 952-1997, Annex C, C.1.4);
//! - $b_R$, **rate ramp** of size $R$ (output unit per s): $b_R(t) = \rho\,t$ with
//!   $\rho \sim N(0, R^2)$ drawn once per test (a drift of unknown sign), covariance
//!   $R^2 s r$, Allan deviation $\sigma(\tau) = R\tau/\sqrt2$ (ibid., C.1.5).
//!
//! - $b_F$, a **flicker bias instability** of coefficient $B$ (two-sided PSD
//!   $B^2/(2\pi f)$, Allan floor $0.6643\,B$, ibid., C.1.3), entered over a schedule as the
//!   [`FlickerBank`] of Gauss-Markov terms that reproduces the floor over the schedule's time
//!   scales, its fit error stated;
//! - $\varepsilon_Q$, **angle (velocity) quantization** $Q$ (output unit times s): an error
//!   of standard deviation $Q$ in the integrated output at each reading, independent from
//!   reading to reading; a window's average $(\theta(b) - \theta(a))/T$ carries
//!   $(e_b - e_a)/T$: variance $2Q^2/T^2$, covariance $-Q^2/(T_1T_2)$ with the window that
//!   starts where it ends, Allan variance $3Q^2/\tau^2$ (ibid., C.1.1).
//!
//! Before $t_0$ both drifts are zero ($b_K(t) = K\,W(\max(t, 0))$), so a window that starts
//! before the test sees only its part after $t_0$.
//!
//! # Samples and averages
//! A calibration averages the samples of each position. We take each sample to be the mean of
//! the output over its sample interval $h = 1/f_s$ (an integrating sensor: gyros and
//! accelerometers deliver angle and velocity increments, $\Delta\theta / h$). Then the mean of
//! the $m = f_s T$ samples of a window $[t_0, t_0 + T]$ is exactly the continuous average
//! $\bar x = \frac1T\int_{t_0}^{t_0+T} x(t)\,dt$, and:
//!
//! | part | variance of a $T$-second average | covariance of the averages of two windows |
//! |---|---|---|
//! | white, density $N$ | $N^2/T$ | $N^2\,\lvert W_1\cap W_2\rvert / (T_1T_2)$ |
//! | Gauss-Markov $(\sigma_b, T_c)$ | $\dfrac{2\sigma_b^2}{u^2}\left(u - 1 + e^{-u}\right)$, $u = T/T_c$ | below |
//! | quantization $q$ | $\dfrac{q^2}{12 f_s T}$ | $\dfrac{q^2}{12 f_s}\,\lvert W_1\cap W_2\rvert/(T_1T_2)$ |
//! | rate random walk $K$ | $K^2\left(t_0 + \dfrac T3\right)$ for $W = [t_0, t_0 + T]$ | $K^2 m_1$ for disjoint windows, $m_1$ the earlier window's midpoint; below |
//! | rate ramp $R$ | $R^2 m^2$, $m$ the window's midpoint | $R^2 m_1 m_2$ |
//!
//! **White noise, continuous and sampled.** The density $N$ is defined by the variance of the
//! average, $\mathrm{Var}\,\bar w_T = N^2/T$, which is also the Allan variance of white noise
//! at $\tau = T$ (IEEE Std 952-1997, Annex C: $\sigma^2(\tau) = N^2/\tau$), so $N$ is the Allan
//! deviation at $\tau = 1$ s and the square root of the two-sided power spectral density.
//! (A density quoted as the root of a one-sided PSD is $\sqrt2$ larger.) Sampled, each sample
//! carries the variance $\sigma_s^2 = N^2 f_s$ and the mean of $m$ independent samples has
//! $\sigma_s^2/m = N^2 f_s/m$, which is $N^2/T$ for $m = f_s T$. For a point-sampling
//! sensor whose per-sample standard deviation is $\sigma_s$ (white within its band up to
//! $f_s/2$), the same holds with $N = \sigma_s/\sqrt{f_s}$.
//!
//! **Gauss-Markov average.** With $u = T/T_c$,
//! $$\mathrm{Var}\,\bar b_T = \frac{1}{T^2}\int_0^T\!\!\int_0^T \sigma_b^2
//!   e^{-|s-r|/T_c}\,ds\,dr = \frac{2\sigma_b^2}{u^2}\left(u - 1 + e^{-u}\right),$$
//! which tends to $\sigma_b^2$ for $T \ll T_c$ (the bias is frozen) and to
//! $2\sigma_b^2 T_c/T$ for $T \gg T_c$ (it averages like white noise of density
//! $\sigma_b\sqrt{2T_c}$). For a sensor that point-samples the process instead, the mean of
//! $m$ samples is $\frac{\sigma_b^2}{m^2}\sum_{k,l}\rho^{|k-l|}$ with $\rho = e^{-1/(f_sT_c)}$,
//! which differs from the integral by a relative $O(1/(f_s T_c))$.
//!
//! **Gauss-Markov covariance of two windows** $W_1 = [a, b]$, $W_2 = [c, d]$ (lengths
//! $T_1$, $T_2$). With the even function
//! $\Phi(x) = T_c^2\,\varphi(|x|/T_c)$, $\varphi(v) = e^{-v} - 1 + v$, which has
//! $\Phi'' = e^{-|x|/T_c}$ and $\Phi(0) = \Phi'(0) = 0$,
//! $$\mathrm{Cov}(\bar b_{W_1}, \bar b_{W_2}) = \frac{\sigma_b^2}{T_1T_2}\left[\Phi(b-c) -
//!   \Phi(a-c) - \Phi(b-d) + \Phi(a-d)\right]$$
//! for any two windows, overlapping or not. For disjoint windows ($c \ge b$) it factors:
//! $$\mathrm{Cov} = \sigma_b^2\,\frac{T_c(1 - e^{-T_1/T_c})}{T_1}\,
//!   \frac{T_c(1 - e^{-T_2/T_c})}{T_2}\,e^{-(c - b)/T_c},$$
//! so the covariance of a window with every later one needs one exponential per gap
//! ([`NoiseModel::window_covariance`] builds the $n\times n$ matrix with $O(n)$
//! exponentials).
//!
//! **Rate random walk covariance of two windows** $W_1 = [a, b]$, $W_2 = [c, d]$ in
//! $t \ge 0$:
//! $$\mathrm{Cov}(\bar b_{W_1}, \bar b_{W_2}) = \frac{K^2}{T_1T_2}\int_a^b\!\!\int_c^d
//!   \min(s, r)\,dr\,ds = \frac{K^2}{T_1T_2}\left[G(b, d) - G(a, d) - G(b, c) + G(a, c)\right],$$
//! with $G(x, y) = \int_0^x\!\int_0^y \min(s, r)\,dr\,ds$: for $x \le y$,
//! $G = \int_0^x \left(s^2/2 + s(y - s)\right)ds = x^2y/2 - x^3/6$, so
//! $G(x, y) = \mu^2 M/2 - \mu^3/6$ with $\mu = \min(x, y)$, $M = \max(x, y)$. For
//! disjoint windows ($c \ge b$) $\min(s, r) = s$ on the whole square, and the covariance is
//! $K^2 (a + b)/2$: $K^2$ times the earlier window's midpoint, the same for every later
//! window. For one window, $G(b, b) - 2G(a, b) + G(a, a) = aT^2 + T^3/3$ gives the variance
//! $K^2(a + T/3)$: the bias wandered for $a$ seconds before the window and a third of it
//! within. The Allan variance follows from the averages as
//! $\sigma^2(\tau) = \frac12\left[\mathrm{Var}\,\bar b_{[0,\tau]} +
//! \mathrm{Var}\,\bar b_{[\tau,2\tau]} - 2\,\mathrm{Cov}\right]
//! = \frac{K^2}2\left[\frac\tau3 + \frac{4\tau}3 - \tau\right] = \frac{K^2\tau}3$, IEEE 952's
//! value. Overlapping windows are evaluated with $G$ after shifting the origin to the earlier
//! start $o$ ($\min(s, r) = o + \min(s - o, r - o)$), which keeps the terms of $G$ of the
//! windows' size and avoids cancellation late in a long test.
//!
//! **Rate ramp.** The average of $\rho t$ over a window is $\rho m$, $m$ its midpoint, so
//! $\mathrm{Cov} = R^2 m_1 m_2$, and the Allan variance is
//! $\frac{R^2}{2}\left[(\tau/2)^2 + (3\tau/2)^2 - 2\cdot\frac{3\tau^2}{4}\right] = R^2\tau^2/2$.
//!
//! Both drifts grow with the time since the start: a position late in a long test carries a
//! larger, and strongly correlated, bias error; the least-squares map decides how much of it
//! reaches the coefficients (a bias-only estimate of constant bias absorbs the common part).
//!
//! # From the datasheet's bias instability to the Gauss-Markov process
//! A datasheet's bias instability $B$ is the flat floor of the Allan deviation divided by
//! $\sqrt{2\ln2/\pi} = 0.6643$ (the floor of flicker noise, IEEE Std 952-1997, Annex C, C.1.3:
//! $\sigma(\tau) = B\sqrt{2\ln 2/\pi}$). A Gauss-Markov process has no floor: its Allan
//! variance (El-Sheimy, Hou and Niu, "Analysis and Modeling of Inertial Sensors Using Allan
//! Variance", IEEE Trans. Instrum. Meas. 57(1), 2008, Table I; here from the averages above,
//! $\sigma^2(\tau) = \mathrm{Var}\,\bar b_\tau - \mathrm{Cov}(\bar b_{[0,\tau]},
//! \bar b_{[\tau, 2\tau]})$) is
//! $$\sigma^2(\tau) = \frac{\sigma_b^2}{u^2}\left(2u - 3 + 4e^{-u} - e^{-2u}\right),
//!   \quad u = \tau/T_c,$$
//! rising as $\sqrt{2u/3}\,\sigma_b$ for short $\tau$ and falling as
//! $\sigma_b\sqrt{2T_c/\tau}$ for long $\tau$, with a single maximum where
//! $\frac{d}{du}\frac{g(u)}{u^2} = 0$, $g(u) = 2u - 3 + 4e^{-u} - e^{-2u}$, i.e. where
//! $u\,g'(u) = 2g(u)$, $g'(u) = 2(1 - e^{-u})^2$: at $u^* = 1.8926$
//! ([`GM_ADEV_PEAK_TAU_PER_TC`]), of height $\sigma(\tau^*) = 0.61736\,\sigma_b$
//! ([`GM_ADEV_PEAK_PER_SIGMA`]). We match that maximum to the datasheet's floor:
//! $$0.61736\,\sigma_b = 0.66428\,B \quad\Rightarrow\quad
//!   \sigma_b = \frac{0.66428}{0.61736}B = 1.0760\,B,$$
//! and $T_c$ should put the maximum where the datasheet's floor lies,
//! $T_c = \tau_{floor}/1.8926$. The process then has the datasheet's floor at the datasheet's
//! $\tau$; it is a model of the bias's wander over the minutes of a calibration, not of the
//! flicker spectrum at every $\tau$.
//!
//! # Units of white-noise densities
//! Datasheets print the white noise in their own units; [`WhiteDensity`] converts to the
//! output's unit per $\sqrt{\mathrm{Hz}}$ (an [`OutputUnit`]: a [`UnitFamily`] and a scale to
//! SI). With $x$ the rate (or specific force) and $\theta = \int x\,dt$ the angle (velocity),
//! white rate noise of density $N$ makes $\theta$ after $t$ seconds a random walk of standard
//! deviation $t\cdot N/\sqrt t = N\sqrt t$. A random walk coefficient per $\sqrt{\mathrm h}$
//! therefore converts through $\sqrt{1\,\mathrm h} = \sqrt{3600\,\mathrm s} = 60\sqrt{\mathrm s}$:
//! - angle random walk, deg/$\sqrt{\mathrm h}$ (`white_deg_per_sqrt_h`):
//!   $1\,\mathrm{deg}/\sqrt{\mathrm h} = \frac{1}{60}\,\mathrm{deg}/\sqrt{\mathrm s}
//!   = \frac1{60}\,(\mathrm{deg/s})/\sqrt{\mathrm{Hz}} = 60\,(\mathrm{deg/h})/\sqrt{\mathrm{Hz}}
//!   = \frac{\pi}{180\cdot60}\,(\mathrm{rad/s})/\sqrt{\mathrm{Hz}}$;
//! - velocity random walk, m/s/$\sqrt{\mathrm h}$ (`white_m_per_s_per_sqrt_h`):
//!   $1\,(\mathrm{m/s})/\sqrt{\mathrm h} = \frac1{60}\,(\mathrm{m/s^2})/\sqrt{\mathrm{Hz}}
//!   = \frac{1000}{60\cdot 9.80665}\,\mathrm{mg}/\sqrt{\mathrm{Hz}}
//!   = 1.69953\,\mathrm{mg}/\sqrt{\mathrm{Hz}}$;
//! - velocity random walk density, $\mu$g/$\sqrt{\mathrm{Hz}}$ (`white_ug_per_sqrt_hz`):
//!   $1\,\mu\mathrm g/\sqrt{\mathrm{Hz}} = 9.80665\times10^{-6}\,(\mathrm{m/s^2})/
//!   \sqrt{\mathrm{Hz}} = 10^{-3}\,\mathrm{mg}/\sqrt{\mathrm{Hz}}$ (g is standard gravity,
//!   [`STANDARD_GRAVITY_M_PER_S2`]);
//! - already in the output's unit (`white_per_sqrt_hz`): no conversion, any output unit.
//!
//! In general a density $v$ in a unit worth $s_k$ SI units is $v\,s_k/s_u$ in an output unit
//! worth $s_u$ SI units (the $1/60$ of the $\sqrt{\mathrm h}$ included in $s_k$). A density of
//! one family (angle random walk) for an output of the other (mg) is
//! [`ModelError::UnitFamilyMismatch`], naming both.
//!
//! # Example
//! ```
//! use gw_model::noise::{GaussMarkov, NoiseModel, WhiteDensity, Window};
//!
//! // A STIM300-class gyro in deg/h: ARW 0.15 deg/sqrt(h), bias instability 0.5 deg/h.
//! let n = WhiteDensity::DegPerSqrtH(0.15).in_output_unit("deg_per_h")?; // 9 (deg/h)/sqrt(Hz)
//! assert!((n - 9.0).abs() < 1e-12);
//! let bias = GaussMarkov::from_bias_instability(0.5, 3600.0)?; // sigma_b = 0.538 deg/h
//! let noise = NoiseModel::new(n, Some(bias), 0.0)?;
//! let w = Window::new(0.0, 60.0)?; // a 60 s dwell
//! // white part of a 60 s average: 9 / sqrt(60) = 1.16 deg/h
//! assert!((noise.white_variance_of_average(&w, 1000.0).sqrt() - 9.0 / 60f64.sqrt()).abs() < 1e-12);
//! // a 1 h bias wander is nearly frozen over 60 s: the average keeps most of sigma_b
//! assert!(noise.correlated_variance_of_average(&w).sqrt() > 0.99 * bias.sigma());
//! # Ok::<(), gw_model::ModelError>(())
//! ```

use crate::error::{ModelError, finite, non_negative, positive};
use nalgebra::DMatrix;
use std::fmt;

/// Standard gravity, m/s² (3rd CGPM, 1901): the g of specific-force units (`g`, `mg`, `ug`).
pub const STANDARD_GRAVITY_M_PER_S2: f64 = 9.806_65;

/// $\sqrt{2\ln 2/\pi}$: the Allan-deviation floor of flicker (bias-instability) noise per unit
/// of the bias-instability coefficient $B$ (IEEE Std 952-1997, Annex C). Dimensionless.
pub const FLICKER_FLOOR_PER_BIAS_INSTABILITY: f64 = 0.664_282_470_267_960_1;

/// $u^* = \tau^*/T_c$ at which the Allan deviation of a first-order Gauss-Markov process peaks:
/// the root of $u\cdot 2(1-e^{-u})^2 = 2(2u - 3 + 4e^{-u} - e^{-2u})$. Dimensionless.
pub const GM_ADEV_PEAK_TAU_PER_TC: f64 = 1.892_617_832_925_018;

/// The peak of the Allan deviation of a first-order Gauss-Markov process per unit of its
/// stationary standard deviation: $\sqrt{g(u^*)}/u^*$, $g(u) = 2u - 3 + 4e^{-u} - e^{-2u}$.
/// Dimensionless.
pub const GM_ADEV_PEAK_PER_SIGMA: f64 = 0.617_364_283_144_441_4;

/// $1/60$: a coefficient per $\sqrt{\mathrm h}$ is $1/60$ of the same per $\sqrt{\mathrm s}$,
/// i.e. per $\sqrt{\mathrm{Hz}}$ of rate (see the [module documentation](self)).
const PER_SQRT_H_IN_PER_SQRT_S: f64 = 1.0 / 60.0;

/// Below this argument the series of $e^{-v} - 1 + v$ and of the Gauss-Markov Allan numerator
/// replace the closed forms (which cancel). Dimensionless; at $v = 0.5$ the 30-term series is
/// exact to rounding.
const SERIES_BELOW: f64 = 0.5;

/// Relative size below which a Gauss-Markov correlation between two windows is set to zero
/// when the matrix is built (its exponential has underflowed into subnormals, which slow
/// the loop and carry nothing). Dimensionless.
const CORRELATION_UNDERFLOW: f64 = 1e-300;

/// Two reading times closer than this, relative to their size (at least 1 s), are one
/// reading of the integrated output (angle quantization): windows that share a reading.
/// Dimensionless.
pub const SAME_READING_RELATIVE: f64 = 1e-9;

/// The physical family of an output's unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum UnitFamily {
    /// An angular rate (gyros): SI unit rad/s.
    AngularRate,
    /// A specific force (accelerometers): SI unit m/s².
    SpecificForce,
}

impl UnitFamily {
    /// `"an angular rate"` or `"a specific force"`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            UnitFamily::AngularRate => "an angular rate",
            UnitFamily::SpecificForce => "a specific force",
        }
    }
}

impl fmt::Display for UnitFamily {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// One degree per hour in rad/s.
const RAD_PER_S_PER_DEG_PER_H: f64 = tt_core::units::RAD_PER_S_PER_DEG_PER_H;
/// One degree per second in rad/s.
const RAD_PER_S_PER_DEG_PER_S: f64 = std::f64::consts::PI / 180.0;

/// The output unit labels [`OutputUnit::parse`] knows: label, family, SI units per label unit.
/// `g` is standard gravity.
pub const OUTPUT_UNITS: &[(&str, UnitFamily, f64)] = &[
    (
        "deg_per_h",
        UnitFamily::AngularRate,
        RAD_PER_S_PER_DEG_PER_H,
    ),
    ("deg/h", UnitFamily::AngularRate, RAD_PER_S_PER_DEG_PER_H),
    (
        "deg_per_s",
        UnitFamily::AngularRate,
        RAD_PER_S_PER_DEG_PER_S,
    ),
    ("deg/s", UnitFamily::AngularRate, RAD_PER_S_PER_DEG_PER_S),
    ("rad_per_s", UnitFamily::AngularRate, 1.0),
    ("rad/s", UnitFamily::AngularRate, 1.0),
    ("g", UnitFamily::SpecificForce, STANDARD_GRAVITY_M_PER_S2),
    (
        "mg",
        UnitFamily::SpecificForce,
        STANDARD_GRAVITY_M_PER_S2 * 1e-3,
    ),
    (
        "ug",
        UnitFamily::SpecificForce,
        STANDARD_GRAVITY_M_PER_S2 * 1e-6,
    ),
    ("m_per_s2", UnitFamily::SpecificForce, 1.0),
    ("m/s^2", UnitFamily::SpecificForce, 1.0),
    ("m/s2", UnitFamily::SpecificForce, 1.0),
];

/// An output's unit understood physically: its family and its size in SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OutputUnit {
    family: UnitFamily,
    si_per_unit: f64,
}

impl OutputUnit {
    /// The unit of a label of [`OUTPUT_UNITS`] (`deg_per_h`, `deg/h`, `mg`, `m_per_s2`, ...;
    /// exact, case-sensitive: `mg` is not `Mg`), or `None` for any other label (an output may
    /// carry any label; only a datasheet density needs it understood).
    #[must_use]
    pub fn parse(label: &str) -> Option<Self> {
        OUTPUT_UNITS
            .iter()
            .find(|(l, _, _)| *l == label)
            .map(|&(_, family, si_per_unit)| Self {
                family,
                si_per_unit,
            })
    }

    /// The family (angular rate or specific force).
    #[must_use]
    pub fn family(&self) -> UnitFamily {
        self.family
    }

    /// SI units (rad/s or m/s²) per unit of the output.
    #[must_use]
    pub fn si_per_unit(&self) -> f64 {
        self.si_per_unit
    }
}

/// A white-noise density as a datasheet prints it, in one of four units; the study key of
/// each is its [`key`](Self::key). Values are densities in the sense of the
/// [module documentation](self): $N^2/T$ is the variance of a $T$-second average.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WhiteDensity {
    /// Angle random walk, deg/$\sqrt{\mathrm h}$ (gyros): $60\,(\mathrm{deg/h})/\sqrt{\mathrm{Hz}}$ each.
    DegPerSqrtH(f64),
    /// Velocity random walk density, $\mu$g/$\sqrt{\mathrm{Hz}}$ (accelerometers).
    UgPerSqrtHz(f64),
    /// Velocity random walk, (m/s)/$\sqrt{\mathrm h}$ (accelerometers):
    /// $\frac1{60}\,(\mathrm{m/s^2})/\sqrt{\mathrm{Hz}}$ each.
    MPerSPerSqrtH(f64),
    /// Already in the output's unit per $\sqrt{\mathrm{Hz}}$ (any output, any unit label).
    PerSqrtHz(f64),
}

impl WhiteDensity {
    /// The study keys, in the order of the variants.
    pub const KEYS: [&'static str; 4] = [
        "white_deg_per_sqrt_h",
        "white_ug_per_sqrt_hz",
        "white_m_per_s_per_sqrt_h",
        "white_per_sqrt_hz",
    ];

    /// The study key (`white_deg_per_sqrt_h`, ...).
    #[must_use]
    pub fn key(&self) -> &'static str {
        match self {
            WhiteDensity::DegPerSqrtH(_) => Self::KEYS[0],
            WhiteDensity::UgPerSqrtHz(_) => Self::KEYS[1],
            WhiteDensity::MPerSPerSqrtH(_) => Self::KEYS[2],
            WhiteDensity::PerSqrtHz(_) => Self::KEYS[3],
        }
    }

    /// The value as given, in the key's unit.
    #[must_use]
    pub fn value(&self) -> f64 {
        match *self {
            WhiteDensity::DegPerSqrtH(v)
            | WhiteDensity::UgPerSqrtHz(v)
            | WhiteDensity::MPerSPerSqrtH(v)
            | WhiteDensity::PerSqrtHz(v) => v,
        }
    }

    /// The family of outputs the unit belongs to (`None` for `white_per_sqrt_hz`, which is
    /// in the output's own unit).
    #[must_use]
    pub fn family(&self) -> Option<UnitFamily> {
        match self {
            WhiteDensity::DegPerSqrtH(_) => Some(UnitFamily::AngularRate),
            WhiteDensity::UgPerSqrtHz(_) | WhiteDensity::MPerSPerSqrtH(_) => {
                Some(UnitFamily::SpecificForce)
            }
            WhiteDensity::PerSqrtHz(_) => None,
        }
    }

    /// SI units per $\sqrt{\mathrm{Hz}}$ ((rad/s)/√Hz or (m/s²)/√Hz) per unit of the key
    /// (`None` for `white_per_sqrt_hz`).
    #[must_use]
    pub(crate) fn si_per_key_unit(&self) -> Option<f64> {
        match self {
            WhiteDensity::DegPerSqrtH(_) => {
                Some(RAD_PER_S_PER_DEG_PER_S * PER_SQRT_H_IN_PER_SQRT_S)
            }
            WhiteDensity::UgPerSqrtHz(_) => Some(STANDARD_GRAVITY_M_PER_S2 * 1e-6),
            WhiteDensity::MPerSPerSqrtH(_) => Some(PER_SQRT_H_IN_PER_SQRT_S),
            WhiteDensity::PerSqrtHz(_) => None,
        }
    }

    /// The density in the output's unit per $\sqrt{\mathrm{Hz}}$, for an output whose unit
    /// label is `unit`: $v\,s_k/s_u$ (see the [module documentation](self)).
    ///
    /// # Errors
    /// [`ModelError::Field`] (not finite, negative) naming the key for a bad value;
    /// [`ModelError::UnitFamilyMismatch`] naming the key and the unit when the density is of
    /// the other family; [`ModelError::UnknownUnit`] when a conversion is needed and `unit`
    /// is not in [`OUTPUT_UNITS`].
    pub fn in_output_unit(&self, unit: &str) -> Result<f64, ModelError> {
        let v = non_negative(self.key(), self.value())?;
        let (Some(family), Some(si)) = (self.family(), self.si_per_key_unit()) else {
            return Ok(v);
        };
        let Some(u) = OutputUnit::parse(unit) else {
            return Err(ModelError::UnknownUnit {
                key: self.key().to_string(),
                unit: unit.to_string(),
            });
        };
        if u.family != family {
            return Err(ModelError::UnitFamilyMismatch {
                key: self.key().to_string(),
                unit: unit.to_string(),
                key_family: family,
                unit_family: u.family,
            });
        }
        Ok(v * si / u.si_per_unit)
    }
}

/// A time window over which an output is averaged: $[t_0, t_0 + T]$, seconds from the start
/// of the calibration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Window {
    start_s: f64,
    duration_s: f64,
}

impl Window {
    /// The window $[t_0, t_0 + T]$.
    ///
    /// # Errors
    /// [`ModelError::Field`] for a non-finite start, not positive naming
    /// `duration_s` unless $T > 0$.
    pub fn new(start_s: f64, duration_s: f64) -> Result<Self, ModelError> {
        finite("start_s", start_s)?;
        positive("duration_s", duration_s)?;
        finite("end_s", start_s + duration_s)?;
        Ok(Self {
            start_s,
            duration_s,
        })
    }

    /// $t_0$, s.
    #[must_use]
    pub fn start_s(&self) -> f64 {
        self.start_s
    }

    /// $T$, s.
    #[must_use]
    pub fn duration_s(&self) -> f64 {
        self.duration_s
    }

    /// $t_0 + T$, s.
    #[must_use]
    pub fn end_s(&self) -> f64 {
        self.start_s + self.duration_s
    }

    /// The length of the intersection with `other`, s (0 for disjoint windows).
    #[must_use]
    pub fn overlap_s(&self, other: &Window) -> f64 {
        (self.end_s().min(other.end_s()) - self.start_s.max(other.start_s)).max(0.0)
    }
}

/// The bias instability as a first-order Gauss-Markov process: stationary standard deviation
/// $\sigma_b$ (output unit) and correlation time $T_c$ (s); autocovariance
/// $\sigma_b^2 e^{-|\Delta t|/T_c}$.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaussMarkov {
    sigma: f64,
    correlation_s: f64,
}

impl GaussMarkov {
    /// A process of stationary standard deviation `sigma` (output unit) and correlation time
    /// `correlation_s`.
    ///
    /// # Errors
    /// [`ModelError::Field`] (not finite, negative) naming `bias_sigma`,
    /// [`ModelError::Field`] (not positive) naming `bias_correlation_s`.
    pub fn new(sigma: f64, correlation_s: f64) -> Result<Self, ModelError> {
        non_negative("bias_sigma", sigma)?;
        positive("bias_correlation_s", correlation_s)?;
        Ok(Self {
            sigma,
            correlation_s,
        })
    }

    /// The process whose Allan deviation peaks at the flicker floor of a datasheet's bias
    /// instability $B$ (output unit): $\sigma_b = B\cdot$
    /// [`FLICKER_FLOOR_PER_BIAS_INSTABILITY`] $/$ [`GM_ADEV_PEAK_PER_SIGMA`] $= 1.0760\,B$
    /// (derivation in the [module documentation](self)); the peak lies at
    /// $\tau = 1.8926\,T_c$.
    ///
    /// # Errors
    /// As [`new`](Self::new), naming `bias_instability` for $B$.
    pub fn from_bias_instability(
        bias_instability: f64,
        correlation_s: f64,
    ) -> Result<Self, ModelError> {
        non_negative("bias_instability", bias_instability)?;
        Self::new(
            bias_instability * FLICKER_FLOOR_PER_BIAS_INSTABILITY / GM_ADEV_PEAK_PER_SIGMA,
            correlation_s,
        )
    }

    /// Stationary standard deviation $\sigma_b$, output unit.
    #[must_use]
    pub fn sigma(&self) -> f64 {
        self.sigma
    }

    /// Correlation time $T_c$, s.
    #[must_use]
    pub fn correlation_s(&self) -> f64 {
        self.correlation_s
    }

    /// The datasheet bias instability $B$ this process stands for (the inverse of
    /// [`from_bias_instability`](Self::from_bias_instability)), output unit.
    #[must_use]
    pub fn bias_instability(&self) -> f64 {
        self.sigma * GM_ADEV_PEAK_PER_SIGMA / FLICKER_FLOOR_PER_BIAS_INSTABILITY
    }

    /// $R(\Delta t) = \sigma_b^2 e^{-|\Delta t|/T_c}$, output unit squared.
    #[must_use]
    pub fn autocovariance(&self, dt_s: f64) -> f64 {
        self.sigma * self.sigma * (-dt_s.abs() / self.correlation_s).exp()
    }

    /// Allan variance at cluster time $\tau$ (El-Sheimy et al. 2008, Table I):
    /// $\frac{\sigma_b^2}{u^2}(2u - 3 + 4e^{-u} - e^{-2u})$, $u = \tau/T_c$, output unit
    /// squared ($0$ for $\tau \le 0$).
    #[must_use]
    pub fn allan_variance(&self, tau_s: f64) -> f64 {
        if tau_s.is_nan() || tau_s <= 0.0 {
            return 0.0;
        }
        let u = tau_s / self.correlation_s;
        let g = if u < SERIES_BELOW {
            // sum_{k>=3} (-1)^k (4 - 2^k)/k! u^k
            let (mut term, mut sum, mut two_k) = (1.0, 0.0, 1.0);
            for k in 1..=30 {
                term *= -u / f64::from(k);
                two_k *= 2.0;
                if k >= 3 {
                    sum += term * (4.0 - two_k);
                }
            }
            sum
        } else {
            2.0 * u - 3.0 + 4.0 * (-u).exp() - (-2.0 * u).exp()
        };
        self.sigma * self.sigma * g / (u * u)
    }

    /// Variance of the average over a window of length $T$:
    /// $\frac{2\sigma_b^2}{u^2}(u - 1 + e^{-u})$, $u = T/T_c$, output unit squared.
    #[must_use]
    pub fn variance_of_average(&self, window: &Window) -> f64 {
        let u = window.duration_s / self.correlation_s;
        2.0 * self.sigma * self.sigma * phi(u) / (u * u)
    }

    /// Covariance of the averages over two windows (closed form of the
    /// [module documentation](self); the factored form for disjoint windows), output unit
    /// squared.
    #[must_use]
    pub fn covariance_of_averages(&self, w1: &Window, w2: &Window) -> f64 {
        let tc = self.correlation_s;
        let s2 = self.sigma * self.sigma;
        let (first, second) = if w1.start_s <= w2.start_s {
            (w1, w2)
        } else {
            (w2, w1)
        };
        if second.start_s >= first.end_s() {
            let gap = second.start_s - first.end_s();
            return s2 * self.average_gain(first) * self.average_gain(second) * (-gap / tc).exp();
        }
        let (a, b, c, d) = (w1.start_s, w1.end_s(), w2.start_s, w2.end_s());
        let big_phi = |x: f64| phi(x.abs() / tc);
        s2 * tc * tc * (big_phi(b - c) - big_phi(a - c) - big_phi(b - d) + big_phi(a - d))
            / (w1.duration_s * w2.duration_s)
    }

    /// $T_c(1 - e^{-T/T_c})/T$: the factor a window contributes to its covariance with a
    /// disjoint window. Dimensionless.
    fn average_gain(&self, w: &Window) -> f64 {
        -self.correlation_s * (-w.duration_s / self.correlation_s).exp_m1() / w.duration_s
    }
}

/// The ratio of successive correlation times in a [`FlickerBank`]: $\sqrt{10}$, two terms
/// per decade. Dimensionless.
pub const FLICKER_BANK_RATIO: f64 = 3.162_277_660_168_379_5;

/// How far a [`FlickerBank`]'s correlation times reach beyond the time scales it stands for:
/// from the shortest over this factor to the longest times it. Dimensionless; with
/// [`FLICKER_BANK_RATIO`] the bank's Allan deviation is within 0.4% of the flicker floor
/// over those time scales (the truncated tails, $2/u$ and $2u/3$ of
/// $\int a(u)\,d\ln u = 2\ln 2$, and the ripple of the geometric spacing).
pub const FLICKER_BANK_REACH: f64 = 100.0;

/// Points per decade at which a [`FlickerBank`]'s Allan deviation is compared with the
/// flicker floor to state its fit error.
const FLICKER_CHECK_PER_DECADE: f64 = 16.0;

/// A flicker (1/f) bias instability of coefficient $B$ entered as a bank of first-order
/// Gauss-Markov terms over stated time scales $[\tau_{lo}, \tau_{hi}]$ (a schedule's
/// shortest dwell and its span), with the fit error stated.
///
/// Flicker noise has the two-sided power spectral density $B^2/(2\pi f)$ and the flat Allan
/// deviation $\sqrt{2\ln2/\pi}\,B$ (IEEE Std 952-1997, Annex C, C.1.3); its variance
/// diverges at low frequencies, so any covariance of window averages needs a stated cut.
/// A Gauss-Markov term $(\sigma^2, T_c)$ has the Allan variance $\sigma^2 a(\tau/T_c)$,
/// $a(u) = (2u - 3 + 4e^{-u} - e^{-2u})/u^2$, and $\int_0^\infty a(u)\,du/u = 2\ln 2$. Terms
/// of equal variance at correlation times spaced by the ratio $r$ in $\ln T_c$ therefore sum
/// to the Allan variance $\sigma^2\,2\ln2/\ln r$ wherever $\tau$ lies well inside their
/// range, which is the flicker floor $2\ln2\,B^2/\pi$ for
/// $$\sigma^2 = \frac{B^2 \ln r}{\pi}$$
/// (their spectra sum to $B^2/(2\pi f)$ over the same band). The bank spaces $T_c$ by
/// [`FLICKER_BANK_RATIO`] from $\tau_{lo}/$[`FLICKER_BANK_REACH`] to
/// $\tau_{hi}\cdot$[`FLICKER_BANK_REACH`]; below $1/(2\pi T_{c,\max})$ it has no power
/// (the cut: slower wander looks like a constant bias and a ramp over the test).
/// [`max_relative_adev_error`](Self::max_relative_adev_error) is the largest
/// $|\sigma_{bank}(\tau)/\sigma_{floor} - 1|$ over $[\tau_{lo}, \tau_{hi}]$, 16 points per
/// decade.
#[derive(Debug, Clone, PartialEq)]
pub struct FlickerBank {
    bias_instability: f64,
    terms: Vec<GaussMarkov>,
    time_scales_s: (f64, f64),
    max_relative_adev_error: f64,
}

impl FlickerBank {
    /// The bank of a flicker coefficient $B$ (output unit, $\ge 0$) over the time scales
    /// from `shortest_s` to `longest_s` (positive, finite; swapped if given the other way).
    #[must_use]
    pub fn new(bias_instability: f64, shortest_s: f64, longest_s: f64) -> Self {
        let (lo, hi) = if shortest_s <= longest_s {
            (shortest_s, longest_s)
        } else {
            (longest_s, shortest_s)
        };
        let r = FLICKER_BANK_RATIO;
        let tc_min = lo / FLICKER_BANK_REACH;
        let tc_max = hi * FLICKER_BANK_REACH;
        let count = ((tc_max / tc_min).ln() / r.ln()).ceil().max(0.0) as usize + 1;
        let sigma = bias_instability * (r.ln() / std::f64::consts::PI).sqrt();
        let terms: Vec<GaussMarkov> = (0..count)
            .map(|i| GaussMarkov {
                sigma,
                correlation_s: tc_min * r.powi(i as i32),
            })
            .collect();
        let mut bank = Self {
            bias_instability,
            terms,
            time_scales_s: (lo, hi),
            max_relative_adev_error: 0.0,
        };
        if bias_instability > 0.0 {
            let floor = bias_instability * FLICKER_FLOOR_PER_BIAS_INSTABILITY;
            let points = ((hi / lo).log10() * FLICKER_CHECK_PER_DECADE)
                .ceil()
                .max(1.0) as usize;
            let mut worst: f64 = 0.0;
            for k in 0..=points {
                let tau = lo * (hi / lo).powf(k as f64 / points as f64);
                worst = worst.max((bank.allan_variance(tau).sqrt() / floor - 1.0).abs());
            }
            bank.max_relative_adev_error = worst;
        }
        bank
    }

    /// The flicker coefficient $B$, output unit.
    #[must_use]
    pub fn bias_instability(&self) -> f64 {
        self.bias_instability
    }

    /// The Gauss-Markov terms, by increasing correlation time.
    #[must_use]
    pub fn terms(&self) -> &[GaussMarkov] {
        &self.terms
    }

    /// The time scales the bank stands for, `(shortest, longest)`, s.
    #[must_use]
    pub fn time_scales_s(&self) -> (f64, f64) {
        self.time_scales_s
    }

    /// The largest relative error of the bank's Allan deviation against the flicker floor
    /// over its time scales (the fit error; 0 for $B = 0$). Dimensionless.
    #[must_use]
    pub fn max_relative_adev_error(&self) -> f64 {
        self.max_relative_adev_error
    }

    /// The bank's Allan variance at cluster time $\tau$, output unit squared.
    #[must_use]
    pub fn allan_variance(&self, tau_s: f64) -> f64 {
        self.terms.iter().map(|t| t.allan_variance(tau_s)).sum()
    }

    /// Covariance of the bank's averages over two windows, output unit squared.
    #[must_use]
    pub fn covariance_of_averages(&self, w1: &Window, w2: &Window) -> f64 {
        self.terms
            .iter()
            .map(|t| t.covariance_of_averages(w1, w2))
            .sum()
    }
}

/// $\varphi(v) = e^{-v} - 1 + v$ for $v \ge 0$, by its series below [`SERIES_BELOW`] (the
/// closed form cancels there).
fn phi(v: f64) -> f64 {
    if v < SERIES_BELOW {
        // sum_{k>=2} (-v)^k / k!
        let (mut term, mut sum) = (-v, 0.0);
        for k in 2..=30 {
            term *= -v / f64::from(k);
            sum += term;
        }
        sum
    } else {
        (-v).exp_m1() + v
    }
}

/// The noise of one output: white density $N$, an optional Gauss-Markov bias, a
/// quantization step $q$, a rate random walk $K$ and a rate ramp $R$ (0 for none), all in the
/// output's unit (see the [module documentation](self)).
#[derive(Debug, Clone, PartialEq)]
pub struct NoiseModel {
    white_per_sqrt_hz: f64,
    bias: Option<GaussMarkov>,
    quantization: f64,
    rate_random_walk: f64,
    rate_ramp: f64,
    flicker: f64,
    angle_quantization: f64,
    /// Standard uncertainty of each parameter, in the order of [`NoiseParameter::ALL`]
    /// (0: none given).
    uncertainty: [f64; NoiseParameter::ALL.len()],
}

/// A parameter of a [`NoiseModel`], for its uncertainty and the answers' sensitivity to it.
/// Values in the model's units: output unit per $\sqrt{\mathrm{Hz}}$ (white), output unit
/// (the Gauss-Markov $\sigma_b$, flicker $B$, quantization step), s (correlation time),
/// output unit times s (angle quantization), per $\sqrt{\mathrm s}$ (rate random walk), per s
/// (rate ramp).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum NoiseParameter {
    /// White density $N$.
    White,
    /// The Gauss-Markov bias's stationary standard deviation $\sigma_b$.
    BiasSigma,
    /// The Gauss-Markov bias's correlation time $T_c$.
    BiasCorrelation,
    /// The flicker coefficient $B$.
    Flicker,
    /// The quantization step $q$ of the samples.
    Quantization,
    /// Angle quantization $Q$.
    AngleQuantization,
    /// Rate random walk $K$.
    RateRandomWalk,
    /// Rate ramp $R$.
    RateRamp,
}

impl NoiseParameter {
    /// Every parameter.
    pub const ALL: [NoiseParameter; 8] = [
        NoiseParameter::White,
        NoiseParameter::BiasSigma,
        NoiseParameter::BiasCorrelation,
        NoiseParameter::Flicker,
        NoiseParameter::Quantization,
        NoiseParameter::AngleQuantization,
        NoiseParameter::RateRandomWalk,
        NoiseParameter::RateRamp,
    ];

    /// A short name: `white`, `bias_sigma`, `bias_correlation_s`, `flicker_bias_instability`,
    /// `quantization`, `angle_quantization`, `rate_random_walk`, `rate_ramp`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            NoiseParameter::White => "white",
            NoiseParameter::BiasSigma => "bias_sigma",
            NoiseParameter::BiasCorrelation => "bias_correlation_s",
            NoiseParameter::Flicker => "flicker_bias_instability",
            NoiseParameter::Quantization => "quantization",
            NoiseParameter::AngleQuantization => "angle_quantization",
            NoiseParameter::RateRandomWalk => "rate_random_walk",
            NoiseParameter::RateRamp => "rate_ramp",
        }
    }

    fn index(self) -> usize {
        Self::ALL.iter().position(|p| *p == self).unwrap_or(0)
    }
}

/// The covariance of an output's averages over $n$ windows, split into its white part (white
/// noise and quantization: non-zero only where windows overlap, diagonal for a calibration)
/// and its correlated part (the Gauss-Markov bias, the rate random walk and the rate ramp).
/// Output unit squared, $n\times n$, in the order of the windows given.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct WindowCovariance {
    /// White noise and quantization.
    pub(crate) white: DMatrix<f64>,
    /// The Gauss-Markov bias instability, the flicker bank, rate random walk and rate ramp.
    pub(crate) correlated: DMatrix<f64>,
    /// The bank that stands for the flicker term, with its fit error (`None`: no flicker).
    pub(crate) flicker: Option<FlickerBank>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl WindowCovariance {
    /// White noise and quantization.
    #[must_use]
    pub fn white(&self) -> &DMatrix<f64> {
        &self.white
    }

    /// The Gauss-Markov bias instability, the flicker bank, rate random walk and rate ramp.
    #[must_use]
    pub fn correlated(&self) -> &DMatrix<f64> {
        &self.correlated
    }

    /// The Gauss-Markov bank the flicker term was entered as, with its fit error (`None`
    /// without a flicker term).
    #[must_use]
    pub fn flicker(&self) -> Option<&FlickerBank> {
        self.flicker.as_ref()
    }
}

impl WindowCovariance {
    /// `white + correlated`.
    #[must_use]
    pub fn total(&self) -> DMatrix<f64> {
        &self.white + &self.correlated
    }
}

impl NoiseModel {
    /// A noise model: white density $N$ (output unit/$\sqrt{\mathrm{Hz}}$), the bias
    /// instability (`None` for none) and the quantization step $q$ (output unit; 0 for none).
    ///
    /// # Errors
    /// [`ModelError::Field`] (not finite, negative) naming `white_per_sqrt_hz` or
    /// `quantization`.
    pub fn new(
        white_per_sqrt_hz: f64,
        bias: Option<GaussMarkov>,
        quantization: f64,
    ) -> Result<Self, ModelError> {
        non_negative("white_per_sqrt_hz", white_per_sqrt_hz)?;
        non_negative("quantization", quantization)?;
        Ok(Self {
            white_per_sqrt_hz,
            bias,
            quantization,
            rate_random_walk: 0.0,
            rate_ramp: 0.0,
            flicker: 0.0,
            angle_quantization: 0.0,
            uncertainty: [0.0; NoiseParameter::ALL.len()],
        })
    }

    /// The value of parameter `p` (0 for a term the model does not have), in the model's
    /// units ([`NoiseParameter`]).
    #[must_use]
    pub fn value(&self, p: NoiseParameter) -> f64 {
        match p {
            NoiseParameter::White => self.white_per_sqrt_hz,
            NoiseParameter::BiasSigma => self.bias.map_or(0.0, |b| b.sigma),
            NoiseParameter::BiasCorrelation => self.bias.map_or(0.0, |b| b.correlation_s),
            NoiseParameter::Flicker => self.flicker,
            NoiseParameter::Quantization => self.quantization,
            NoiseParameter::AngleQuantization => self.angle_quantization,
            NoiseParameter::RateRandomWalk => self.rate_random_walk,
            NoiseParameter::RateRamp => self.rate_ramp,
        }
    }

    /// The standard uncertainty of parameter `p` (0: none given), in its unit.
    #[must_use]
    pub fn uncertainty(&self, p: NoiseParameter) -> f64 {
        self.uncertainty[p.index()]
    }

    /// The model with the standard uncertainty `u` of parameter `p`, in its unit.
    ///
    /// # Errors
    /// [`ModelError::Field`] (not finite, negative) naming `<name>_uncertainty`
    /// ([`NoiseParameter::name`]).
    pub fn with_uncertainty(mut self, p: NoiseParameter, u: f64) -> Result<Self, ModelError> {
        let field = format!("{}_uncertainty", p.name());
        self.uncertainty[p.index()] = non_negative(&field, u)?;
        Ok(self)
    }

    /// The model with parameter `p` moved by `k` standard uncertainties (others unchanged),
    /// clipped at 0 (a correlation time at a thousandth of its value); `None` when `p` has
    /// no uncertainty or the model has no such term.
    #[must_use]
    pub fn perturbed(&self, p: NoiseParameter, k: f64) -> Option<Self> {
        let u = self.uncertainty(p);
        let v = self.value(p);
        let has_term = match p {
            NoiseParameter::BiasSigma | NoiseParameter::BiasCorrelation => self.bias.is_some(),
            _ => true,
        };
        if !(u > 0.0 && has_term && k.is_finite()) {
            return None;
        }
        let moved = (v + k * u).max(0.0);
        let mut m = self.clone();
        match p {
            NoiseParameter::White => m.white_per_sqrt_hz = moved,
            NoiseParameter::BiasSigma => {
                if let Some(b) = m.bias.as_mut() {
                    b.sigma = moved;
                }
            }
            NoiseParameter::BiasCorrelation => {
                if let Some(b) = m.bias.as_mut() {
                    b.correlation_s = moved.max(1e-3 * v);
                }
            }
            NoiseParameter::Flicker => m.flicker = moved,
            NoiseParameter::Quantization => m.quantization = moved,
            NoiseParameter::AngleQuantization => m.angle_quantization = moved,
            NoiseParameter::RateRandomWalk => m.rate_random_walk = moved,
            NoiseParameter::RateRamp => m.rate_ramp = moved,
        }
        Some(m)
    }

    /// The model with a flicker (1/f) bias instability of coefficient $B$ (output unit; 0 for
    /// none): the flat Allan-deviation floor $\sigma(\tau) = 0.6643\,B$ of IEEE Std 952,
    /// entered into [`window_covariance`](Self::window_covariance) as the [`FlickerBank`]
    /// over the schedule's time scales.
    ///
    /// # Errors
    /// [`ModelError::Field`] (not finite, negative) naming `flicker_bias_instability`.
    pub fn with_flicker(mut self, bias_instability: f64) -> Result<Self, ModelError> {
        self.flicker = non_negative("flicker_bias_instability", bias_instability)?;
        Ok(self)
    }

    /// The model with an angle (velocity) quantization $Q$ (output unit times s; 0 for none):
    /// the standard deviation of the integrated output's error at each reading, independent
    /// from one reading to the next, $\sigma(\tau) = \sqrt3\,Q/\tau$ (IEEE Std 952-1997,
    /// Annex C, C.1.1).
    ///
    /// # Errors
    /// [`ModelError::Field`] (not finite, negative) naming `angle_quantization`.
    pub fn with_angle_quantization(mut self, q_times_s: f64) -> Result<Self, ModelError> {
        self.angle_quantization = non_negative("angle_quantization", q_times_s)?;
        Ok(self)
    }

    /// The flicker coefficient $B$, output unit (0: none).
    #[must_use]
    pub fn flicker(&self) -> f64 {
        self.flicker
    }

    /// Angle quantization $Q$, output unit times s (0: none).
    #[must_use]
    pub fn angle_quantization(&self) -> f64 {
        self.angle_quantization
    }

    /// The Gauss-Markov bank that stands for the flicker term over the time scales of
    /// `windows` (shortest window to the span from the first start to the last end), `None`
    /// without a flicker term or windows.
    #[must_use]
    pub fn flicker_bank(&self, windows: &[Window]) -> Option<FlickerBank> {
        if self.flicker <= 0.0 || windows.is_empty() {
            return None;
        }
        let shortest = windows
            .iter()
            .map(|w| w.duration_s)
            .fold(f64::INFINITY, f64::min);
        let first = windows
            .iter()
            .map(|w| w.start_s)
            .fold(f64::INFINITY, f64::min);
        let last = windows
            .iter()
            .map(Window::end_s)
            .fold(f64::NEG_INFINITY, f64::max);
        Some(FlickerBank::new(
            self.flicker,
            shortest,
            (last - first).max(shortest),
        ))
    }

    /// Covariance of the angle-quantization parts of two windows' averages:
    /// $Q^2[\delta(b,d) - \delta(b,c) - \delta(a,d) + \delta(a,c)]/(T_1T_2)$ for
    /// $W_1 = [a, b]$, $W_2 = [c, d]$, $\delta$ one where two readings coincide: $2Q^2/T^2$
    /// for one window, $-Q^2/(T_1T_2)$ where one window ends as the other starts, output
    /// unit squared.
    #[must_use]
    pub fn angle_quantization_covariance_of_averages(&self, w1: &Window, w2: &Window) -> f64 {
        if self.angle_quantization <= 0.0 {
            return 0.0;
        }
        let same = |x: f64, y: f64| {
            let scale = x.abs().max(y.abs()).max(1.0);
            (x - y).abs() <= SAME_READING_RELATIVE * scale
        };
        let d = |x: f64, y: f64| if same(x, y) { 1.0 } else { 0.0 };
        let (a, b, c, e) = (w1.start_s, w1.end_s(), w2.start_s, w2.end_s());
        self.angle_quantization.powi(2) * (d(b, e) - d(b, c) - d(a, e) + d(a, c))
            / (w1.duration_s * w2.duration_s)
    }

    /// The model with a rate random walk of density $K$ (output unit per $\sqrt{\mathrm s}$;
    /// 0 for none): $\sigma(\tau) = K\sqrt{\tau/3}$.
    ///
    /// # Errors
    /// [`ModelError::Field`] (not finite, negative) naming `rate_random_walk`.
    pub fn with_rate_random_walk(mut self, k_per_sqrt_s: f64) -> Result<Self, ModelError> {
        self.rate_random_walk = non_negative("rate_random_walk", k_per_sqrt_s)?;
        Ok(self)
    }

    /// The model with a rate ramp of standard deviation $R$ (output unit per s; 0 for none):
    /// $\sigma(\tau) = R\tau/\sqrt2$.
    ///
    /// # Errors
    /// [`ModelError::Field`] (not finite, negative) naming `rate_ramp`.
    pub fn with_rate_ramp(mut self, r_per_s: f64) -> Result<Self, ModelError> {
        self.rate_ramp = non_negative("rate_ramp", r_per_s)?;
        Ok(self)
    }

    /// Rate random walk density $K$, output unit per $\sqrt{\mathrm s}$ (0: none).
    #[must_use]
    pub fn rate_random_walk(&self) -> f64 {
        self.rate_random_walk
    }

    /// Rate ramp $R$, output unit per s (0: none).
    #[must_use]
    pub fn rate_ramp(&self) -> f64 {
        self.rate_ramp
    }

    /// Covariance of the drift parts (rate random walk and rate ramp) of two windows'
    /// averages: $K^2\,\overline{\min}(W_1, W_2) + R^2 m_1 m_2$ (closed forms of the
    /// [module documentation](self), time clipped at the start $t_0 = 0$), output unit
    /// squared.
    #[must_use]
    pub fn drift_covariance_of_averages(&self, w1: &Window, w2: &Window) -> f64 {
        let mut c = 0.0;
        if self.rate_random_walk > 0.0 {
            c += self.rate_random_walk.powi(2) * mean_min_over_windows(w1, w2);
        }
        if self.rate_ramp > 0.0 {
            c += self.rate_ramp.powi(2) * mean_time_since_start(w1) * mean_time_since_start(w2);
        }
        c
    }

    /// Variance of the drift parts (rate random walk and rate ramp) of a window's average:
    /// $K^2(t_0 + T/3) + R^2 m^2$ for a window in $t \ge 0$, output unit squared.
    #[must_use]
    pub fn drift_variance_of_average(&self, window: &Window) -> f64 {
        self.drift_covariance_of_averages(window, window)
    }

    /// The noise model from datasheet values for an output whose unit label is `unit`: a
    /// white density in any of the datasheet units, the bias instability $B$ with its
    /// correlation time (s), and the quantization step (output unit).
    ///
    /// # Errors
    /// As [`WhiteDensity::in_output_unit`], [`GaussMarkov::from_bias_instability`] and
    /// [`new`](Self::new); each error names the study key (`white_deg_per_sqrt_h`,
    /// `bias_instability`, `bias_correlation_s`, `quantization`).
    pub fn from_datasheet(
        unit: &str,
        white: Option<WhiteDensity>,
        bias_instability_and_correlation_s: Option<(f64, f64)>,
        quantization: Option<f64>,
    ) -> Result<Self, ModelError> {
        let n = white.map_or(Ok(0.0), |w| w.in_output_unit(unit))?;
        let bias = bias_instability_and_correlation_s
            .map(|(b, tc)| GaussMarkov::from_bias_instability(b, tc))
            .transpose()?;
        Self::new(n, bias, quantization.unwrap_or(0.0))
    }

    /// White density $N$, output unit/$\sqrt{\mathrm{Hz}}$.
    #[must_use]
    pub fn white_per_sqrt_hz(&self) -> f64 {
        self.white_per_sqrt_hz
    }

    /// The Gauss-Markov bias, if any.
    #[must_use]
    pub fn bias(&self) -> Option<&GaussMarkov> {
        self.bias.as_ref()
    }

    /// Quantization step $q$, output unit (0: none).
    #[must_use]
    pub fn quantization(&self) -> f64 {
        self.quantization
    }

    /// Variance of one sample's white part at sample rate $f_s$ (white noise and
    /// quantization): $N^2 f_s + q^2/12$, output unit squared.
    #[must_use]
    pub fn white_sample_variance(&self, sample_rate_hz: f64) -> f64 {
        self.white_per_sqrt_hz.powi(2) * sample_rate_hz + self.quantization.powi(2) / 12.0
    }

    /// Variance of the white part (white noise, quantization and angle quantization) of the
    /// average over a window at sample rate $f_s$: $N^2/T + q^2/(12 f_s T) + 2Q^2/T^2$,
    /// output unit squared.
    #[must_use]
    pub fn white_variance_of_average(&self, window: &Window, sample_rate_hz: f64) -> f64 {
        self.white_sample_variance(sample_rate_hz) / (sample_rate_hz * window.duration_s)
            + 2.0 * (self.angle_quantization / window.duration_s).powi(2)
    }

    /// Variance of the quantization part alone of a window's average: $q^2/(12 f_s T)$,
    /// output unit squared.
    #[must_use]
    pub fn quantization_variance_of_average(&self, window: &Window, sample_rate_hz: f64) -> f64 {
        self.quantization.powi(2) / (12.0 * sample_rate_hz * window.duration_s)
    }

    /// Variance of the Gauss-Markov part of a window's average (0 without a bias model),
    /// output unit squared.
    #[must_use]
    pub fn correlated_variance_of_average(&self, window: &Window) -> f64 {
        self.bias.map_or(0.0, |b| b.variance_of_average(window))
    }

    /// Variance of a window's average, every part but flicker (whose bank depends on the
    /// schedule's time scales: [`flicker_bank`](Self::flicker_bank),
    /// [`window_covariance`](Self::window_covariance)), output unit squared.
    #[must_use]
    pub fn variance_of_average(&self, window: &Window, sample_rate_hz: f64) -> f64 {
        self.white_variance_of_average(window, sample_rate_hz)
            + self.correlated_variance_of_average(window)
            + self.drift_variance_of_average(window)
    }

    /// Covariance of the white parts of two windows' averages:
    /// $(N^2 + q^2/(12 f_s))\,|W_1\cap W_2|/(T_1T_2)$ plus the angle quantization's
    /// ([`angle_quantization_covariance_of_averages`](Self::angle_quantization_covariance_of_averages)),
    /// output unit squared.
    #[must_use]
    pub fn white_covariance_of_averages(
        &self,
        w1: &Window,
        w2: &Window,
        sample_rate_hz: f64,
    ) -> f64 {
        let overlap = w1.overlap_s(w2);
        let q = self.angle_quantization_covariance_of_averages(w1, w2);
        if overlap <= 0.0 {
            return q;
        }
        self.white_sample_variance(sample_rate_hz) / sample_rate_hz * overlap
            / (w1.duration_s * w2.duration_s)
            + q
    }

    /// Covariance of two windows' averages, every part but flicker (see
    /// [`variance_of_average`](Self::variance_of_average)), output unit squared.
    #[must_use]
    pub fn covariance_of_averages(&self, w1: &Window, w2: &Window, sample_rate_hz: f64) -> f64 {
        self.white_covariance_of_averages(w1, w2, sample_rate_hz)
            + self.bias.map_or(0.0, |b| b.covariance_of_averages(w1, w2))
            + self.drift_covariance_of_averages(w1, w2)
    }

    /// The covariance of the averages over `windows` at sample rate $f_s$, white and
    /// correlated parts, in the order given.
    ///
    /// For windows that do not overlap (a calibration's positions) the white part is
    /// diagonal and the correlated part is built from the factored closed form with one
    /// exponential per window and per gap, in time order: for $t_i < t_j$,
    /// $C_{ij} = \sigma_b^2 h_i h_j e^{-(t_j - e_i)/T_c}$, $h = T_c(1-e^{-T/T_c})/T$, $e_i$
    /// the end of window $i$, and $e^{-(t_{j} - e_i)/T_c} = e^{-(t_{j-1} - e_i)/T_c}\,
    /// e^{-(t_j - t_{j-1})/T_c}$. Overlapping windows fall back to the general closed form
    /// pair by pair. The drifts (rate random walk, rate ramp) are added pair by pair from
    /// their closed forms ($O(n^2)$ products, no transcendental function).
    ///
    /// # Errors
    /// [`ModelError::Field`] (not positive) naming `sample_rate_hz`.
    pub fn window_covariance(
        &self,
        windows: &[Window],
        sample_rate_hz: f64,
    ) -> Result<WindowCovariance, ModelError> {
        positive("sample_rate_hz", sample_rate_hz)?;
        let n = windows.len();
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&i, &j| windows[i].start_s.total_cmp(&windows[j].start_s));
        let disjoint = order
            .windows(2)
            .all(|p| windows[p[1]].start_s >= windows[p[0]].end_s());
        let mut white = DMatrix::zeros(n, n);
        let mut correlated = DMatrix::zeros(n, n);
        if disjoint {
            for (i, w) in windows.iter().enumerate() {
                white[(i, i)] = self.white_variance_of_average(w, sample_rate_hz);
            }
        } else {
            for i in 0..n {
                for j in 0..=i {
                    let c =
                        self.white_covariance_of_averages(&windows[i], &windows[j], sample_rate_hz);
                    white[(i, j)] = c;
                    white[(j, i)] = c;
                }
            }
        }
        if disjoint && self.angle_quantization > 0.0 {
            // between windows that share a reading: one ends where the next starts
            for p in order.windows(2) {
                let (i, j) = (p[0], p[1]);
                let c = self.angle_quantization_covariance_of_averages(&windows[i], &windows[j]);
                white[(i, j)] += c;
                white[(j, i)] += c;
            }
        }
        if self.rate_random_walk > 0.0 || self.rate_ramp > 0.0 {
            for i in 0..n {
                for j in 0..=i {
                    let c = self.drift_covariance_of_averages(&windows[i], &windows[j]);
                    correlated[(i, j)] = c;
                    correlated[(j, i)] = c;
                }
            }
        }
        let flicker = self.flicker_bank(windows);
        let bank = flicker.as_ref().map_or(&[][..], |f| f.terms.as_slice());
        for bias in self.bias.iter().chain(bank).filter(|b| b.sigma > 0.0) {
            add_gauss_markov(bias, windows, &order, disjoint, &mut correlated);
        }
        Ok(WindowCovariance {
            white,
            correlated,
            flicker,
        })
    }
}

/// Add the covariance of a Gauss-Markov term's averages over `windows` (`order`: their
/// indices in time order; `disjoint`: no two overlap) to `correlated`.
fn add_gauss_markov(
    bias: &GaussMarkov,
    windows: &[Window],
    order: &[usize],
    disjoint: bool,
    correlated: &mut DMatrix<f64>,
) {
    let n = windows.len();
    if !disjoint {
        for i in 0..n {
            for j in 0..=i {
                let c = bias.covariance_of_averages(&windows[i], &windows[j]);
                correlated[(i, j)] += c;
                if i != j {
                    correlated[(j, i)] += c;
                }
            }
        }
        return;
    }
    let tc = bias.correlation_s;
    let gain: Vec<f64> = order
        .iter()
        .map(|&i| bias.sigma * bias.average_gain(&windows[i]))
        .collect();
    // step[k] = exp(-(t_k - t_{k-1}) / Tc) in time order; gap[k] = exp(-(t_{k+1} - e_k) / Tc).
    let step: Vec<f64> = (0..n)
        .map(|k| {
            if k == 0 {
                1.0
            } else {
                (-(windows[order[k]].start_s - windows[order[k - 1]].start_s) / tc).exp()
            }
        })
        .collect();
    for (k, &i) in order.iter().enumerate() {
        correlated[(i, i)] += bias.variance_of_average(&windows[i]);
        if k + 1 == n {
            break;
        }
        let mut e = (-(windows[order[k + 1]].start_s - windows[i].end_s()) / tc).exp();
        for l in (k + 1)..n {
            if l > k + 1 {
                e *= step[l];
            }
            if e < CORRELATION_UNDERFLOW {
                break;
            }
            let j = order[l];
            let c = gain[k] * gain[l] * e;
            correlated[(i, j)] += c;
            correlated[(j, i)] += c;
        }
    }
}

/// The window's part in $t \ge 0$ (the drifts start at $t_0 = 0$): `(start, end)`, empty
/// (`start == end`) for a window wholly before the start.
fn after_start(w: &Window) -> (f64, f64) {
    (w.start_s.max(0.0), w.end_s().max(0.0))
}

/// $\frac{1}{T}\int_W \max(t, 0)\,dt$: the window's mean time since the start, s.
fn mean_time_since_start(w: &Window) -> f64 {
    let (a, b) = after_start(w);
    (b - a) * 0.5 * (a + b) / w.duration_s
}

/// $\frac{1}{T_1T_2}\int_{W_1}\!\int_{W_2}\min(s^+, r^+)\,dr\,ds$, s: the covariance of the
/// averages of a unit Wiener process started at $t_0 = 0$ (closed form of the
/// [module documentation](self)).
fn mean_min_over_windows(w1: &Window, w2: &Window) -> f64 {
    let ((a, b), (c, d)) = (after_start(w1), after_start(w2));
    let (l1, l2) = (b - a, d - c);
    if l1 <= 0.0 || l2 <= 0.0 {
        return 0.0;
    }
    let integral = if b <= c {
        l2 * l1 * 0.5 * (a + b)
    } else if d <= a {
        l1 * l2 * 0.5 * (c + d)
    } else {
        // overlapping: shift the origin to the earlier start o, min(s, r) = o + min(s-o, r-o)
        let o = a.min(c);
        let g = |x: f64, y: f64| {
            let (m, big) = if x <= y { (x, y) } else { (y, x) };
            m * m * (0.5 * big - m / 6.0)
        };
        let (a, b, c, d) = (a - o, b - o, c - o, d - o);
        l1 * l2 * o + (g(b, d) - g(a, d) - g(b, c) + g(a, c))
    };
    integral / (w1.duration_s * w2.duration_s)
}
