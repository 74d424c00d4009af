//! Deterministic random turntables: the sampling distribution and its random streams.
//!
//! # Formula
//! A turntable with $n_\chi$ angular errors and $n_J$ joints takes
//! $W = n_\chi + n_J$ 32-bit words per sample ([`TurntableSampler::words_per_sample`]). The
//! stream is consumed in blocks of $n \le$ [`BLOCK_CAPACITY`] samples; a block takes $Wn$
//! consecutive words $w_0, w_1, \dots$ of a ChaCha8 stream, component-major: word $w_{jn+k}$
//! is quantity $j$ of sample $k$ of the block, with quantities
//!
//! | $j$ | quantity | mapping of its word $w$ |
//! |---|---|---|
//! | $0 \dots n_\chi - 1$ | $\chi_j$, in the order of $\chi$ ([`tt_kinematics::Turntable::rotation_error_names`]) | $t = \mathrm{i32}(w) + \tfrac12$, $\chi_j = t\,(\mathrm{UB}_j - \mathrm{LB}_j)\,2^{-31} + \operatorname{sign}(t)\,\mathrm{LB}_j$ |
//! | $n_\chi + m$ | angle of joint $m$ (pose order) with range $[0, 2\pi]$ (a full turn, the default) | $\phi_m = 2\pi\,w\,2^{-32}$ |
//! | $n_\chi + m$ | angle of joint $m$ with any other range $[\ell_m, h_m]$ | $\phi_m = \min(\ell_m + (h_m - \ell_m)\,(w\,2^{-32}),\ h_m)$ |
//!
//! (component-major so that decoding is a contiguous, vectorisable loop per quantity). For
//! the paper's table ($\chi$ of eq 25, joints $\phi_1, \phi_2$) this is 10 words per sample,
//! exactly the layout and mapping of the crate's earlier, paper-only sampler: the same seed
//! gives the same turntables, bit for bit. [`TurntableSampler::sample`] is a block of one. A
//! [`crate::MonteCarlo`] chunk is a sequence of full blocks of [`BLOCK_CAPACITY`] and a
//! shorter last block.
//!
//! $\mathrm{i32}(w)$ reinterprets the word as a two's-complement integer in
//! $[-2^{31}, 2^{31})$, so $t$ runs over the $2^{32}$ half-integers of $(-2^{31}, 2^{31})$,
//! symmetric about zero. Hence the sign $s_i = \operatorname{sign}(t)$ is a fair coin, and,
//! independently of it, $|\chi_i|$ is uniform on the midpoint grid of $2^{31}$ cells of
//! $[\mathrm{LB}_i, \mathrm{UB}_i]$ (never exactly an end point); its mean is exactly the
//! continuous one and its variance differs from $(\mathrm{UB}_i-\mathrm{LB}_i)^2/12$ by the
//! relative amount $2^{-62}$. Joint angles are uniform on a grid of $2^{32}$ points of their
//! range: $[0, 2\pi)$ for a full turn; $[\ell, h)$ otherwise (the minimum only guards
//! against the rounding of the last grid point onto or past $h$, so every angle lies in
//! $[\ell, h]$). This is the distribution the paper's words imply for Figure 9 ("values of
//! the error components satisfying $\mathrm{LB}_i \le |\chi_i| \le \mathrm{UB}_i$ are generated
//! randomly"), which does not state it (NOTES item 15); it is also the distribution of the
//! NumPy baseline (`numpy_mc_anchor.py`). Joints that cancel from
//! $\mathbf R_d^T \mathbf R_t$ (those before the first error, see
//! [`tt_kinematics::Turntable::free_joints`]) are drawn too, so that any
//! [`tt_kinematics::OrientationErrorModel`] can be evaluated on the same samples and a
//! reported worst sample carries a complete pose; the fast path never computes their sine
//! and cosine. Error translations are not drawn: they do not change the orientation.
//!
//! Why 32-bit words: 4 bytes per quantity instead of 8 halves the generator's share of the
//! run time; $2^{31}$ magnitude levels are far finer than any tolerance is known.
//!
//! # Streams
//! The generator is [`McRng`] = ChaCha8 (the 8-round ChaCha of the `rand_chacha` crate, which
//! passes the standard statistical batteries; 12 and 20 rounds only add cryptographic margin
//! and cost 1.4x and 2.4x the time on this project's machine, see the README). Chunk
//! $c$ of a run with seed $s$ uses [`chunk_rng`]`(s, c)`: the key expanded from $s$
//! (`seed_from_u64`) and the ChaCha stream id $c$ (`set_stream`), so $2^{64}$ independent
//! streams per seed. Sample $k$ of the run is sample $k \bmod n_c$ of chunk $\lfloor k / n_c
//! \rfloor$ for the fixed chunk size $n_c$, whatever the thread that computes it.
//!
//! # Reference
//! Paper §4.3 (Monte Carlo check of Table 4, Figure 9); NOTES.md item 15.

