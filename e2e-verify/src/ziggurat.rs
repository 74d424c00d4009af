//! Standard normal draws by a 32-bit ziggurat over a seeded ChaCha stream read a block of
//! words at a time ([`WordBlock`]): one 32-bit word and one multiply per draw on the fast
//! path (98.8% of draws), against two 64-bit words, a logarithm, a square root and a
//! sine-cosine for Box-Muller ([`crate::noise::standard_normal_pair`]). The time-domain
//! simulator ([`crate::timedomain`]) draws with it.
//!
//! # Method
//! Marsaglia and Tsang's ziggurat with $C = 256$ layers of equal area
//! $v = 4.928673233990\ldots\times10^{-3}$ under $f(x) = e^{-x^2/2}$, base layer edge
//! $r = 3.654152885361\ldots$: the edges $x_1 = r$, $x_{i+1} = \sqrt{-2\ln(v/x_i + f(x_i))}$,
//! $x_0 = v/f(r)$ (the base strip's rectangle-equivalent width), $x_{256} = 0$. One 32-bit
//! word $w$ gives the layer $i$ (its low 8 bits) and, from its high 24 bits read as a signed
//! integer $j \in [-2^{23}, 2^{23})$, the signed uniform $u = (j + \tfrac12)\,2^{-23}$ on a
//! grid symmetric about 0 in $(-1, 1)$ (the layer's and the value's bits are disjoint, as
//! Doornik asks); $x = u\,x_i$ is accepted at once when $|x| < x_{i+1}$, else for $i = 0$
//! the tail beyond $r$ by Marsaglia's exponential method, else when a uniform height in the
//! layer's wedge lies below $f(x)$ (the rare paths take further words, two per 53-bit
//! uniform). Every accepted value has the normal density up to the grid of $u$: a fast-path
//! value lies on a grid of step $x_i\,2^{-23} \le 4.7\times10^{-7}$, so the distribution
//! function is exact within about $10^{-7}$, far below what any simulation here resolves
//! (the tests check moments, a Kolmogorov-Smirnov and a chi-square statistic, and the tail).
//!
//! # Words
//! [`WordBlock`] reads its ChaCha stream [`BLOCK_WORDS`] words at a time (`fill_bytes` into
//! a buffer) and hands them out one by one, in the stream's order (the same words, in the
//! same order, as `next_u32` would give): one index check per word and one call into the
//! generator per block. A draw is a function of the stream alone, so chunks seeded by
//! mc-verify's [`chunk_rng`](mc_verify::chunk_rng) give the same draws on any thread.
//!
//! # Reference
//! G. Marsaglia and W. W. Tsang, "The Ziggurat Method for Generating Random Variables",
//! J. Stat. Software 5(8), 2000; J. A. Doornik, "An Improved Ziggurat Method to Generate
//! Normal Random Samples", 2005 (independent bits for the layer and the value).

use rand_core::Rng;
use std::sync::LazyLock;

/// Layers of the ziggurat.
const LAYERS: usize = 256;
/// The base layer's edge $r$ for 256 layers (Marsaglia and Tsang 2000).
const R: f64 = 3.654_152_885_361_009;
/// The area of every layer $v$ for 256 layers (Marsaglia and Tsang 2000).
const V: f64 = 4.928_673_233_990_e-3;
/// $2^{-23}$: the step of the signed 24-bit uniform.
const STEP_24: f64 = 1.0 / (1u64 << 23) as f64;
/// $2^{-32}$.
const STEP_32: f64 = 1.0 / (1u64 << 32) as f64;
/// $2^{-53}$.
const STEP_53: f64 = 1.0 / (1u64 << 53) as f64;

/// Words a [`WordBlock`] reads from its generator at once (1 KiB: four refills of ChaCha's
/// own 64-word buffer per call).
pub(crate) const BLOCK_WORDS: usize = 256;

/// A random stream read [`BLOCK_WORDS`] 32-bit words at a time (see the [module](self)).
#[derive(Debug, Clone)]
pub struct WordBlock<G> {
    rng: G,
    words: [u32; BLOCK_WORDS],
    next: usize,
}

