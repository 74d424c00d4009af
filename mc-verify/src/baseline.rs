//! The crate's earlier specialised kernel for the paper's two-axis table, kept as a
//! reference and a benchmark baseline (it is not used by [`crate::MonteCarlo::run`]).
//!
//! Until turntables became data, the Monte Carlo evaluated only the paper's Table 3 with a
//! hand-unrolled quaternion chain:
//! $$\Delta\mathbf R = R_z(-\phi_2)\,\mathbf E_1\,R_z(\phi_2)\,\mathbf E_2,\quad
//!   \mathbf E_1 = R_y(\Delta\phi_{y1}) R_z(\Delta\alpha_{z1}) R_x(\Delta\alpha_{x1})
//!   R_y(\Delta\varepsilon_y) R_x(\Delta\varepsilon_x),\quad
//!   \mathbf E_2 = R_y(\Delta\alpha_{y2}) R_z(\Delta\phi_{z2}) R_x(\Delta\alpha_{x2}),$$
//! per sample with all eight error inputs in registers, in the same tiers as
//! [`crate::fast`]. This module is a verbatim copy of that kernel (driver, statistics and
//! sampling are shared with the general path). Two uses:
//! - proof that the general plan interpreter reproduces it bit for bit on the paper's table
//!   (`tests/paper_identity.rs`);
//! - the baseline of the throughput goal "the paper's table through the general plan reaches
//!   at least 90 % of the specialised kernel" (`benches/mc_throughput.rs`,
//!   `examples/throughput.rs`).

use crate::error::McError;
use crate::fast::{
    BlockKernel, SHORT_SERIES_MAX_ABS_RAD, TIER_ANY, TIER_MEDIUM, TIER_SHORT, TurnTable,
    half_sin_cos, half_sin_cos_series, half_sin_cos_short, sin_cos_turn_with, turn_table,
};
use crate::run::{McResult, MonteCarlo};
use crate::sampler::{BLOCK_CAPACITY, SampleBlock, TurntableSampler};
use crate::simd::SimdLevel;
use crate::{SERIES_MAX_ABS_RAD, Tier};
use tt_kinematics::paper;

/// Angular errors of the paper's table.
const CHI_LEN: usize = 8;

/// [`paper_kernel_run_with_simd`] on the widest SIMD level of the CPU.
///
/// # Errors
/// [`McError::NotThePaperTable`] unless `mc`'s turntable is the paper's Table 3 (same
/// evaluation plan, both joints full turns).
pub fn paper_kernel_run(mc: &MonteCarlo) -> Result<McResult, McError> {
    paper_kernel_run_with_simd(mc, SimdLevel::detected())
}

/// The run of `mc` (same samples, same statistics) with the kept specialised paper kernel
/// instead of the general plan, its hot loop compiled for `level`.
///
/// # Errors
/// [`McError::NotThePaperTable`] unless `mc`'s turntable is the paper's Table 3;
/// [`McError::SimdUnavailable`] if the CPU lacks `level`.
pub fn paper_kernel_run_with_simd(mc: &MonteCarlo, level: SimdLevel) -> Result<McResult, McError> {
    let level = level.check()?;
    let t = mc.turntable().ok_or(McError::NotThePaperTable)?;
    let paper = paper::table3();
    let full_turn = [0.0, std::f64::consts::TAU].map(f64::to_bits);
    let full_turns = t
        .joint_ranges_rad()
        .iter()
        .all(|r| r.map(f64::to_bits) == full_turn);
    if t.plan() != paper.plan() || t.n_joints() != 2 || !full_turns {
        return Err(McError::NotThePaperTable);
    }
    let sampler = mc.sampler();
    let progress = &|_| {};
    Ok(match mc.tier() {
        Tier::Tangent => {
            let scale: [f64; CHI_LEN] = std::array::from_fn(|i| sampler.scale_rad()[i]);
            let coeffs = short_tan_coefficients(&scale);
            mc.drive_kernel(level, progress, &Specialised(ZeroLbShort { coeffs }))
        }
        Tier::Short => mc.drive_kernel(
            level,
            progress,
            &Specialised(TierInputs::<TIER_SHORT> { sampler }),
        ),
        Tier::Medium => mc.drive_kernel(
            level,
            progress,
            &Specialised(TierInputs::<TIER_MEDIUM> { sampler }),
        ),
        Tier::Any => mc.drive_kernel(
            level,
            progress,
            &Specialised(TierInputs::<TIER_ANY> { sampler }),
        ),
    })
}