use crate::bounds::ErrorBox;
use rand_chacha::ChaCha8Rng;
use rand_core::{Rng, SeedableRng};
use std::f64::consts::TAU;
use tt_kinematics::{Pose, Turntable};

/// The project's Monte Carlo generator: ChaCha with 8 rounds (portable, seedable, 2^64 streams).
pub type McRng = ChaCha8Rng;

/// Samples per full block (the unit of drawing and of vectorised evaluation).
pub const BLOCK_CAPACITY: usize = 128;

/// $2\pi / 2^{32}$: radians per step of the full-turn grid.
pub(crate) const RAD_PER_TURN_WORD: f64 = TAU / 4_294_967_296.0;

/// $2^{-31}$.
const TWO_POW_M31: f64 = 1.0 / 2_147_483_648.0;

/// $2^{-32}$.
const TWO_POW_M32: f64 = 1.0 / 4_294_967_296.0;

/// The generator of chunk `chunk` of a run seeded with `seed`: key from `seed`
/// (`SeedableRng::seed_from_u64`), ChaCha stream id `chunk`.
///
/// ```
/// use mc_verify::{chunk_rng, ErrorBox, TurntableSampler};
/// let table = tt_kinematics::paper::table3();
/// let sampler = TurntableSampler::new(&ErrorBox::from_upper_rad(&table, vec![1e-4; 8])?, &table);
/// let (a, b) = (sampler.sample(&mut chunk_rng(7, 3)), sampler.sample(&mut chunk_rng(7, 3)));
/// assert_eq!(a, b); // same (seed, chunk): same draws
/// # Ok::<(), mc_verify::McError>(())
/// ```
#[must_use]
pub fn chunk_rng(seed: u64, chunk: u64) -> McRng {
    let mut rng = McRng::seed_from_u64(seed);
    rng.set_stream(chunk);
    rng
}

/// How a joint's word becomes its angle (see the [module](self) table).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum JointLaw {
    /// Range exactly $[0, 2\pi]$: $\phi = 2\pi\,w\,2^{-32}$ (an integer multiple of
    /// $2\pi/2^{32}$, whose sine and cosine the fast path takes from a table).
    FullTurn,
    /// Any other range $[\ell, h]$: $\phi = \min(\ell + (h - \ell)(w\,2^{-32}), h)$.
    Range {
        /// $\ell$, rad.
        lo_rad: f64,
        /// $h - \ell$, rad.
        span_rad: f64,
        /// $h$, rad.
        hi_rad: f64,
    },
}

impl JointLaw {
    fn new([lo, hi]: [f64; 2]) -> Self {
        if lo.to_bits() == 0.0_f64.to_bits() && hi.to_bits() == TAU.to_bits() {
            JointLaw::FullTurn
        } else {
            JointLaw::Range {
                lo_rad: lo,
                span_rad: hi - lo,
                hi_rad: hi,
            }
        }
    }

