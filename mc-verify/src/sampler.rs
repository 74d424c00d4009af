//! Deterministic random turntables: the sampling distribution and its random streams.
//!
//! # Formula
//! The stream is consumed in blocks of $n \le$ [`BLOCK_CAPACITY`] samples; a block takes
//! $10n$ consecutive 32-bit words $w_0, w_1, \dots$ of a ChaCha8 stream, component-major:
//! word $w_{jn+k}$ is quantity $j$ of sample $k$ of the block, with quantities
//!
//! | $j$ | quantity | mapping of its word $w$ |
//! |---|---|---|
//! | $0 \dots 7$ | $\chi_0 \dots \chi_7$ (order of eq 25) | $t = \mathrm{i32}(w) + \tfrac12$, $\chi_j = t\,(\mathrm{UB}_j - \mathrm{LB}_j)\,2^{-31} + \operatorname{sign}(t)\,\mathrm{LB}_j$ |
//! | $8$ | $\phi_1$ | $\phi_1 = 2\pi\,w\,2^{-32}$ |
//! | $9$ | $\phi_2$ | $\phi_2 = 2\pi\,w\,2^{-32}$ |
//!
//! (component-major so that decoding is a contiguous, vectorisable loop per quantity).
//! [`TurntableSampler::sample`] is a block of one. A [`crate::MonteCarlo`] chunk is a
//! sequence of full blocks of [`BLOCK_CAPACITY`] and a shorter last block.
//!
//! $\mathrm{i32}(w)$ reinterprets the word as a two's-complement integer in
//! $[-2^{31}, 2^{31})$, so $t$ runs over the $2^{32}$ half-integers of $(-2^{31}, 2^{31})$,
//! symmetric about zero. Hence the sign $s_i = \operatorname{sign}(t)$ is a fair coin, and,
//! independently of it, $|\chi_i|$ is uniform on the midpoint grid of $2^{31}$ cells of
//! $[\mathrm{LB}_i, \mathrm{UB}_i]$ (never exactly an end point); its mean is exactly the
//! continuous one and its variance differs from $(\mathrm{UB}_i-\mathrm{LB}_i)^2/12$ by the
//! relative amount $2^{-62}$. $\phi_1, \phi_2$ are uniform on a grid of $2^{32}$ points of
//! $[0, 2\pi)$. This is the distribution the paper's words imply for Figure 9
//! ("values of the error components satisfying $\mathrm{LB}_i \le |\chi_i| \le \mathrm{UB}_i$
//! are generated randomly"), which does not state it (NOTES item 15); it is also the
//! distribution of the NumPy baseline (`numpy_mc_anchor.py`). $\phi_1$ is drawn although it
//! cancels from $\mathbf R_d^T \mathbf R_t$, so that any [`tt_kinematics::OrientationErrorModel`]
//! can be evaluated on the same samples and a reported worst sample carries a complete pose.
//!
//! Why 32-bit words: 40 bytes per sample instead of 80 halves the generator's share of the
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
use tt_kinematics::{CHI_LEN, Pose};

/// The project's Monte Carlo generator: ChaCha with 8 rounds (portable, seedable, 2^64 streams).
pub type McRng = ChaCha8Rng;

/// 32-bit words consumed per sample: eight for $\chi$, one each for $\phi_1$ and $\phi_2$.
pub const WORDS_PER_SAMPLE: usize = 10;

/// Samples per full block (the unit of drawing and of vectorised evaluation).
pub const BLOCK_CAPACITY: usize = 128;

/// Bytes consumed per sample.
pub const BYTES_PER_SAMPLE: usize = 4 * WORDS_PER_SAMPLE;

/// $2\pi / 2^{32}$: radians per step of the pose grid.
pub(crate) const RAD_PER_TURN_WORD: f64 = std::f64::consts::TAU / 4_294_967_296.0;

/// $2^{-31}$.
const TWO_POW_M31: f64 = 1.0 / 2_147_483_648.0;

