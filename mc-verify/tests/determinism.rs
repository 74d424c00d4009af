//! Determinism: streams from (seed, chunk), never from the thread; order-fixed reduction; for
//! the paper's table and a three-axis table.

mod common;

use common::{config, fingerprint, paper_table, table4, three_axis, three_axis_box};
use mc_verify::{
    BLOCK_CAPACITY, ErrorBox, McResult, MonteCarlo, SampleBlock, TurntableSampler, chunk_rng,
};
use std::sync::atomic::{AtomicU64, Ordering};
use tt_kinematics::{ExactChain, Turntable};

/// Both tables with their boxes.
fn tables() -> Vec<(&'static str, Turntable, ErrorBox)> {
    vec![
        ("paper", paper_table(), table4()),
        ("three-axis", three_axis(), three_axis_box()),
    ]
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
}

fn run_on(threads: usize, mc: &MonteCarlo) -> McResult {
    pool(threads).install(|| mc.run())
}

/// Issue 5: "Bit-identical results for 1, 2 and 4 threads". Many small chunks (and a short
/// last chunk and block) so that every thread count splits the work differently.
#[test]
fn fast_run_is_bit_identical_for_1_2_and_4_threads() {
    for (name, t, b) in tables() {
        let mut cfg = config(300_001, 2017);
        cfg.chunk_size = 1_000;
        let mc = MonteCarlo::new(&t, b, cfg).unwrap();
        let one = fingerprint(&run_on(1, &mc));
        assert_eq!(one, fingerprint(&run_on(2, &mc)), "{name}");
        assert_eq!(one, fingerprint(&run_on(4, &mc)), "{name}");
    }
}

#[test]
fn model_run_is_bit_identical_for_1_2_and_4_threads() {
    for (name, t, b) in tables() {
        let mut cfg = config(20_003, 3);
        cfg.chunk_size = 500;
        let mc = MonteCarlo::new(&t, b, cfg).unwrap();
        let chain = ExactChain::new(&t);
        let runs: Vec<Vec<u64>> = [1, 2, 4]
            .iter()
            .map(|&n| fingerprint(&pool(n).install(|| mc.run_model(&chain).unwrap())))
            .collect();
        assert_eq!(runs[0], runs[1], "{name}");
        assert_eq!(runs[0], runs[2], "{name}");
    }
}

#[test]
fn same_seed_twice_gives_the_same_result_and_another_seed_a_different_one() {
    for (name, t, b) in tables() {
        let mc = |seed| MonteCarlo::new(&t, b.clone(), config(100_000, seed)).unwrap();
        let a = fingerprint(&mc(1).run());
        assert_eq!(a, fingerprint(&mc(1).run()), "{name}");
        let other = mc(2).run();
        assert_ne!(a, fingerprint(&other), "{name}");
        // not just the seed field: the draws differ
        assert_ne!(
            mc(1).run().axes()[0].worst().chi_rad(),
            other.axes()[0].worst().chi_rad()
        );
    }
}

/// Different chunks of one seed are different streams; the same (seed, chunk) is the same.
#[test]
fn chunk_streams_depend_on_seed_and_chunk_only() {
    for (_, t, b) in tables() {
        let s = TurntableSampler::new(&b, &t);
        let draw = |seed, chunk| s.sample(&mut chunk_rng(seed, chunk));
        assert_eq!(draw(9, 4), draw(9, 4));
        assert_ne!(draw(9, 4), draw(9, 5));
        assert_ne!(draw(9, 4), draw(8, 4));
    }
}

/// `sample` is a block of one; a block of n consumes exactly `words_per_sample * n` words
/// (10 for the paper's table: 8 errors and 2 joints; 16 for the three-axis table: 13 and 3).
#[test]
fn sample_is_a_block_of_one_and_blocks_consume_words_per_sample_words() {
    for ((_, t, b), words) in tables().into_iter().zip([10, 16]) {
        let s = TurntableSampler::new(&b, &t);
        assert_eq!(s.words_per_sample(), words);
        let mut block = SampleBlock::new(&s);
        let (mut a, mut r) = (chunk_rng(1, 0), chunk_rng(1, 0));
        for _ in 0..3 {
            let (pose, chi) = s.sample(&mut a);
            s.fill_block(&mut r, 1, &mut block);
            assert_eq!(block.len(), 1);
            assert_eq!(chi, block.chi_rad(0));
            let mut into = vec![0.0; b.len()];
            block.chi_rad_into(0, &mut into);
            assert_eq!(chi, into);
            assert_eq!(pose, block.pose(0));
            assert_eq!(pose.len(), t.n_joints());
        }
        s.fill_block(&mut a, BLOCK_CAPACITY, &mut block);
        for _ in 0..words * BLOCK_CAPACITY {
            rand_core::Rng::next_u32(&mut r);
        }
        assert_eq!(s.sample(&mut a), s.sample(&mut r));
    }
}