    /// The angle (rad) of word `w`.
    #[inline(always)]
    pub(crate) fn angle(self, w: u32) -> f64 {
        match self {
            JointLaw::FullTurn => f64::from(w) * RAD_PER_TURN_WORD,
            JointLaw::Range {
                lo_rad,
                span_rad,
                hi_rad,
            } => {
                let a = lo_rad + span_rad * (f64::from(w) * TWO_POW_M32);
                // compare-select (the values are finite): never past the range's end
                if a < hi_rad { a } else { hi_rad }
            }
        }
    }

    /// The angles of `words` into `out`, in order (one loop per law: it vectorises).
    #[inline(always)]
    pub(crate) fn decode(self, words: impl Iterator<Item = u32>, out: &mut [f64]) {
        match self {
            JointLaw::FullTurn => {
                for (a, w) in out.iter_mut().zip(words) {
                    *a = JointLaw::FullTurn.angle(w);
                }
            }
            law @ JointLaw::Range { .. } => {
                for (a, w) in out.iter_mut().zip(words) {
                    *a = law.angle(w);
                }
            }
        }
    }
}

/// Draws turntables (pose and error vector $\chi$) from an [`ErrorBox`] with the distribution
/// documented in the [module](self) (uniform magnitudes, fair random signs, uniform pose in
/// the joint ranges).
///
/// Reusable outside this crate (for an end-to-end Monte Carlo over turntables): with
/// [`chunk_rng`]`(seed, c)` and [`TurntableSampler::fill_block`] in blocks of
/// [`BLOCK_CAPACITY`], it gives the very draws of chunk `c` of a [`crate::MonteCarlo`] run
/// (sample `k` of the run is sample `k mod n_c` of chunk `k / n_c`, `n_c` the chunk size);
/// [`TurntableSampler::sample`] draws the same law one sample at a time.
#[derive(Debug, Clone, PartialEq)]
pub struct TurntableSampler {
    /// $(\mathrm{UB}_i - \mathrm{LB}_i)\,2^{-31}$, rad.
    scale_rad: Vec<f64>,
    /// $\mathrm{LB}_i$, rad.
    lb_rad: Vec<f64>,
    /// Word-to-angle law of every joint, pose order.
    joints: Vec<JointLaw>,
}

impl TurntableSampler {
    /// A sampler for the box `bounds` of `turntable`'s angular errors and its joint ranges
    /// ([`Turntable::joint_ranges_rad`]). It draws one word per bound of `bounds` (which
    /// [`ErrorBox::new`] makes one per angular error of the turntable; [`crate::MonteCarlo::new`]
    /// checks that the box belongs to the turntable) and one per joint.
    #[must_use]
    pub fn new(bounds: &ErrorBox, turntable: &Turntable) -> Self {
        Self::for_joint_ranges(bounds, &turntable.joint_ranges_rad())
    }

    /// The sampler of a box over any joint ranges (rad, one `[lo, hi]` per joint): what
    /// [`crate::MonteCarlo::for_model`] draws.
    #[must_use]
    pub fn for_joint_ranges(bounds: &ErrorBox, joint_ranges_rad: &[[f64; 2]]) -> Self {
        let (lb, ub) = (bounds.lb_rad(), bounds.ub_rad());
        Self {
            scale_rad: lb
                .iter()
                .zip(ub)
                .map(|(l, u)| (u - l) * TWO_POW_M31)
                .collect(),
            lb_rad: lb.to_vec(),
            joints: joint_ranges_rad
                .iter()
                .copied()
                .map(JointLaw::new)
                .collect(),
        }
    }

    /// 32-bit words consumed per sample: one per angular error, then one per joint.
    #[must_use]
    pub fn words_per_sample(&self) -> usize {
        self.scale_rad.len() + self.joints.len()
    }

    /// Number of angular errors drawn per sample (length of $\chi$).
    #[must_use]
    pub fn n_rotation_errors(&self) -> usize {
        self.scale_rad.len()
    }

    /// Number of joint angles drawn per sample.
    #[must_use]
    pub fn n_joints(&self) -> usize {
        self.joints.len()
    }

