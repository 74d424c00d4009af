//! Seeded draws of the noise tests' Monte Carlo (gw-model's window covariances and
//! calib-lsq's coefficient covariances simulated sample by sample): one definition, so the
//! two crates' simulations draw alike.

use rand_chacha::ChaCha8Rng;
use rand_core::Rng;

/// A uniform in (0, 1) from 53 random bits (the midpoint of one of $2^{53}$ equal cells, so
/// never 0 or 1).
pub fn uniform(rng: &mut ChaCha8Rng) -> f64 {
    ((rng.next_u64() >> 11) as f64 + 0.5) * (1.0 / (1u64 << 53) as f64)
}

/// Two independent standard normals (Box-Muller on two [`uniform`] draws).
pub fn normals(rng: &mut ChaCha8Rng) -> (f64, f64) {
    let (u1, u2) = (uniform(rng), uniform(rng));
    let r = (-2.0 * u1.ln()).sqrt();
    let t = 2.0 * std::f64::consts::PI * u2;
    (r * t.cos(), r * t.sin())
}