impl<G: Rng> WordBlock<G> {
    /// The words of `rng`, from its current position.
    #[must_use]
    pub fn new(rng: G) -> Self {
        Self {
            rng,
            words: [0; BLOCK_WORDS],
            next: BLOCK_WORDS,
        }
    }

    #[cold]
    fn refill(&mut self) {
        let mut bytes = [0u8; 4 * BLOCK_WORDS];
        self.rng.fill_bytes(&mut bytes);
        for (w, b) in self.words.iter_mut().zip(bytes.chunks_exact(4)) {
            *w = u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
        }
        self.next = 0;
    }

    /// The next word of the stream.
    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        if self.next >= BLOCK_WORDS {
            self.refill();
        }
        let w = self.words[self.next];
        self.next += 1;
        w
    }

    /// A uniform in $(0, 1)$ from one word: $(w + \tfrac12)\,2^{-32}$, a grid symmetric about
    /// $\tfrac12$ (mean exactly $\tfrac12$).
    #[inline]
    pub fn unit_32(&mut self) -> f64 {
        (f64::from(self.next_u32()) + 0.5) * STEP_32
    }

    /// A uniform in $(0, 1]$ from the high 53 bits of two words (for heights and logarithms).
    #[inline]
    fn open_unit_53(&mut self) -> f64 {
        let hi = u64::from(self.next_u32());
        let lo = u64::from(self.next_u32());
        ((((hi << 32) | lo) >> 11) + 1) as f64 * STEP_53
    }
}

/// The ziggurat's tables: the layer edges $x_0..x_{256}$, $f(x_i)$ and $x_i\,2^{-23}$,
/// computed once ([`Ziggurat::get`]); [`Ziggurat::sample`] draws. Hold the reference in a
/// loop (one lookup of the tables instead of one per draw).
#[derive(Debug)]
pub struct Ziggurat {
    x: [f64; LAYERS + 1],
    f: [f64; LAYERS + 1],
    /// $x_i\,2^{-23}$: the step of layer $i$'s grid.
    step: [f64; LAYERS],
}

fn pdf(x: f64) -> f64 {
    (-0.5 * x * x).exp()
}

static TABLES: LazyLock<Ziggurat> = LazyLock::new(|| {
    let mut x = [0.0; LAYERS + 1];
    x[0] = V / pdf(R);
    x[1] = R;
    for i in 1..LAYERS - 1 {
        x[i + 1] = (-2.0 * (V / x[i] + pdf(x[i])).ln()).sqrt();
    }
    x[LAYERS] = 0.0;
    let mut f = [0.0; LAYERS + 1];
    for (fi, xi) in f.iter_mut().zip(&x) {
        *fi = pdf(*xi);
    }
    let mut step = [0.0; LAYERS];
    for (s, xi) in step.iter_mut().zip(&x) {
        *s = xi * STEP_24;
    }
    Ziggurat { x, f, step }
});

impl Ziggurat {
    /// The tables (computed on first use).
    #[must_use]
    pub fn get() -> &'static Self {
        &TABLES
    }

    /// One standard normal draw (see the [module](self)).
    #[inline]
    pub fn sample<G: Rng>(&self, words: &mut WordBlock<G>) -> f64 {
        loop {
            let w = words.next_u32();
            let i = (w & 0xff) as usize;
            // the high 24 bits as a signed integer (arithmetic shift of the word read as i32)
            let j = (w as i32) >> 8;
            let x = (f64::from(j) + 0.5) * self.step[i];
            if x.abs() < self.x[i + 1] {
                return x;
            }
            if let Some(x) = self.rare(words, i, x) {
                return x;
            }
        }
    }

    /// The base layer's tail or a wedge's test (1.2% of draws).
    #[cold]
    #[inline(never)]
    fn rare<G: Rng>(&self, words: &mut WordBlock<G>, i: usize, x: f64) -> Option<f64> {
        if i == 0 {
            return Some(tail(words, x < 0.0));
        }
        let height = self.f[i + 1] + (self.f[i] - self.f[i + 1]) * words.open_unit_53();
        (height < pdf(x)).then_some(x)
    }
}

