//! The one chunked Monte Carlo driver of the workspace: every Monte Carlo (the orientation
//! Monte Carlo of this crate, the end-to-end, combined-noise, time-domain and angle-dependent
//! ones of e2e-verify) runs its chunks through [`run_chunks`].
//!
//! A run of $N$ samples is cut into chunks of a fixed size; chunk $c$ draws from its own
//! stream [`crate::chunk_rng`]`(seed, c)`, never from the thread, and the chunks' results are
//! merged in chunk order. So a run gives the same bits on any number of threads. Chunks are
//! evaluated in waves of a bounded number on the current rayon pool: memory holds one wave's
//! results, whatever the sample count.
//!
//! # Example
//! ```
//! use mc_verify::driver::{chunk_len, run_chunks};
//! use rand_core::Rng;
//!
//! // 10,000 uniform draws in chunks of 1,024: their mean, the same on any thread count.
//! let (samples, chunk_size) = (10_000_u64, 1_024_u64);
//! let chunks = samples.div_ceil(chunk_size);
//! let mut sum = 0.0;
//! run_chunks(
//!     chunks,
//!     16,
//!     |c| -> Result<f64, std::convert::Infallible> {
//!         let mut rng = mc_verify::chunk_rng(7, c);
//!         let n = chunk_len(samples, chunk_size, c);
//!         Ok((0..n).map(|_| (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64).sum())
//!     },
//!     |part| {
//!         sum += part;
//!         Ok(())
//!     },
//! )?;
//! let mean = sum / samples as f64;
//! assert!((mean - 0.5).abs() < 0.02);
//! # Ok::<(), std::convert::Infallible>(())
//! ```

use rayon::prelude::*;

/// Evaluate `chunk(c)` for every chunk `c` in `0..chunks`, in waves of at most `wave` chunks
/// (at least one) on the current rayon pool, and hand each result to `merge` in chunk order.
///
/// # Errors
/// The first error in chunk order, from `chunk` or from `merge`; no chunk after its wave is
/// evaluated.
pub fn run_chunks<P, E, C, M>(chunks: u64, wave: u64, chunk: C, mut merge: M) -> Result<(), E>
where
    P: Send,
    E: Send,
    C: Fn(u64) -> Result<P, E> + Sync,
    M: FnMut(P) -> Result<(), E>,
{
    let wave = wave.max(1);
    let mut start = 0;
    while start < chunks {
        let end = (start + wave).min(chunks);
        let parts: Vec<Result<P, E>> = (start..end).into_par_iter().map(&chunk).collect();
        for part in parts {
            merge(part?)?;
        }
        start = end;
    }
    Ok(())
}

/// The number of samples in chunk `chunk` of a run of `samples` in chunks of `chunk_size`
/// (the last chunk may be shorter; 0 past the end).
#[must_use]
pub fn chunk_len(samples: u64, chunk_size: u64, chunk: u64) -> usize {
    let first = chunk.saturating_mul(chunk_size);
    usize::try_from(samples.saturating_sub(first).min(chunk_size)).unwrap_or(usize::MAX)
}

#[cfg(test)]
mod tests {
    use super::{chunk_len, run_chunks};

    #[test]
    fn chunks_are_merged_in_chunk_order_whatever_the_wave_and_thread_count() {
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            for wave in [0, 1, 3, 64] {
                let mut seen = Vec::new();
                pool.install(|| {
                    run_chunks(
                        10,
                        wave,
                        |c| Ok::<u64, ()>(c * c),
                        |p| {
                            seen.push(p);
                            Ok(())
                        },
                    )
                })
                .unwrap();
                assert_eq!(seen, (0..10).map(|c| c * c).collect::<Vec<_>>());
            }
        }
    }

    #[test]
    fn the_first_error_in_chunk_order_stops_the_run() {
        let mut merged = 0;
        let r = run_chunks(
            100,
            8,
            |c| if c == 13 || c == 40 { Err(c) } else { Ok(c) },
            |_| {
                merged += 1;
                Ok(())
            },
        );
        assert_eq!(r, Err(13));
        assert_eq!(merged, 13);
        let r = run_chunks(
            5,
            2,
            Ok::<u64, u64>,
            |p| if p == 3 { Err(99) } else { Ok(()) },
        );
        assert_eq!(r, Err(99));
    }

    #[test]
    fn chunk_lengths_cover_the_samples_exactly() {
        assert_eq!(chunk_len(10, 4, 0), 4);
        assert_eq!(chunk_len(10, 4, 2), 2);
        assert_eq!(chunk_len(10, 4, 3), 0);
        assert_eq!(chunk_len(u64::MAX, 1 << 20, u64::MAX), 0);
        let total: usize = (0..10_u64.div_ceil(3)).map(|c| chunk_len(10, 3, c)).sum();
        assert_eq!(total, 10);
    }
}
