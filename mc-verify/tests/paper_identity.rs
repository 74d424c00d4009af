//! The general plan evaluates the paper's table exactly as the crate's earlier kernel,
//! specialised to it, did: same draws, same results, bit for bit.
//!
//! Two proofs: (1) values pinned from the earlier code (commit 5018d77, its
//! `MonteCarlo::run` on the same configurations, printed with a throw-away example) are
//! reproduced to the bit; (2) the kept copy of that kernel ([`mc_verify::baseline`]) and the
//! general plan give bit-identical results on the same samples, in every tier.

mod common;

use common::{
    PoseAt, TABLE4_ARCMIN, config, fingerprint, fingerprint_laid_out, paper_table, table4,
};
use mc_verify::baseline::{paper_kernel_run, paper_kernel_run_with_simd};
use mc_verify::{
    ErrorBox, McError, McResult, MonteCarlo, SimdLevel, Tier, TurntableSampler, chunk_rng,
};

/// The fingerprint layout of the earlier crate (pose (phi1, phi2) before the chi of the
/// worst sample, eight chi), so that pinned hashes can be compared.
fn legacy_fingerprint(r: &McResult) -> Vec<u64> {
    for a in r.axes() {
        assert_eq!(
            a.worst().pose().angles_rad().len(),
            2,
            "the paper's two joints"
        );
    }
    fingerprint_laid_out(r, PoseAt::AfterWorst, |i| {
        i.expect("eq 16 on every axis").to_bits()
    })
}