    /// $(\mathrm{UB}_i - \mathrm{LB}_i)\,2^{-31}$, rad.
    pub(crate) fn scale_rad(&self) -> &[f64] {
        &self.scale_rad
    }

    /// The joints' word-to-angle laws.
    pub(crate) fn joint_laws(&self) -> &[JointLaw] {
        &self.joints
    }

    /// $\chi_i$ (rad) from its word `w` (see the module table). Panics if `i` is not an
    /// error index.
    #[inline(always)]
    #[must_use]
    pub fn chi_from_word(&self, i: usize, w: u32) -> f64 {
        let t = f64::from(w as i32) + 0.5;
        t * self.scale_rad[i] + self.lb_rad[i].copysign(t)
    }

    /// The angle (rad, inside the joint's range) of joint `joint` from its word `w` (see the
    /// module table). Panics if `joint` is not a joint index.
    #[inline(always)]
    #[must_use]
    pub fn angle_from_word(&self, joint: usize, w: u32) -> f64 {
        self.joints[joint].angle(w)
    }

    /// Draw one turntable (a block of one): its pose and $\chi$ (rad, order of $\chi$).
    /// Consumes exactly [`TurntableSampler::words_per_sample`] words of `rng`.
    pub fn sample<R: Rng + ?Sized>(&self, rng: &mut R) -> (Pose, Vec<f64>) {
        let words: Vec<u32> = (0..self.words_per_sample())
            .map(|_| rng.next_u32())
            .collect();
        let n = self.n_rotation_errors();
        let chi = (0..n).map(|i| self.chi_from_word(i, words[i])).collect();
        let angles = (0..self.n_joints())
            .map(|j| self.angle_from_word(j, words[n + j]))
            .collect();
        (finite_pose(angles), chi)
    }

    /// Draw a block of `n` turntables into `block` (`n` is clamped to
    /// `1..=BLOCK_CAPACITY`); consumes exactly `n *` [`TurntableSampler::words_per_sample`]
    /// words of `rng`. [`crate::MonteCarlo`] draws its samples this way. A block made for
    /// another sampler is resized first (once).
    #[inline(always)]
    pub fn fill_block<R: Rng + ?Sized>(&self, rng: &mut R, n: usize, block: &mut SampleBlock) {
        fill_words(self, rng, n, block);
        let SampleBlock {
            len, bytes, chi, ..
        } = block;
        for (i, out) in chi.iter_mut().enumerate() {
            self.decode_chi(i, column_words(bytes, *len, i), out);
        }
    }

    /// $\chi_i$ (rad) of the words of component `i` into `out`, in order
    /// ([`TurntableSampler::chi_from_word`] of each; a loop the compiler vectorises).
    #[inline(always)]
    pub(crate) fn decode_chi(&self, i: usize, words: impl Iterator<Item = u32>, out: &mut [f64]) {
        let (scale, lb) = (self.scale_rad[i], self.lb_rad[i]);
        for (x, w) in out.iter_mut().zip(words) {
            let t = f64::from(w as i32) + 0.5;
            *x = t * scale + lb.copysign(t);
        }
    }
}

/// A pose from angles that are finite by construction (decoded words).
pub(crate) fn finite_pose(angles_rad: Vec<f64>) -> Pose {
    Pose::new(angles_rad).unwrap_or_else(|_| unreachable!("decoded angles are finite"))
}

/// Fill only the words of a block of `n` samples (clamped to `1..=BLOCK_CAPACITY`), without
/// decoding $\chi$ (resizing the block first if it was made for another sampler).
#[inline(always)]
pub(crate) fn fill_words<R: Rng + ?Sized>(
    sampler: &TurntableSampler,
    rng: &mut R,
    n: usize,
    block: &mut SampleBlock,
) {
    if !block.fits(sampler) {
        *block = SampleBlock::new(sampler);
    }
    let n = n.clamp(1, BLOCK_CAPACITY);
    block.len = n;
    rng.fill_bytes(&mut block.bytes[..n * 4 * block.words_per_sample]);
}