/// The generator of chunk `chunk` of a run seeded with `seed`: key from `seed`
/// (`SeedableRng::seed_from_u64`), ChaCha stream id `chunk`.
///
/// ```
/// use mc_verify::{chunk_rng, TurntableSampler, ErrorBox};
/// let sampler = TurntableSampler::new(&ErrorBox::from_upper_rad([1e-4; 8])?);
/// let (a, b) = (sampler.sample(&mut chunk_rng(7, 3)), sampler.sample(&mut chunk_rng(7, 3)));
/// assert_eq!(a.1, b.1); // same (seed, chunk): same draws
/// # Ok::<(), mc_verify::McError>(())
/// ```
#[must_use]
pub fn chunk_rng(seed: u64, chunk: u64) -> McRng {
    let mut rng = McRng::seed_from_u64(seed);
    rng.set_stream(chunk);
    rng
}

/// Draws turntables (pose and error vector $\chi$) from an [`ErrorBox`] with the distribution
/// documented in the [module](self) (uniform magnitudes, fair random signs, uniform pose).
///
/// Reusable outside this crate (for an end-to-end Monte Carlo over turntables): with
/// [`chunk_rng`]`(seed, c)` and [`TurntableSampler::fill_block`] in blocks of
/// [`BLOCK_CAPACITY`], it gives the very draws of chunk `c` of a [`crate::MonteCarlo`] run
/// (sample `k` of the run is sample `k mod n_c` of chunk `k / n_c`, `n_c` the chunk size);
/// [`TurntableSampler::sample`] draws the same law one sample at a time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TurntableSampler {
    /// $(\mathrm{UB}_i - \mathrm{LB}_i)\,2^{-31}$, rad.
    scale_rad: [f64; CHI_LEN],
    /// $\mathrm{LB}_i$, rad.
    lb_rad: [f64; CHI_LEN],
}

impl TurntableSampler {
    /// A sampler for the box `bounds`.
    #[must_use]
    pub fn new(bounds: &ErrorBox) -> Self {
        let (lb, ub) = (bounds.lb_rad(), bounds.ub_rad());
        Self {
            scale_rad: std::array::from_fn(|i| (ub[i] - lb[i]) * TWO_POW_M31),
            lb_rad: lb,
        }
    }

    /// $(\mathrm{UB}_i - \mathrm{LB}_i)\,2^{-31}$, rad.
    pub(crate) fn scale_rad(&self) -> &[f64; CHI_LEN] {
        &self.scale_rad
    }

    /// $\chi_i$ (rad) from its word `w` (see the module table).
    #[inline(always)]
    #[must_use]
    pub fn chi_from_word(&self, i: usize, w: u32) -> f64 {
        let t = f64::from(w as i32) + 0.5;
        t * self.scale_rad[i] + self.lb_rad[i].copysign(t)
    }

    /// A pose angle (rad, in $[0, 2\pi)$) from its word.
    #[inline(always)]
    #[must_use]
    pub fn angle_from_word(w: u32) -> f64 {
        f64::from(w) * RAD_PER_TURN_WORD
    }

    /// Draw one turntable (a block of one): its pose and $\chi$ (rad, order of eq 25).
    /// Consumes exactly [`WORDS_PER_SAMPLE`] words of `rng`.
    pub fn sample<R: Rng + ?Sized>(&self, rng: &mut R) -> (Pose, [f64; CHI_LEN]) {
        let w: [u32; WORDS_PER_SAMPLE] = std::array::from_fn(|_| rng.next_u32());
        let chi = std::array::from_fn(|i| self.chi_from_word(i, w[i]));
        let pose = Pose {
            phi1_rad: Self::angle_from_word(w[8]),
            phi2_rad: Self::angle_from_word(w[9]),
        };
        (pose, chi)
    }