/// Coefficients of the zero-lower-bound short tier per component: $(s/2, s^3/24)$.
fn short_tan_coefficients(scale_rad: &[f64; CHI_LEN]) -> [[f64; 2]; CHI_LEN] {
    scale_rad.map(|s| [0.5 * s, s * s * s / 24.0])
}

/// Block kernel of the zero-lower-bound short tier: `t[i]` is the half-integer of the word of
/// $\chi_i$.
#[inline(always)]
fn delta_from_t(s2: f64, c2: f64, t: [f64; CHI_LEN], k: &[[f64; 2]; CHI_LEN]) -> [f64; 3] {
    let tau = std::array::from_fn(|i| t[i] * (k[i][0] + (t[i] * t[i]) * k[i][1]));
    delta_from_tan_half_angles(s2, c2, &tau)
}

/// The chain with unnormalised quaternions: `tau[i]` $= \tan\tfrac{\chi_i}{2}$ in the order
/// of eq 25; `(s2, c2) = (sin phi2, cos phi2)`. Returns `[dpsi, dtheta, dgamma]` (eq 24),
/// rad.
#[inline(always)]
fn delta_from_tan_half_angles(s2: f64, c2: f64, tau: &[f64; CHI_LEN]) -> [f64; 3] {
    let [ta, tg, tc, tb, th, tf, te, td] = *tau;
    // E1 = Ry(a) Rz(b) Rx(c) Ry(d) Rx(e), each factor (1, tau e_axis)
    let (w, x, y, z) = (1.0, ta * tb, ta, tb);
    // * Rx(c)
    let (w, x, y, z) = (w - x * tc, w * tc + x, y + z * tc, z - y * tc);
    // * Ry(d)
    let (w, x, y, z) = (w - y * td, x - z * td, w * td + y, x * td + z);
    // * Rx(e)
    let (w, x, y, z) = (w - x * te, w * te + x, y + z * te, z - y * te);
    // conjugation Rz(-phi2) E1 Rz(phi2): vector part turned by -phi2 about z
    let (x, y) = (c2 * x + s2 * y, c2 * y - s2 * x);
    // * E2 = Ry(f) Rz(g) Rx(h)
    let (w, x, y, z) = (w - y * tf, x - z * tf, w * tf + y, x * tf + z);
    let (w, x, y, z) = (w - z * tg, x + y * tg, y - x * tg, w * tg + z);
    let (w, x, y, z) = (w - x * th, w * th + x, y + z * th, z - y * th);
    // read-out of the unit quaternion q~/|q~|
    let r = 2.0 / ((w * w + x * x) + (y * y + z * z));
    [
        r * (x * z + w * y),
        r * (x * y + w * z),
        r * (y * z + w * x),
    ]
}

/// A quaternion `(w, x, y, z)`.
type Quaternion = (f64, f64, f64, f64);

/// `q` times the rotation about x of half-angle sine and cosine `(s, c)`.
#[inline(always)]
fn times_rx((w, x, y, z): Quaternion, (s, c): (f64, f64)) -> Quaternion {
    (w * c - x * s, w * s + x * c, y * c + z * s, z * c - y * s)
}

/// `q` times the rotation about y of half-angle sine and cosine `(s, c)`.
#[inline(always)]
fn times_ry((w, x, y, z): Quaternion, (s, c): (f64, f64)) -> Quaternion {
    (w * c - y * s, x * c - z * s, w * s + y * c, x * s + z * c)
}

