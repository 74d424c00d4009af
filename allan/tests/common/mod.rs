//! Synthetic logs with known noise, their exact Allan variance, and a direct (whole log in
//! memory) overlapping Allan deviation written independently of the crate.
#![allow(dead_code)]

use rand_chacha::ChaCha8Rng;
use rand_core::{Rng, SeedableRng};

/// Standard normal draws (Box-Muller on a seeded ChaCha8 stream).
pub(crate) struct Normal {
    rng: ChaCha8Rng,
    spare: Option<f64>,
}

impl Normal {
    pub(crate) fn new(seed: u64) -> Self {
        Self {
            rng: ChaCha8Rng::seed_from_u64(seed),
            spare: None,
        }
    }

    fn uniform(&mut self) -> f64 {
        // (0, 1]: 53 random bits
        ((self.rng.next_u64() >> 11) + 1) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    pub(crate) fn draw(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        let r = (-2.0 * self.uniform().ln()).sqrt();
        let th = 2.0 * std::f64::consts::PI * self.uniform();
        self.spare = Some(r * th.sin());
        r * th.cos()
    }
}

/// A log: white noise of standard deviation `white_sd` per sample, a random walk whose
/// increments have standard deviation `rw_step` per sample, and first-order Gauss-Markov
/// (discrete AR(1)) components `(sd, phi)`, plus a constant `bias`.
#[derive(Debug, Clone)]
pub(crate) struct Recipe {
    pub bias: f64,
    pub white_sd: f64,
    pub rw_step: f64,
    pub gauss_markov: Vec<(f64, f64)>,
}

impl Recipe {
    pub(crate) fn white(sd: f64) -> Self {
        Self {
            bias: 0.0,
            white_sd: sd,
            rw_step: 0.0,
            gauss_markov: Vec::new(),
        }
    }

    /// Streams the log's samples to `visit`.
    pub(crate) fn generate(&self, samples: u64, seed: u64, mut visit: impl FnMut(f64)) {
        let mut g = Normal::new(seed);
        let mut rw = 0.0;
        let mut gm: Vec<f64> = self
            .gauss_markov
            .iter()
            .map(|(sd, _)| sd * g.draw())
            .collect();
        for _ in 0..samples {
            let mut y = self.bias;
            if self.white_sd > 0.0 {
                y += self.white_sd * g.draw();
            }
            if self.rw_step > 0.0 {
                rw += self.rw_step * g.draw();
                y += rw;
            }
            for (x, (sd, phi)) in gm.iter_mut().zip(&self.gauss_markov) {
                *x = phi * *x + sd * (1.0 - phi * phi).sqrt() * g.draw();
                y += *x;
            }
            visit(y);
        }
    }

    pub(crate) fn collect(&self, samples: u64, seed: u64) -> Vec<f64> {
        let mut v = Vec::with_capacity(samples as usize);
        self.generate(samples, seed, |y| v.push(y));
        v
    }

    /// The exact Allan variance at cluster `m` (samples) of this discrete process (log unit^2):
    /// white sigma^2/m; random walk q^2 (2m^2 + 1)/(6m); AR(1) (Var S - Cov(S1, S2))/m^2 with
    /// S a sum of m consecutive samples.
    pub(crate) fn avar(&self, m: u64) -> f64 {
        let mf = m as f64;
        let mut v = self.white_sd * self.white_sd / mf;
        v += self.rw_step * self.rw_step * (2.0 * mf * mf + 1.0) / (6.0 * mf);
        for &(sd, phi) in &self.gauss_markov {
            v += ar1_avar(sd * sd, phi, m);
        }
        v
    }
}

/// Allan variance of a stationary AR(1) of variance `var` and coefficient `phi` at cluster `m`:
/// with gamma_e = var phi^|e| and S1, S2 sums of m consecutive samples,
/// Var S = var [m + 2 sum_{e=1}^{m-1} (m - e) phi^e],
/// Cov(S1, S2) = var sum_{e=1}^{2m-1} min(e, 2m - e) phi^e, AVAR = (Var S - Cov)/m^2.
pub(crate) fn ar1_avar(var: f64, phi: f64, m: u64) -> f64 {
    let mf = m as f64;
    let mut var_s = mf;
    let mut cov = 0.0;
    let mut pe = 1.0;
    for e in 1..2 * m {
        pe *= phi;
        if pe == 0.0 {
            break;
        }
        let ef = e as f64;
        if e < m {
            var_s += 2.0 * (mf - ef) * pe;
        }
        cov += ef.min(2.0 * mf - ef) * pe;
    }
    var * (var_s - cov) / (mf * mf)
}

/// The fully overlapping Allan deviation at cluster `m` of a whole log, the textbook way:
/// cluster means of every window of m samples, differences of adjacent windows, mean square
/// / 2. (No phase, no streaming: an independent reference.)
pub(crate) fn direct_oadev(y: &[f64], m: usize) -> f64 {
    let n = y.len();
    assert!(2 * m <= n);
    // prefix sums in a wider type for exact window means
    let mut prefix = Vec::with_capacity(n + 1);
    let mut acc = 0.0f64;
    let mut comp = 0.0f64;
    prefix.push(0.0);
    for &v in y {
        // Kahan-compensated prefix sums
        let t = v - comp;
        let s = acc + t;
        comp = (s - acc) - t;
        acc = s;
        prefix.push(acc);
    }
    let mut sum = 0.0;
    let terms = n - 2 * m + 1;
    for t in 0..terms {
        let a = (prefix[t + m] - prefix[t]) / m as f64;
        let b = (prefix[t + 2 * m] - prefix[t + m]) / m as f64;
        sum += (b - a) * (b - a);
    }
    (sum / (2.0 * terms as f64)).sqrt()
}

/// A flicker-like bias: first-order Gauss-Markov components of equal variance with
/// correlation times `t_min_s * ratio^j` up to `t_max_s`, whose summed two-sided density
/// approximates B^2 / (2 pi f) between 1/(2 pi t_max) and 1/(2 pi t_min): each component of
/// variance q^2 and time T has density 2 q^2 T / (1 + (2 pi f T)^2); summed over
/// log-spaced T this is about q^2 / (2 f ln ratio), so q^2 = B^2 ln(ratio) / pi.
/// Returns the `(sd, phi)` pairs of the discrete AR(1) components at `rate_hz`.
pub(crate) fn flicker_components(
    b: f64,
    rate_hz: f64,
    t_min_s: f64,
    t_max_s: f64,
) -> Vec<(f64, f64)> {
    let ratio: f64 = 10f64.sqrt();
    let sd = (ratio.ln() / std::f64::consts::PI).sqrt() * b;
    let mut out = Vec::new();
    let mut t = t_min_s;
    while t <= t_max_s * (1.0 + 1e-12) {
        out.push((sd, (-1.0 / (t * rate_hz)).exp()));
        t *= ratio;
    }
    out
}
