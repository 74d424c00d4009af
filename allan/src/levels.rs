//! The cluster sizes of a curve and, per cluster size, the streaming sums of the four
//! deviations: overlapping Allan (second differences of the phase), overlapping Hadamard
//! (third differences), modified Allan (third differences of the phase's running sum) and
//! total (the Allan second differences plus those of the series reflected at both ends).
//!
//! Phase $x_t$ ($t = 0 \dots N$, $x_0 = 0$) is the running sum of the referenced samples, in
//! sample units. A level has a cluster size $m$ and a stride $s$ (a divisor of $m$; $r = m/s$
//! evaluations per cluster time). At stride 1 the sums run over contiguous slices of the
//! shared phase history; at a larger stride a level keeps the last $3r + 1$ phases at the
//! multiples of $s$, the last $2r + 1$ sums $B_k = \sum_{l = ks}^{ks + s - 1} x_l$ (for the
//! modified deviation) and the first $2r + 1$ phases (for the total deviation's reflection):
//! memory depends on $r$, never on $N$.

use std::collections::VecDeque;

/// Which cluster sizes a curve has.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum Taus {
    /// $m = 1, 2, 4, 8, \dots$ (the default).
    #[default]
    Octave,
    /// $m = 1, 10, 100, \dots$ (powers of ten, as allantools' `decade`).
    Decade,
    /// Every cluster size of 1 to [`ALL_DENSE`] samples, then [`ALL_PER_OCTAVE`] per octave
    /// ($m = j\,2^k$, $j$ = [`ALL_PER_OCTAVE`] to $2\,$[`ALL_PER_OCTAVE`]$ - 1$), each
    /// evaluated every $2^k$ samples (32 to 63 evaluations per cluster time, whatever the
    /// overlap factor): the densest grid the streaming estimator keeps at a cost per sample
    /// independent of the log's length.
    All,
    /// These cluster times, s (each a whole number of samples).
    List(Vec<f64>),
}

/// Cluster sizes of `all` evaluated at every sample.
pub const ALL_DENSE: u64 = 64;

/// Cluster sizes per octave of `all` beyond [`ALL_DENSE`].
pub const ALL_PER_OCTAVE: u64 = 32;

/// Largest number of evaluations per cluster time $r$ of a listed cluster time (its memory
/// is $5r$ doubles).
pub const MAX_LIST_EVALUATIONS: u64 = 1 << 16;

/// Largest cluster size, samples ($2^{61}$: any `u64` sample count).
const MAX_CLUSTER: u64 = 1 << 61;

/// The $(m, s)$ pairs of a grid for overlap factor `overlap`, by increasing $m$ (no
/// duplicates). A listed size without a divisor $r \in [R, $ [`MAX_LIST_EVALUATIONS`]$]$ (and
/// larger than [`MAX_LIST_EVALUATIONS`]) is returned in `Err` with its index.
pub(crate) fn grid(taus: &Taus, overlap: u64, sizes: &[u64]) -> Result<Vec<(u64, u64)>, usize> {
    let by_overlap = |m: u64| -> Option<u64> {
        if m <= overlap {
            return Some(1);
        }
        (overlap..=m.min(MAX_LIST_EVALUATIONS))
            .find(|r| m % r == 0)
            .map(|r| m / r)
    };
    let mut out: Vec<(u64, u64)> = match taus {
        Taus::Octave => (0..62)
            .map(|k| 1u64 << k)
            .map(|m| (m, by_overlap(m).unwrap_or(1)))
            .collect(),
        Taus::Decade => (0..19)
            .map(|k| 10u64.pow(k))
            .map(|m| (m, by_overlap(m).unwrap_or(1)))
            .collect(),
        Taus::All => {
            let mut v: Vec<(u64, u64)> = (1..=ALL_DENSE).map(|m| (m, 1)).collect();
            let mut s = ALL_DENSE / ALL_PER_OCTAVE;
            while ALL_PER_OCTAVE * s * 2 <= MAX_CLUSTER {
                for j in ALL_PER_OCTAVE..2 * ALL_PER_OCTAVE {
                    let m = j * s;
                    if m > ALL_DENSE {
                        v.push((m, s));
                    }
                }
                s *= 2;
            }
            v
        }
        Taus::List(_) => {
            let mut v = Vec::with_capacity(sizes.len());
            for (i, &m) in sizes.iter().enumerate() {
                v.push((m, by_overlap(m).ok_or(i)?));
            }
            v
        }
    };
    out.sort_unstable();
    out.dedup_by_key(|p| p.0);
    Ok(out)
}

/// Squared-difference sums of one level.
#[derive(Debug, Clone, Default)]
pub(crate) struct Sums {
    /// Allan: sum of squared second differences and their count.
    pub(crate) adev: (f64, u64),
    /// Hadamard: third differences.
    pub(crate) hdev: (f64, u64),
    /// Modified Allan: squared sums of $m$ consecutive second differences.
    pub(crate) mdev: (f64, u64),
}

/// One cluster size.
#[derive(Debug, Clone)]
pub(crate) struct Level {
    pub(crate) m: u64,
    pub(crate) stride: u64,
    pub(crate) sums: Sums,
    /// Strided levels only: the last `3r + 1` phases at multiples of the stride.
    xs: VecDeque<f64>,
    /// The first `2r + 1` phases at multiples of the stride (the total deviation's head).
    head: Vec<f64>,
    /// Index (in strides) of the next phase to take.
    next: u64,
    /// The last `2r + 1` sums $B_k$, and the partial sum of the current one.
    bs: VecDeque<f64>,
    carry: f64,
    /// The last `r` second differences of $B$ and their running sum (recomputed every `r`).
    ds: VecDeque<f64>,
    dsum: f64,
    since_exact: u64,
}