/// The tail beyond $r$, negative when `negative` (Marsaglia 1964): $a = \ln U_1 / r$,
/// $b = \ln U_2$, accepted when $-2b \ge a^2$; the value $r - a$.
fn tail<G: Rng>(words: &mut WordBlock<G>, negative: bool) -> f64 {
    loop {
        let a = words.open_unit_53().ln() / R;
        let b = words.open_unit_53().ln();
        if -2.0 * b >= a * a {
            return if negative { a - R } else { R - a };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Draws per distribution test (seeded: the statistics are fixed numbers, never flaky).
    const DRAWS: usize = 4_000_000;
    /// Standard errors allowed for a moment or a frequency (one of a dozen checked at once).
    const SE: f64 = 5.0;
    /// The Kolmogorov distribution's 0.999 quantile: sqrt(n) D_n of n exact normal draws
    /// exceeds it with probability 0.001 (Smirnov's asymptotic law, n in the millions).
    const KS_999: f64 = 1.949;
    /// The standard normal's 0.999 quantile (for the chi-square's Wilson-Hilferty quantile).
    const Z_999: f64 = 3.090_232_306_167_813;

    fn draws(n: usize, stream: u64) -> Vec<f64> {
        let z = Ziggurat::get();
        let mut words = WordBlock::new(mc_verify::chunk_rng(21, stream));
        (0..n).map(|_| z.sample(&mut words)).collect()
    }

    /// The standard normal's distribution function on [-9, 9] by cumulative Simpson sums of
    /// the density (step 1e-3: error below 1e-12), linearly interpolated (error below
    /// h^2/8 max|f''| = 5e-8): independent of the ziggurat's tables.
    struct Cdf {
        lo: f64,
        h: f64,
        values: Vec<f64>,
    }

    impl Cdf {
        fn new() -> Self {
            let (lo, h) = (-9.0, 1e-3);
            let density = |x: f64| pdf(x) / std::f64::consts::TAU.sqrt();
            let mut values = vec![0.0];
            let mut acc = 0.0;
            for k in 0..18_000 {
                let a = lo + k as f64 * h;
                acc += h / 6.0 * (density(a) + 4.0 * density(a + 0.5 * h) + density(a + h));
                values.push(acc);
            }
            Self { lo, h, values }
        }

        fn at(&self, x: f64) -> f64 {
            let t = ((x - self.lo) / self.h).clamp(0.0, (self.values.len() - 2) as f64);
            let k = t.floor() as usize;
            let w = t - k as f64;
            self.values[k] * (1.0 - w) + self.values[k + 1] * w
        }
    }

    /// The last edge the recursion reaches lies near 0 (the tables close: 256 layers of area v
    /// cover the density), and the edges fall monotonically.
    #[test]
    fn ziggurat_tables_close_at_zero_and_fall() {
        let t = Ziggurat::get();
        // x_255 of Marsaglia and Tsang's table is 0.27...: the recursion reproduces the
        // published layer count (closing tolerance: the 13 digits of v)
        assert!(
            t.x[LAYERS - 1] > 0.2 && t.x[LAYERS - 1] < 0.35,
            "{}",
            t.x[255]
        );
        for w in t.x.windows(2) {
            assert!(w[1] < w[0], "{w:?}");
        }
        // the published base width v / f(r) = 3.9107579595...
        assert!((t.x[0] - 3.910_757_959_537_09).abs() < 1e-9, "{}", t.x[0]);
    }

    /// The block hands out the generator's own words in its order, across refills.
    #[test]
    fn word_block_reads_the_stream_in_order() {
        let mut plain = mc_verify::chunk_rng(5, 3);
        let mut block = WordBlock::new(mc_verify::chunk_rng(5, 3));
        for k in 0..3 * BLOCK_WORDS + 7 {
            assert_eq!(block.next_u32(), plain.next_u32(), "word {k}");
        }
    }

    /// Moments and tail fractions of 4e6 seeded draws agree with the standard normal's
    /// (mean 0, variance 1, third moment 0, fourth moment 3, P(|Z| > 1), P(|Z| > 2) and
    /// P(|Z| > r): the base layer's tail, reached with its frequency) within 5 standard
    /// errors of 4e6 draws.
    #[test]
    fn ziggurat_draws_have_the_normal_moments_and_tails() {
        let z = draws(DRAWS, 0);
        let n = DRAWS as f64;
        let m = |k: i32| z.iter().map(|v| v.powi(k)).sum::<f64>() / n;
        // standard errors: sqrt(Var(Z^k) / n) = sqrt(1, 2, 15, 96 / n)
        for (k, want, var) in [(1, 0.0, 1.0), (2, 1.0, 2.0), (3, 0.0, 15.0), (4, 3.0, 96.0)] {
            let got = m(k);
            assert!(
                (got - want).abs() < SE * (var / n).sqrt(),
                "moment {k}: {got} vs {want}"
            );
        }
        // erfc(e / sqrt 2), from Python's math.erfc
        for (e, p) in [
            (1.0, 0.317_310_507_862_914_15),
            (2.0, 0.045_500_263_896_358_44),
            (R, 0.000_258_032_487_653_901_3),
        ] {
            let f = z.iter().filter(|v| v.abs() > e).count() as f64 / n;
            assert!(
                (f - p).abs() < SE * (p * (1.0 - p) / n).sqrt(),
                "P(|Z| > {e}) = {f} vs {p}"
            );
        }
    }

    /// The Kolmogorov-Smirnov distance of 4e6 draws to the normal distribution function is
    /// below the 0.999 quantile of its law for that sample size, KS_999 / sqrt(n) (9.7e-4);
    /// and the chi-square over 100 bins of equal probability (40,000 expected each) is below
    /// its 0.999 quantile for 99 degrees of freedom (Wilson-Hilferty: 148.3).
    #[test]
    fn ziggurat_draws_pass_kolmogorov_smirnov_and_chi_square() {
        const BINS: usize = 100;
        let mut z = draws(DRAWS, 1);
        z.sort_by(f64::total_cmp);
        let cdf = Cdf::new();
        let n = DRAWS as f64;
        let mut d: f64 = 0.0;
        let mut counts = [0usize; BINS];
        for (k, v) in z.iter().enumerate() {
            let p = cdf.at(*v);
            d = d
                .max((p - k as f64 / n).abs())
                .max(((k + 1) as f64 / n - p).abs());
            counts[((p * BINS as f64) as usize).min(BINS - 1)] += 1;
        }
        assert!(d < KS_999 / n.sqrt(), "KS distance {d}");
        let expected = n / BINS as f64;
        let chi2: f64 = counts
            .iter()
            .map(|c| (*c as f64 - expected).powi(2) / expected)
            .sum();
        let df = (BINS - 1) as f64;
        let a = 2.0 / (9.0 * df);
        let limit = df * (1.0 - a + Z_999 * a.sqrt()).powi(3);
        assert!(
            chi2 < limit,
            "chi-square {chi2} over {df} dof (limit {limit})"
        );
    }

    /// The tail method alone: every draw lies beyond r, and the fractions beyond r + 0.25 and
    /// r + 0.75 are the normal's conditional ones Q(r + d) / Q(r) (from Python's math.erfc)
    /// within 5 standard errors of 4e5 draws.
    #[test]
    fn tail_draws_follow_the_normal_beyond_r() {
        const TAIL_DRAWS: usize = 400_000;
        let mut words = WordBlock::new(mc_verify::chunk_rng(21, 2));
        let t: Vec<f64> = (0..TAIL_DRAWS)
            .map(|k| tail(&mut words, k % 2 == 1).abs())
            .collect();
        assert!(t.iter().all(|v| *v > R));
        let n = TAIL_DRAWS as f64;
        for (d, p) in [(0.25, 0.366_449_964_259_147), (0.75, 0.041_156_845_481_911)] {
            let f = t.iter().filter(|v| **v > R + d).count() as f64 / n;
            assert!(
                (f - p).abs() < SE * (p * (1.0 - p) / n).sqrt(),
                "P(Z > r + {d} | Z > r) = {f} vs {p}"
            );
        }
    }
}
