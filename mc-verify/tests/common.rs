//! Shared fixtures of the integration tests (included with `mod common;`).
#![allow(dead_code)]

use mc_verify::{ErrorBox, McConfig, McResult, MonteCarlo};
use tt_core::Requirement;
use tt_kinematics::{Turntable, paper};

/// Table 4 of the paper (arcmin), rows in the order of chi (eq 25; NOTES item 6):
/// dphi_y1, dphi_z2, dalpha_x1, dalpha_z1, dalpha_x2, dalpha_y2, deps_x, deps_y.
pub(crate) const TABLE4_ARCMIN: [f64; 8] = [
    0.4235, 0.7800, 0.4234, 0.7800, 0.2825, 0.2824, 0.4234, 0.4233,
];

/// The paper's requirement, eq 16: 0.027 deg on each angle, deg.
pub(crate) const EQ16_REQUIREMENT_DEG: f64 = 0.027;

/// The paper's requirement (eq 16) on all three angles, rad.
pub(crate) fn eq16() -> Requirement {
    Requirement::from_options([Some(EQ16_REQUIREMENT_DEG.to_radians()); 3]).expect("valid")
}

/// `samples` draws with `seed` and the paper's requirement.
pub(crate) fn config(samples: u64, seed: u64) -> McConfig {
    McConfig::new(samples, seed, eq16())
}

/// 20,000 draws of [`table4`] seeded 3 with a requirement on theta only (1e-4 rad): psi and
/// gamma count every draw as within.
pub(crate) fn theta_only_run() -> McResult {
    let i = Requirement::from_options([None, Some(1e-4), None]).expect("valid");
    MonteCarlo::new(&paper_table(), table4(), McConfig::new(20_000, 3, i))
        .expect("valid run")
        .run()
}

/// The paper's table (Table 3).
pub(crate) fn paper_table() -> Turntable {
    paper::table3()
}

/// The paper's box: Table 4 upper bounds, zero lower bounds (the paper prints none).
pub(crate) fn table4() -> ErrorBox {
    ErrorBox::from_arcmin(&paper_table(), vec![0.0; 8], TABLE4_ARCMIN.to_vec())
        .expect("Table 4 is a valid box")
}

/// The three-axis table of tt-kinematics' conformance suite and of
/// `studies/three-axis-example.toml` (13 angular errors, 3 joints).
#[allow(unused_imports)] // each test binary uses a part of this module
pub(crate) use tt_kinematics::conformance::{three_axis, three_axis_description};

/// Upper bounds of the three-axis table in the short tier (0.3 to 0.6 arcmin).
pub(crate) fn three_axis_ub_arcmin() -> Vec<f64> {
    (0..13).map(|i| 0.3 + 0.025 * f64::from(i)).collect()
}

/// The three-axis box of the examples: [`three_axis_ub_arcmin`], zero lower bounds.
pub(crate) fn three_axis_box() -> ErrorBox {
    ErrorBox::from_arcmin(&three_axis(), vec![0.0; 13], three_axis_ub_arcmin()).expect("valid box")
}

/// Every number of a result as bits (floats by `to_bits`), for bit-identity checks.
pub(crate) fn fingerprint(r: &McResult) -> Vec<u64> {
    fingerprint_laid_out(r, PoseAt::AfterHistogram, |i| {
        i.map_or(u64::MAX, f64::to_bits)
    })
}

/// Where a fingerprint puts the worst sample's pose among an axis's words.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum PoseAt {
    /// Right after the worst sample's value (the earlier crate's layout).
    AfterWorst,
    /// After the histogram's range and out-of-range counts.
    AfterHistogram,
}

/// Every number of a result as bits, the pose at `pose_at` and each axis's requirement (if
/// any) as `requirement` writes it.
pub(crate) fn fingerprint_laid_out(
    r: &McResult,
    pose_at: PoseAt,
    requirement: impl Fn(Option<f64>) -> u64,
) -> Vec<u64> {
    let mut v = vec![
        r.count().samples(),
        r.count().seed(),
        u64::from(r.chunk_size()),
        r.count().meeting(),
    ];
    v.extend(r.requirement().to_array().map(requirement));
    for (a, &within) in r.axes().iter().zip(r.count().meeting_per_output()) {
        let pose = a.worst().pose().angles_rad().iter().map(|x| x.to_bits());
        v.extend([
            a.max_abs_rad().to_bits(),
            a.mean_rad().to_bits(),
            a.m2_rad2().to_bits(),
            within,
            a.worst().index(),
            a.worst().value().to_bits(),
        ]);
        if pose_at == PoseAt::AfterWorst {
            v.extend(pose.clone());
        }
        v.extend([
            a.histogram().hi().to_bits(),
            a.histogram().underflow(),
            a.histogram().overflow(),
        ]);
        if pose_at == PoseAt::AfterHistogram {
            v.extend(pose);
        }
        v.extend(a.worst().chi_rad().iter().map(|x| x.to_bits()));
        v.extend(a.histogram().counts());
    }
    v
}