/// FNV-1a over the little-endian bytes of the words.
fn fnv1a(v: &[u64]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for x in v {
        for b in x.to_le_bytes() {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    h
}

fn arcmin_box(lb: [f64; 8], ub: [f64; 8]) -> ErrorBox {
    ErrorBox::from_arcmin(&paper_table(), lb.to_vec(), ub.to_vec()).unwrap()
}

/// One box per tier, with the configuration of the pinned runs.
fn pinned_cases() -> Vec<(&'static str, ErrorBox, u64, u64, u32, Tier)> {
    vec![
        ("table4 LB=0", table4(), 300_001, 2017, 1_000, Tier::Tangent),
        (
            "table4 LB=UB/4",
            arcmin_box(TABLE4_ARCMIN.map(|u| 0.25 * u), TABLE4_ARCMIN),
            70_001,
            11,
            10_000,
            Tier::Short,
        ),
        (
            "20 arcmin",
            arcmin_box([0.0; 8], [20.0; 8]),
            70_001,
            11,
            10_000,
            Tier::Medium,
        ),
        (
            "30-120 arcmin",
            arcmin_box([30.0; 8], [120.0; 8]),
            70_001,
            11,
            10_000,
            Tier::Any,
        ),
    ]
}

/// Hashes of the earlier crate's results for [`pinned_cases`] (in order), then Table 4 with
/// 10^6 samples, seed 2017, default chunks.
const PINNED_HASHES: [u64; 5] = [
    0x100e_b7dd_a7bc_3fc6,
    0xa985_28c6_72b3_3fa9,
    0xfefa_b120_4d00_74fc,
    0xc313_232e_bd9f_fe29,
    0x7b59_f536_e695_bb05,
];

fn mc(b: ErrorBox, samples: u64, seed: u64, chunk: u32) -> MonteCarlo {
    let mut cfg = config(samples, seed);
    cfg.chunk_size = chunk;
    MonteCarlo::new(&paper_table(), b, cfg).unwrap()
}

/// Draws and results of the general code equal the pinned results of the earlier,
/// paper-only code to the bit, in every tier (including the per-axis maxima, means, M2,
/// worst samples and all 600 histogram counts).
#[test]
fn general_plan_reproduces_values_pinned_from_the_specialised_kernel() {
    for ((name, b, samples, seed, chunk, tier), hash) in
        pinned_cases().into_iter().zip(PINNED_HASHES)
    {
        let mc = mc(b, samples, seed, chunk);
        assert_eq!(mc.tier(), tier, "{name}");
        let f = legacy_fingerprint(&mc.run());
        assert_eq!(f.len(), 664, "{name}");
        assert_eq!(fnv1a(&f), hash, "{name}");
    }
    let r = mc(table4(), 1_000_000, 2017, mc_verify::DEFAULT_CHUNK_SIZE).run();
    assert_eq!(fnv1a(&legacy_fingerprint(&r)), PINNED_HASHES[4]);
    // readable pins of the same run: max |dpsi|, |dtheta|, |dgamma| (rad) and worst indices
    assert_eq!(
        r.max_abs_rad().map(f64::to_bits),
        [
            0x3f39_f610_f4d8_150c,
            0x3f3d_b98a_2fd8_1caa,
            0x3f3a_6710_90e4_a39e
        ]
    );
    assert_eq!(
        r.axes().each_ref().map(|a| a.worst().index()),
        [221_236, 391_133, 313_346]
    );
}

/// The draws themselves: `sample` on chunk_rng(7, 3) gives the pinned turntables.
#[test]
fn draws_reproduce_values_pinned_from_the_earlier_sampler() {
    let s = TurntableSampler::new(&table4(), &paper_table());
    assert_eq!(s.words_per_sample(), 10);
    let mut rng = chunk_rng(7, 3);
    let pinned: [([u64; 8], [u64; 2]); 2] = [
        (
            [
                0xbf1e_a534_635f_e3c3,
                0x3f15_9880_41f5_5841,
                0xbf1e_dbbb_61c7_aa2d,
                0x3f06_1801_2138_7bef,
                0xbf08_3051_dedc_52c8,
                0xbecc_ef6c_5c03_1dcc,
                0x3f01_c1fa_6f70_d5f5,
                0x3f15_9380_a16d_ea79,
            ],
            [0x3ff3_6e86_ddd9_b59c, 0x4001_a770_9de7_69e4],
        ),
        (
            [
                0x3ef5_d71e_bd52_7f70,
                0x3f26_de9a_8d34_0b55,
                0x3f17_f42c_8ac2_bd98,
                0xbf03_3e10_6645_e08e,
                0xbf0e_9346_6cff_23e0,
                0x3f0c_546f_80be_3b52,
                0xbf16_fe98_e42b_624c,
                0x3ef7_9f1a_ec3c_6d93,
            ],
            [0x4012_01e9_9701_fe7d, 0x4005_b045_1b6f_8863],
        ),
    ];
    for (chi_bits, pose_bits) in pinned {
        let (pose, chi) = s.sample(&mut rng);
        assert_eq!(
            chi.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            chi_bits
        );
        assert_eq!(
            pose.angles_rad()
                .iter()
                .map(|x| x.to_bits())
                .collect::<Vec<_>>(),
            pose_bits
        );
    }
}

/// The kept specialised kernel and the general plan, same samples: bit-identical results in
/// every tier and on every SIMD level of this CPU.
#[test]
fn general_plan_equals_the_kept_specialised_kernel_bit_for_bit_in_every_tier() {
    // plus boxes with zero upper bounds (exact zeros flow through the chain)
    let zero_ub = [0.0, 0.78, 0.4, 0.0, 0.3, 0.3, 0.0, 0.4];
    let mut cases = pinned_cases();
    for (name, lb, ub) in [
        ("some UB = 0", [0.0; 8], zero_ub),
        ("some UB = 0, LB > 0", zero_ub.map(|u| 0.5 * u), zero_ub),
        ("all UB = 0", [0.0; 8], [0.0; 8]),
        ("some UB = 0, 2 deg", [0.0; 8], zero_ub.map(|u| 150.0 * u)),
    ] {
        cases.push((name, arcmin_box(lb, ub), 0, 5, 7_000, Tier::Any));
    }
    for (name, b, _, seed, chunk, _) in cases {
        let mc = mc(b, 40_001, seed, chunk);
        let general = fingerprint(&mc.run());
        assert_eq!(
            general,
            fingerprint(&paper_kernel_run(&mc).unwrap()),
            "{name}"
        );
        for level in SimdLevel::available() {
            assert_eq!(
                fingerprint(&mc.run_with_simd(level).unwrap()),
                fingerprint(&paper_kernel_run_with_simd(&mc, level).unwrap()),
                "{name}: level {}",
                level.name()
            );
        }
    }
}

/// The specialised kernel refuses another table.
#[test]
fn the_specialised_kernel_refuses_another_turntable() {
    let t = common::three_axis();
    let mc = MonteCarlo::new(&t, common::three_axis_box(), config(1_000, 1)).unwrap();
    assert_eq!(paper_kernel_run(&mc), Err(McError::NotThePaperTable));
}
