//! Determinism: streams from (seed, chunk), never from the thread; order-fixed reduction.

mod common;

use common::{fingerprint, table4};
use mc_verify::{
    BLOCK_CAPACITY, ErrorBox, McConfig, McResult, MonteCarlo, SampleBlock, TurntableSampler,
    chunk_rng,
};
use std::sync::atomic::{AtomicU64, Ordering};
use tt_kinematics::ExactChain;

fn run_on(threads: usize, mc: &MonteCarlo) -> McResult {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(|| mc.run())
}

/// Issue 5: "Bit-identical results for 1, 2 and 4 threads". Many small chunks (and a short
/// last chunk and block) so that every thread count splits the work differently.
#[test]
fn fast_run_is_bit_identical_for_1_2_and_4_threads() {
    let mut cfg = McConfig::new(300_001, 2017);
    cfg.chunk_size = 1_000;
    let mc = MonteCarlo::new(table4(), cfg).unwrap();
    let one = fingerprint(&run_on(1, &mc));
    assert_eq!(one, fingerprint(&run_on(2, &mc)));
    assert_eq!(one, fingerprint(&run_on(4, &mc)));
}

#[test]
fn model_run_is_bit_identical_for_1_2_and_4_threads() {
    let mut cfg = McConfig::new(20_003, 3);
    cfg.chunk_size = 500;
    let mc = MonteCarlo::new(table4(), cfg).unwrap();
    let runs: Vec<Vec<u64>> = [1, 2, 4]
        .iter()
        .map(|&t| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(t)
                .build()
                .unwrap();
            fingerprint(&pool.install(|| mc.run_model(&ExactChain::default()).unwrap()))
        })
        .collect();
    assert_eq!(runs[0], runs[1]);
    assert_eq!(runs[0], runs[2]);
}

#[test]
fn same_seed_twice_gives_the_same_result_and_another_seed_a_different_one() {
    let mc = |seed| MonteCarlo::new(table4(), McConfig::new(100_000, seed)).unwrap();
    let a = fingerprint(&mc(1).run());
    assert_eq!(a, fingerprint(&mc(1).run()));
    let b = mc(2).run();
    assert_ne!(a, fingerprint(&b));
    // not just the seed field: the draws differ
    assert_ne!(
        mc(1).run().axes[0].worst.chi_rad.map(f64::to_bits),
        b.axes[0].worst.chi_rad.map(f64::to_bits)
    );
}

/// Different chunks of one seed are different streams; the same (seed, chunk) is the same.
#[test]
fn chunk_streams_depend_on_seed_and_chunk_only() {
    let s = TurntableSampler::new(&table4());
    let draw = |seed, chunk| s.sample(&mut chunk_rng(seed, chunk)).1.map(f64::to_bits);
    assert_eq!(draw(9, 4), draw(9, 4));
    assert_ne!(draw(9, 4), draw(9, 5));
    assert_ne!(draw(9, 4), draw(8, 4));
}

/// `sample` is a block of one; a block of n consumes exactly 10 n words.
#[test]
fn sample_is_a_block_of_one_and_blocks_consume_ten_words_per_sample() {
    let s = TurntableSampler::new(&table4());
    let mut block = SampleBlock::default();
    let (mut a, mut b) = (chunk_rng(1, 0), chunk_rng(1, 0));
    for _ in 0..3 {
        let (pose, chi) = s.sample(&mut a);
        s.fill_block(&mut b, 1, &mut block);
        assert_eq!(block.len(), 1);
        assert_eq!(chi.map(f64::to_bits), block.chi_rad(0).map(f64::to_bits));
        assert_eq!(pose, block.pose(0));
    }
    s.fill_block(&mut a, BLOCK_CAPACITY, &mut block);
    for _ in 0..10 * BLOCK_CAPACITY {
        rand_core::Rng::next_u32(&mut b);
    }
    let (pa, ca) = s.sample(&mut a);
    let (pb, cb) = s.sample(&mut b);
    assert_eq!(ca.map(f64::to_bits), cb.map(f64::to_bits));
    assert_eq!(pa, pb);
}

#[test]
fn progress_reports_monotone_counts_ending_at_the_sample_count() {
    // 1,000 chunks: several waves (at most 256 chunks each), so several progress calls
    let mut cfg = McConfig::new(1_000_000, 1);
    cfg.chunk_size = 1_000;
    let mc = MonteCarlo::new(table4(), cfg).unwrap();
    let last = AtomicU64::new(0);
    let calls = AtomicU64::new(0);
    let r = mc.run_with_progress(&|done| {
        assert!(done >= last.load(Ordering::SeqCst));
        last.store(done, Ordering::SeqCst);
        calls.fetch_add(1, Ordering::SeqCst);
    });
    assert_eq!(last.load(Ordering::SeqCst), 1_000_000);
    assert!(calls.load(Ordering::SeqCst) >= 2);
    assert_eq!(r.samples, 1_000_000);
}

#[test]
fn draw_only_draws_every_sample() {
    let b = ErrorBox::from_upper_rad([1e-4; 8]).unwrap();
    let mc = MonteCarlo::new(b, McConfig::new(123_457, 1)).unwrap();
    assert_eq!(mc.draw_only(), 123_457);
}

/// The streams are reusable (issue 7): the worst samples a run reports are found again by
/// drawing their chunk with `chunk_rng` and `fill_block` in blocks of `BLOCK_CAPACITY`.
#[test]
fn run_samples_are_reproduced_by_chunk_rng_and_fill_block() {
    // chunks of 3,000 = 23 blocks of 128 + one of 56; the last chunk is shorter still
    let mut cfg = McConfig::new(50_000, 77);
    cfg.chunk_size = 3_000;
    let mc = MonteCarlo::new(table4(), cfg).unwrap();
    let r = mc.run();
    let s = TurntableSampler::new(&table4());
    let cs = u64::from(cfg.chunk_size);
    for a in &r.axes {
        let (chunk, mut k) = (a.worst.index / cs, (a.worst.index % cs) as usize);
        // blocks of BLOCK_CAPACITY, the last one of a chunk shorter
        let mut left = (r.samples - chunk * cs).min(cs) as usize;
        let mut rng = chunk_rng(77, chunk);
        let mut block = SampleBlock::default();
        loop {
            let n = left.min(BLOCK_CAPACITY);
            s.fill_block(&mut rng, n, &mut block);
            if k < n {
                break;
            }
            k -= n;
            left -= n;
        }
        assert_eq!(
            block.chi_rad(k).map(f64::to_bits),
            a.worst.chi_rad.map(f64::to_bits)
        );
        assert_eq!(block.pose(k), a.worst.pose);
    }
}