impl Level {
    pub(crate) fn new(m: u64, stride: u64) -> Self {
        Self {
            m,
            stride,
            sums: Sums::default(),
            xs: VecDeque::new(),
            head: Vec::new(),
            next: 0,
            bs: VecDeque::new(),
            carry: 0.0,
            ds: VecDeque::new(),
            dsum: 0.0,
            since_exact: 0,
        }
    }

    fn r(&self) -> usize {
        (self.m / self.stride) as usize
    }

    /// Strided levels: take the phases `x_t`, `t = t0 ..= t0 + b` (`phases[i]` is
    /// `x_{t0 + i}`), with `pre[i]` the running sum of `phases[..i]` (for the sums $B$).
    pub(crate) fn take_strided(&mut self, t0: u64, phases: &[f64], pre: &[f64]) {
        let s = self.stride;
        let r = self.r();
        let last = t0 + phases.len() as u64 - 1;
        // B windows [t - s, t) ending at multiples t of s in (t0, last]; x_{last} is left to
        // the next block (its window ends later), except through `carry` below
        let mut window_start = t0; // within this block, the first phase not yet in a B
        let mut t = (t0 / s + 1) * s;
        while t <= last {
            let part = pre[(t - t0) as usize] - pre[(window_start - t0) as usize];
            let b = self.carry + part;
            self.carry = 0.0;
            window_start = t;
            self.push_b(b, r);
            t += s;
        }
        if last > window_start {
            self.carry += pre[(last - t0) as usize] - pre[(window_start - t0) as usize];
        }
        // phases at multiples of s
        let mut t = self.next * s;
        while t <= last {
            if t >= t0 {
                self.push_x(phases[(t - t0) as usize], r);
            }
            self.next += 1;
            t = self.next * s;
        }
    }

    fn push_b(&mut self, b: f64, r: usize) {
        self.bs.push_back(b);
        if self.bs.len() > 2 * r + 1 {
            self.bs.pop_front();
        }
        if self.bs.len() == 2 * r + 1 {
            let d = self.bs[2 * r] - 2.0 * self.bs[r] + self.bs[0];
            self.ds.push_back(d);
            self.dsum += d;
            if self.ds.len() > r {
                let old = self.ds.pop_front().unwrap_or(0.0);
                self.dsum -= old;
            }
            self.since_exact += 1;
            if self.since_exact >= r as u64 {
                self.dsum = self.ds.iter().sum();
                self.since_exact = 0;
            }
            if self.ds.len() == r {
                self.sums.mdev.0 += self.dsum * self.dsum;
                self.sums.mdev.1 += 1;
            }
        }
    }

    fn push_x(&mut self, x: f64, r: usize) {
        self.xs.push_back(x);
        if self.xs.len() > 3 * r + 1 {
            self.xs.pop_front();
        }
        let n = self.xs.len();
        if self.head.len() < 2 * r + 1 {
            self.head.push(x);
        }
        if n > 2 * r {
            let d = self.xs[n - 1] - 2.0 * self.xs[n - 1 - r] + self.xs[n - 1 - 2 * r];
            self.sums.adev.0 += d * d;
            self.sums.adev.1 += 1;
        }
        if n > 3 * r {
            let d = self.xs[n - 1] - 3.0 * self.xs[n - 1 - r] + 3.0 * self.xs[n - 1 - 2 * r]
                - self.xs[n - 1 - 3 * r];
            self.sums.hdev.0 += d * d;
            self.sums.hdev.1 += 1;
        }
    }

    /// Strided levels: the total deviation's sum of squared second differences over every
    /// center and its count (the series is the phases at multiples of the stride up to the
    /// last one, reflected at both ends).
    pub(crate) fn total_strided(&self) -> (f64, u64) {
        let tail: Vec<f64> = self.xs.iter().copied().collect();
        let n = self.next - 1; // index of the last phase taken, in strides
        total_sum(&self.head, &tail, n, self.r() as u64, self.sums.adev.0)
    }
}

/// The total variance's sum of squared second differences at lag `r` of the series
/// $X_0 \dots X_n$ reflected at both ends ($X^*_{-j} = 2X_0 - X_j$, $X^*_{n+j} = 2X_n -
/// X_{n-j}$), over the centers $c = 1 \dots n - 1$, and their count $n - 1$. `head` holds
/// $X_0 \dots$ (at least $2r$), `tail` ends with $X_n$ (at least $2r + 1$), `interior` is
/// the sum over the centers $r \dots n - r$ (the Allan sum).
pub(crate) fn total_sum(head: &[f64], tail: &[f64], n: u64, r: u64, interior: f64) -> (f64, u64) {
    let (n, r) = (n as usize, r as usize);
    debug_assert!(n >= 2 * r && head.len() >= 2 * r && tail.len() > 2 * r);
    // X_i for i in n - 2r ..= n
    let at_tail = |i: usize| tail[tail.len() - 1 - (n - i)];
    let mut sum = interior;
    for c in 1..r {
        let left = 2.0 * head[0] - head[r - c];
        let d = left - 2.0 * head[c] + head[c + r];
        sum += d * d;
    }
    for c in n + 1 - r..n {
        let right = 2.0 * at_tail(n) - at_tail(2 * n - c - r);
        let d = at_tail(c - r) - 2.0 * at_tail(c) + right;
        sum += d * d;
    }
    (sum, n as u64 - 1)
}
