//! Runtime choice of the instruction set of the hot loop: the only `unsafe` of the workspace.
//!
//! The Monte Carlo kernel is a branch-free loop over a block of samples, which the compiler
//! vectorises; so are the end-to-end Monte Carlo's per-turntable chain and calibration
//! (e2e-verify, through [`HotLoop`] and [`run_at`]). A portable build targets x86-64 v1 (SSE2, two `f64` lanes); the ChaCha
//! generator already picks AVX2 at run time (`ppv-lite86`), so without the same for the
//! kernel the evaluation, not the generator, would bound a run. [`SimdLevel::detected`] picks
//! the widest level the CPU has, and the loop is compiled once per level (the same Rust
//! code, monomorphised and inlined inside a `#[target_feature]` function; hence the
//! `#[inline(always)]` on every function of the loop, and kernels as trait implementations
//! rather than closures, which would be compiled once for the portable level).
//!
//! Measured on this project's machine (one thread, the paper's Table 4 and a three-axis
//! table, `cargo run --release -p mc-verify --example throughput`): AVX2 runs the whole Monte
//! Carlo loop 1.3x faster than the portable level. AVX-512 (eight lanes) was tried and gained about 1 %, within noise,
//! for a newer minimum Rust (1.89) and the clock penalty of wide vectors on some CPUs, so
//! it is not offered.
//!
//! # Results do not depend on the level
//! Only vector width changes. Rust never contracts `a * b + c` into a fused multiply-add
//! (it would need an explicit `mul_add`), never reassociates floating-point sums, and every
//! reduction of the crate has a fixed lane order written in the source; the levels enable
//! no FMA feature at all. Each IEEE 754 operation is correctly rounded on every level, so a
//! run is bit-identical on all of them (tested: `simd_levels_give_bit_identical_results`).
//!
//! # Safety argument
//! Calling a `#[target_feature(enable = "...")]` function is `unsafe` because executing its
//! instructions on a CPU without the feature is undefined behaviour. `run_at` calls such a
//! function only after `is_x86_feature_detected!` has confirmed every feature it enables;
//! [`SimdLevel::is_available`] is the single place that check is made.

use crate::error::McError;

/// Instruction-set level of the hot loop (x86-64; other architectures have
/// [`SimdLevel::Portable`] only).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SimdLevel {
    /// The target's baseline (SSE2 on x86-64): always available.
    Portable,
    /// AVX2 (256-bit vectors, four `f64` lanes).
    Avx2,
}

impl SimdLevel {
    /// Every level, narrowest first.
    pub const ALL: [SimdLevel; 2] = [SimdLevel::Portable, SimdLevel::Avx2];

    /// Short name (`portable`, `avx2`).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            SimdLevel::Portable => "portable",
            SimdLevel::Avx2 => "avx2",
        }
    }

    /// Whether this CPU can run the level.
    #[must_use]
    pub fn is_available(self) -> bool {
        match self {
            SimdLevel::Portable => true,
            #[cfg(target_arch = "x86_64")]
            SimdLevel::Avx2 => std::arch::is_x86_feature_detected!("avx2"),
            #[cfg(not(target_arch = "x86_64"))]
            _ => false,
        }
    }

    /// The widest level this CPU has (what [`crate::MonteCarlo::run`] uses).
    #[must_use]
    pub fn detected() -> Self {
        static LEVEL: std::sync::OnceLock<SimdLevel> = std::sync::OnceLock::new();
        *LEVEL.get_or_init(|| {
            Self::ALL
                .into_iter()
                .rev()
                .find(|l| l.is_available())
                .unwrap_or(SimdLevel::Portable)
        })
    }

    /// The levels this CPU has, narrowest first.
    #[must_use]
    pub fn available() -> Vec<Self> {
        Self::ALL.into_iter().filter(|l| l.is_available()).collect()
    }

    /// `Ok(self)` if available, else the typed error naming it.
    ///
    /// # Errors
    /// [`McError::SimdUnavailable`] if the CPU lacks the level.
    pub fn check(self) -> Result<Self, McError> {
        if self.is_available() {
            Ok(self)
        } else {
            Err(McError::SimdUnavailable { level: self.name() })
        }
    }
}

/// A piece of hot code to compile once per level; its `run` must be `#[inline(always)]`
/// (with everything it calls in the loop) so that it is compiled inside the level's
/// `#[target_feature]` function. Public so that a caller's own hot loop (e2e-verify's
/// per-turntable chain and calibration) takes the same dispatch, with no `unsafe` of its own.
pub trait HotLoop {
    /// What the loop returns.
    type Output;
    /// Run it.
    fn run(self) -> Self::Output;
}

/// Run `hot` compiled for `level`. `level` must be available: callers obtain it from
/// [`SimdLevel::detected`] or [`SimdLevel::check`]; an unavailable level falls back to
/// [`SimdLevel::Portable`] (never executes an instruction the CPU lacks).
#[inline]
pub fn run_at<H: HotLoop>(level: SimdLevel, hot: H) -> H::Output {
    #[cfg(target_arch = "x86_64")]
    if level == SimdLevel::Avx2 && level.is_available() {
        // SAFETY: `is_available` has just confirmed AVX2 (`is_x86_feature_detected!`), the
        // only feature `run_avx2` enables.
        #[allow(unsafe_code)]
        return unsafe { run_avx2(hot) };
    }
    let _ = level;
    hot.run()
}

/// [`HotLoop::run`] compiled with AVX2 enabled (the loop is inlined here).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn run_avx2<H: HotLoop>(hot: H) -> H::Output {
    hot.run()
}
