//! Shared fixtures of the integration tests (included with `mod common;`).
#![allow(dead_code)]

use mc_verify::{ErrorBox, McResult};

/// Table 4 of the paper (arcmin), rows in the order of chi (eq 25; NOTES item 6):
/// dphi_y1, dphi_z2, dalpha_x1, dalpha_z1, dalpha_x2, dalpha_y2, deps_x, deps_y.
pub const TABLE4_ARCMIN: [f64; 8] = [
    0.4235, 0.7800, 0.4234, 0.7800, 0.2825, 0.2824, 0.4234, 0.4233,
];

/// The paper's box: Table 4 upper bounds, zero lower bounds (the paper prints none).
pub fn table4() -> ErrorBox {
    ErrorBox::from_arcmin([0.0; 8], TABLE4_ARCMIN).expect("Table 4 is a valid box")
}

/// Every number of a result as bits (floats by `to_bits`), for bit-identity checks.
pub fn fingerprint(r: &McResult) -> Vec<u64> {
    let mut v = vec![
        r.samples,
        r.seed,
        u64::from(r.chunk_size),
        r.within_requirement_all,
    ];
    v.extend(r.requirement_rad.map(f64::to_bits));
    for a in &r.axes {
        v.extend([
            a.max_abs_rad.to_bits(),
            a.mean_rad.to_bits(),
            a.m2_rad2.to_bits(),
            a.within_requirement,
            a.worst.index,
            a.worst.value_rad.to_bits(),
            a.worst.pose.phi1_rad.to_bits(),
            a.worst.pose.phi2_rad.to_bits(),
            a.histogram.half_range_rad.to_bits(),
            a.histogram.underflow,
            a.histogram.overflow,
        ]);
        v.extend(a.worst.chi_rad.map(f64::to_bits));
        v.extend(&a.histogram.counts);
    }
    v
}