/// `q` times the rotation about z of half-angle sine and cosine `(s, c)`.
#[inline(always)]
fn times_rz((w, x, y, z): Quaternion, (s, c): (f64, f64)) -> Quaternion {
    (w * c - z * s, x * c + y * s, y * c - x * s, w * s + z * c)
}

/// The quaternion chain. `h[i] = (sin chi_i/2, cos chi_i/2)` in the order of eq 25;
/// `(s2, c2) = (sin phi2, cos phi2)`. Returns `[dpsi, dtheta, dgamma]` (eq 24), rad.
#[inline(always)]
fn delta_from_half_angles(s2: f64, c2: f64, h: &[(f64, f64); CHI_LEN]) -> [f64; 3] {
    let (sa, ca) = h[0]; // Ry(dphi_y1)
    let (sg, cg) = h[1]; // Rz(dphi_z2)
    let (sc, cc) = h[2]; // Rx(dalpha_x1)
    let (sb, cb) = h[3]; // Rz(dalpha_z1)
    let (sh, ch) = h[4]; // Rx(dalpha_x2)
    let (sf, cf) = h[5]; // Ry(dalpha_y2)
    let (se, ce) = h[6]; // Rx(deps_x)
    let (sd, cd) = h[7]; // Ry(deps_y)

    // E1 = Ry(a) Rz(b) Rx(c) Ry(d) Rx(e)
    let (w, x, y, z) = (ca * cb, sa * sb, sa * cb, ca * sb);
    // * Rx(c)
    let q = times_rx((w, x, y, z), (sc, cc));
    // * Ry(d)
    let q = times_ry(q, (sd, cd));
    // * Rx(e)
    let (w1, x, y, z1) = times_rx(q, (se, ce));
    // conjugation Rz(-phi2) E1 Rz(phi2): vector part turned by -phi2 about z
    let (x1, y1) = (c2 * x + s2 * y, c2 * y - s2 * x);

    // * E2 = Ry(f) Rz(g) Rx(h), one factor at a time
    let q = times_ry((w1, x1, y1, z1), (sf, cf));
    let q = times_rz(q, (sg, cg));
    let (w, x, y, z) = times_rx(q, (sh, ch));

    [
        2.0 * (x * z + w * y),
        2.0 * (x * y + w * z),
        2.0 * (y * z + w * x),
    ]
}

/// Block kernel: every `chi[i]` must lie inside the range of tier `TIER` (guaranteed by the
/// caller from the error box).
#[inline(always)]
fn delta_block_sample<const TIER: u8>(s2: f64, c2: f64, chi: [f64; CHI_LEN]) -> [f64; 3] {
    let h = match TIER {
        TIER_SHORT => chi.map(half_sin_cos_short),
        TIER_MEDIUM => chi.map(half_sin_cos_series),
        _ => chi.map(half_sin_cos),
    };
    delta_from_half_angles(s2, c2, &h)
}

/// Per-chunk buffers of the specialised kernels: the eight inputs per sample and
/// $(\sin\phi_2, \cos\phi_2)$.
struct Buffers {
    inputs: Box<[[f64; BLOCK_CAPACITY]; CHI_LEN]>,
    sc: Box<[[f64; BLOCK_CAPACITY]; 2]>,
}

fn buffers() -> Buffers {
    Buffers {
        inputs: Box::new([[0.0; BLOCK_CAPACITY]; CHI_LEN]),
        sc: Box::new([[0.0; BLOCK_CAPACITY]; 2]),
    }
}