    /// Draw a block of `n` turntables into `block` (`n` is clamped to
    /// `1..=BLOCK_CAPACITY`); consumes exactly `n *` [`WORDS_PER_SAMPLE`] words of `rng`.
    /// [`crate::MonteCarlo`] draws its samples this way.
    #[inline(always)]
    pub fn fill_block<R: Rng + ?Sized>(&self, rng: &mut R, n: usize, block: &mut SampleBlock) {
        fill_words(rng, n, block);
        let SampleBlock { len, bytes, chi } = block;
        for (i, out) in chi.iter_mut().enumerate() {
            self.decode_chi(i, column_words(bytes, *len, i), out);
        }
    }

    /// $\chi_i$ (rad) of the words of component `i` into `out`, in order
    /// ([`TurntableSampler::chi_from_word`] of each; a loop the compiler vectorises).
    #[inline(always)]
    pub(crate) fn decode_chi(&self, i: usize, words: impl Iterator<Item = u32>, out: &mut [f64]) {
        for (x, w) in out.iter_mut().zip(words) {
            *x = self.chi_from_word(i, w);
        }
    }
}

/// Fill only the words of a block of `n` samples (clamped to `1..=BLOCK_CAPACITY`), without
/// decoding $\chi$; the decoded values are then available through [`SampleBlock::word`] and
/// [`TurntableSampler::chi_from_word`] only.
pub(crate) fn fill_words<R: Rng + ?Sized>(rng: &mut R, n: usize, block: &mut SampleBlock) {
    let n = n.clamp(1, BLOCK_CAPACITY);
    block.len = n;
    rng.fill_bytes(&mut block.bytes[..n * BYTES_PER_SAMPLE]);
}

/// The words of quantity `j` of a block of `len` samples whose stream bytes are `bytes`.
#[inline(always)]
fn column_words(bytes: &[u8], len: usize, j: usize) -> impl Iterator<Item = u32> + '_ {
    bytes[4 * j * len..4 * (j + 1) * len]
        .chunks_exact(4)
        .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
}

/// A block of drawn turntables (structure of arrays), filled by
/// [`TurntableSampler::fill_block`].
#[derive(Clone)]
pub struct SampleBlock {
    pub(crate) len: usize,
    pub(crate) bytes: [u8; BLOCK_CAPACITY * BYTES_PER_SAMPLE],
    pub(crate) chi: [[f64; BLOCK_CAPACITY]; CHI_LEN],
}

impl Default for SampleBlock {
    fn default() -> Self {
        Self {
            len: 0,
            bytes: [0; BLOCK_CAPACITY * BYTES_PER_SAMPLE],
            chi: [[0.0; BLOCK_CAPACITY]; CHI_LEN],
        }
    }
}

impl std::fmt::Debug for SampleBlock {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SampleBlock")
            .field("len", &self.len)
            .finish_non_exhaustive()
    }
}

impl SampleBlock {
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

    /// The words of quantity `j` (0-9, see the module table) of all samples of the block,
    /// in sample order (a contiguous column: loops over it vectorise).
    #[inline(always)]
    pub(crate) fn column_words(&self, j: usize) -> impl Iterator<Item = u32> + '_ {
        column_words(&self.bytes, self.len, j)
    }

    /// The raw word of quantity `j` (0-9, see the module table) of sample `k`.
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

    /// $\chi$ of sample `k` (rad, order of eq 25). Panics if `k >= len()`.
    #[must_use]
    pub fn chi_rad(&self, k: usize) -> [f64; CHI_LEN] {
        assert!(k < self.len, "sample {k} of a block of {}", self.len);
        std::array::from_fn(|i| self.chi[i][k])
    }

    /// The pose of sample `k`. Panics if `k >= len()`.
    #[must_use]
    pub fn pose(&self, k: usize) -> Pose {
        assert!(k < self.len, "sample {k} of a block of {}", self.len);
        Pose {
            phi1_rad: TurntableSampler::angle_from_word(self.word(8, k)),
            phi2_rad: TurntableSampler::angle_from_word(self.word(9, k)),
        }
    }
}