/// A block made for one sampler is resized when filled by another (no panic, right draws).
#[test]
fn a_block_adapts_to_the_sampler_that_fills_it() {
    let paper = TurntableSampler::new(&table4(), &paper_table());
    let three = TurntableSampler::new(&three_axis_box(), &three_axis());
    let mut block = SampleBlock::new(&paper);
    three.fill_block(&mut chunk_rng(4, 0), 5, &mut block);
    let (pose, chi) = three.sample(&mut chunk_rng(4, 0));
    assert_eq!(block.chi_rad(0).len(), 13);
    assert_eq!(block.pose(0).len(), 3);
    // sample 0 of a block of 5 is not sample 0 of a block of one (component-major words),
    // but it follows the same law
    assert_eq!(chi.len(), 13);
    assert_eq!(pose.len(), 3);
}

#[test]
fn progress_reports_monotone_counts_ending_at_the_sample_count() {
    // 1,000 chunks: several waves (at most 256 chunks each), so several progress calls
    let mut cfg = config(1_000_000, 1);
    cfg.chunk_size = 1_000;
    let mc = MonteCarlo::new(&paper_table(), table4(), cfg).unwrap();
    let last = AtomicU64::new(0);
    let calls = AtomicU64::new(0);
    let r = mc.run_with_progress(&|done| {
        assert!(done >= last.load(Ordering::SeqCst));
        last.store(done, Ordering::SeqCst);
        calls.fetch_add(1, Ordering::SeqCst);
    });
    assert_eq!(last.load(Ordering::SeqCst), 1_000_000);
    assert!(calls.load(Ordering::SeqCst) >= 2);
    assert_eq!(r.count().samples(), 1_000_000);
}

#[test]
fn draw_only_draws_every_sample() {
    for (_, t, b) in tables() {
        let mc = MonteCarlo::new(&t, b, config(123_457, 1)).unwrap();
        assert_eq!(mc.draw_only(), 123_457);
        assert_eq!(mc.draw_words_only(), 123_457);
    }
}

/// The streams are reusable (issue 7): the worst samples a run reports are found again by
/// drawing their chunk with `chunk_rng` and `fill_block` in blocks of `BLOCK_CAPACITY`, and
/// `chunk_values_rad` gives their values.
#[test]
fn run_samples_are_reproduced_by_chunk_rng_and_fill_block() {
    for (name, t, b) in tables() {
        // chunks of 3,000 = 23 blocks of 128 + one of 56; the last chunk is shorter still
        let mut cfg = config(50_000, 77);
        cfg.chunk_size = 3_000;
        let mc = MonteCarlo::new(&t, b.clone(), cfg).unwrap();
        let r = mc.run();
        let s = TurntableSampler::new(&b, &t);
        let cs = u64::from(cfg.chunk_size);
        for a in r.axes() {
            let (chunk, mut k) = (a.worst().index() / cs, (a.worst().index() % cs) as usize);
            let values = mc.chunk_values_rad(chunk);
            assert_eq!(
                values[k][a.axis().index()].to_bits(),
                a.worst().value().to_bits(),
                "{name}"
            );
            // blocks of BLOCK_CAPACITY, the last one of a chunk shorter
            let mut left = (r.count().samples() - chunk * cs).min(cs) as usize;
            assert_eq!(values.len(), left);
            let mut rng = chunk_rng(77, chunk);
            let mut block = SampleBlock::new(&s);
            loop {
                let n = left.min(BLOCK_CAPACITY);
                s.fill_block(&mut rng, n, &mut block);
                if k < n {
                    break;
                }
                k -= n;
                left -= n;
            }
            assert_eq!(block.chi_rad(k), a.worst().chi_rad(), "{name}");
            assert_eq!(&block.pose(k), a.worst().pose(), "{name}");
        }
        assert!(mc.chunk_values_rad(mc.chunks()).is_empty());
    }
}