/// $(\sin\phi_2, \cos\phi_2)$ of the `n` samples of `block` (word 9).
#[inline(always)]
fn phi2_sin_cos(
    table: &TurnTable,
    block: &SampleBlock,
    n: usize,
    sc: &mut [[f64; BLOCK_CAPACITY]; 2],
) {
    let [sin2, cos2] = sc;
    for ((s, c), w) in sin2[..n]
        .iter_mut()
        .zip(&mut cos2[..n])
        .zip(block.column_words(9))
    {
        (*s, *c) = sin_cos_turn_with(table, w);
    }
}

/// What a specialised kernel reads from a block: its eight inputs per sample, and one
/// sample's orientation error from them. Every method is `#[inline(always)]` (see
/// [`BlockKernel`]).
trait SampleInputs: Sync {
    /// The eight inputs of the `n` samples of `block`, one row per input.
    fn fill(&self, block: &SampleBlock, n: usize, inputs: &mut [[f64; BLOCK_CAPACITY]; CHI_LEN]);
    /// `[dpsi, dtheta, dgamma]` of one sample from $(\sin\phi_2, \cos\phi_2)$ and its inputs.
    fn delta(&self, s2: f64, c2: f64, inputs: [f64; CHI_LEN]) -> [f64; 3];
}

/// A specialised kernel: the inputs of `I`, $(\sin\phi_2, \cos\phi_2)$ of each sample, and
/// each sample's orientation error.
struct Specialised<I>(I);

impl<I: SampleInputs> BlockKernel for Specialised<I> {
    type Scratch = Buffers;

    fn scratch(&self) -> Buffers {
        buffers()
    }

    #[inline(always)]
    fn eval_block(
        &self,
        block: &SampleBlock,
        n: usize,
        b: &mut Buffers,
        out: &mut [[f64; BLOCK_CAPACITY]; 3],
    ) {
        self.0.fill(block, n, &mut b.inputs);
        phi2_sin_cos(turn_table(), block, n, &mut b.sc);
        let inputs = &b.inputs;
        for k in 0..n {
            let d = self.0.delta(
                b.sc[0][k],
                b.sc[1][k],
                std::array::from_fn(|i| inputs[i][k]),
            );
            out[0][k] = d[0];
            out[1][k] = d[1];
            out[2][k] = d[2];
        }
    }
}

/// All lower bounds zero, short-series tier: unnormalised quaternions from the words'
/// half-integers.
struct ZeroLbShort {
    coeffs: [[f64; 2]; CHI_LEN],
}

impl SampleInputs for ZeroLbShort {
    #[inline(always)]
    fn fill(&self, block: &SampleBlock, n: usize, inputs: &mut [[f64; BLOCK_CAPACITY]; CHI_LEN]) {
        for (i, t) in inputs.iter_mut().enumerate() {
            for (x, w) in t[..n].iter_mut().zip(block.column_words(i)) {
                *x = f64::from(w as i32) + 0.5;
            }
        }
    }

    #[inline(always)]
    fn delta(&self, s2: f64, c2: f64, t: [f64; CHI_LEN]) -> [f64; 3] {
        delta_from_t(s2, c2, t, &self.coeffs)
    }
}

/// Any box: decoded $\chi$, half-angle functions of tier `TIER`.
struct TierInputs<'a, const TIER: u8> {
    sampler: &'a TurntableSampler,
}

impl<const TIER: u8> SampleInputs for TierInputs<'_, TIER> {
    #[inline(always)]
    fn fill(&self, block: &SampleBlock, n: usize, inputs: &mut [[f64; BLOCK_CAPACITY]; CHI_LEN]) {
        for (i, chi) in inputs.iter_mut().enumerate() {
            self.sampler
                .decode_chi(i, block.column_words(i), &mut chi[..n]);
        }
    }

    #[inline(always)]
    fn delta(&self, s2: f64, c2: f64, chi: [f64; CHI_LEN]) -> [f64; 3] {
        delta_block_sample::<TIER>(s2, c2, chi)
    }
}

// The tiers of the kept kernel are those of the general one.
const _: () = assert!(SHORT_SERIES_MAX_ABS_RAD < SERIES_MAX_ABS_RAD);