/// The words of quantity `j` of a block of `len` samples whose stream bytes are `bytes`.
#[inline(always)]
fn column_words(bytes: &[u8], len: usize, j: usize) -> impl Iterator<Item = u32> + '_ {
    bytes[4 * j * len..4 * (j + 1) * len]
        .chunks_exact(4)
        .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
}

/// A block of drawn turntables (structure of arrays), sized for one sampler
/// ([`SampleBlock::new`]) and filled by [`TurntableSampler::fill_block`]; it allocates once,
/// never per sample.
#[derive(Clone)]
pub struct SampleBlock {
    pub(crate) len: usize,
    words_per_sample: usize,
    /// The stream bytes of the block: `len * words_per_sample` little-endian words.
    bytes: Vec<u8>,
    /// Decoded $\chi$, one column per angular error.
    chi: Vec<[f64; BLOCK_CAPACITY]>,
    /// The sampler's joint laws (to decode poses).
    joints: Vec<JointLaw>,
}

impl std::fmt::Debug for SampleBlock {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SampleBlock")
            .field("len", &self.len)
            .field("words_per_sample", &self.words_per_sample)
            .finish_non_exhaustive()
    }
}

impl SampleBlock {
    /// An empty block with room for [`BLOCK_CAPACITY`] samples of `sampler`.
    #[must_use]
    pub fn new(sampler: &TurntableSampler) -> Self {
        let words_per_sample = sampler.words_per_sample();
        Self {
            len: 0,
            words_per_sample,
            bytes: vec![0; BLOCK_CAPACITY * 4 * words_per_sample],
            chi: vec![[0.0; BLOCK_CAPACITY]; sampler.n_rotation_errors()],
            joints: sampler.joints.clone(),
        }
    }

    fn fits(&self, sampler: &TurntableSampler) -> bool {
        self.chi.len() == sampler.n_rotation_errors() && self.joints == sampler.joints
    }

    /// Number of samples in the block.
    #[must_use]
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the block holds no sample (only before the first fill).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The words of quantity `j` (see the module table) of all samples of the block, in
    /// sample order (a contiguous column: loops over it vectorise).
    #[inline(always)]
    pub(crate) fn column_words(&self, j: usize) -> impl Iterator<Item = u32> + '_ {
        column_words(&self.bytes, self.len, j)
    }

    /// The raw word of quantity `j` (see the module table) of sample `k`.
    #[inline(always)]
    pub(crate) fn word(&self, j: usize, k: usize) -> u32 {
        let o = 4 * (j * self.len + k);
        u32::from_le_bytes([
            self.bytes[o],
            self.bytes[o + 1],
            self.bytes[o + 2],
            self.bytes[o + 3],
        ])
    }

    /// $\chi$ of sample `k` (rad, order of $\chi$) into `out`. Panics if `k >= len()` or if
    /// `out` does not have one slot per angular error.
    pub fn chi_rad_into(&self, k: usize, out: &mut [f64]) {
        assert!(k < self.len, "sample {k} of a block of {}", self.len);
        assert_eq!(out.len(), self.chi.len(), "one slot per angular error");
        for (o, col) in out.iter_mut().zip(&self.chi) {
            *o = col[k];
        }
    }

    /// $\chi$ of sample `k` (rad, order of $\chi$). Panics if `k >= len()`.
    #[must_use]
    pub fn chi_rad(&self, k: usize) -> Vec<f64> {
        let mut chi = vec![0.0; self.chi.len()];
        self.chi_rad_into(k, &mut chi);
        chi
    }

    /// The pose of sample `k` (every joint, pose order). Panics if `k >= len()`.
    #[must_use]
    pub fn pose(&self, k: usize) -> Pose {
        assert!(k < self.len, "sample {k} of a block of {}", self.len);
        let n = self.chi.len();
        finite_pose(
            self.joints
                .iter()
                .enumerate()
                .map(|(j, law)| law.angle(self.word(n + j, k)))
                .collect(),
        )
    }
}
