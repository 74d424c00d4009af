//! How an allocation that is tight on the linear model (26) fares on the exact chain.
//!
//! The allocation is exact for the first-order model; the finite-rotation chain adds terms of
//! second order in the errors (products $\chi_i\chi_j$, about $10^{-7}$ rad for sub-arcminute
//! errors against $I = 4.7\times10^{-4}$ rad). An allocation that uses the whole requirement on
//! the linear model can therefore exceed it on the exact chain by that much. This module
//! measures it, and [`allocate_with_exact_margin`] shrinks the requirement by the measured
//! excess until the exact chain's worst case found is within the original requirement.

use crate::allocation::{Allocation, Allocator};
use crate::error::AllocError;
use crate::problem::AllocationProblem;
use std::f64::consts::TAU;
use tt_kinematics::{
    CHI_LEN, ExactChain, OrientationAxis, OrientationErrorModel, Pose, TurntableErrors,
};

/// Poses $\phi_2$ scanned besides each angle's linear worst pose (every 2.5 degrees).
const SCAN_POSES: usize = 144;

/// The exact chain's worst case found for one angle.
#[derive(Debug, Clone, PartialEq)]
pub struct ExactAxisCheck {
    /// The angle.
    pub axis: OrientationAxis,
    /// $I_k$ (rad).
    pub requirement_rad: f64,
    /// The linear model's worst case (the certificate's, rad).
    pub linear_worst_rad: f64,
    /// The largest $|f_k|$ of the exact chain found (rad).
    pub exact_worst_rad: f64,
    /// `exact_worst_rad - requirement_rad` (rad): positive means the exact chain exceeds $I_k$.
    pub excess_rad: f64,
    /// The pose $\phi_2$ (rad) of that worst case ($\phi_1$ cancels exactly).
    pub phi2_rad: f64,
    /// The error vertex $\chi$ (rad) of that worst case, each $\pm\mathrm{UB}_i$.
    pub chi_rad: [f64; CHI_LEN],
}

/// Evaluate the exact chain (finite rotations, eq 17-24) at the $2^8$ sign vertices
/// $\chi_i = \pm\mathrm{UB}_i$, at each angle's linear worst pose and on a 2.5-degree grid of
/// $\phi_2$, and report the largest $|f_k|$ found per angle.
///
/// This is a search, not a proof: it finds the second-order excess where the linear model is
/// worst, which is where it matters.
///
/// # Errors
/// [`AllocError::NonFinite`] when a bound is infinite (a component no angle depends on).
pub fn exact_chain_check(allocation: &Allocation) -> Result<[ExactAxisCheck; 3], AllocError> {
    let ub = allocation.upper_bounds_rad;
    for (i, u) in ub.iter().enumerate() {
        crate::error::finite(format!("upper_bounds[{i}]"), *u)?;
    }
    let chain = ExactChain::default();
    let mut out = Vec::with_capacity(3);
    for axis in OrientationAxis::ALL {
        let cert = allocation.certificate.get(axis);
        let mut poses = vec![cert.worst_phi2_rad];
        poses.extend((0..SCAN_POSES).map(|j| TAU * j as f64 / SCAN_POSES as f64));
        let mut best = (f64::NEG_INFINITY, 0.0, [0.0; CHI_LEN]);
        for &phi2 in &poses {
            let pose = Pose::new(0.0, phi2).map_err(|_| AllocError::NonFinite {
                field: "phi2".into(),
                value: phi2,
            })?;
            for signs in 0u32..(1 << CHI_LEN) {
                let chi: [f64; CHI_LEN] =
                    std::array::from_fn(|i| if signs & (1 << i) == 0 { ub[i] } else { -ub[i] });
                let errors =
                    TurntableErrors::from_rad(chi, 0.0).map_err(|_| AllocError::NonFinite {
                        field: "upper_bounds".into(),
                        value: f64::NAN,
                    })?;
                let v = chain.orientation_error(&pose, &errors).get(axis).abs();
                if v > best.0 {
                    best = (v, phi2, chi);
                }
            }
        }
        out.push(ExactAxisCheck {
            axis,
            requirement_rad: cert.requirement_rad,
            linear_worst_rad: cert.worst_case_rad,
            exact_worst_rad: best.0,
            excess_rad: best.0 - cert.requirement_rad,
            phi2_rad: best.1,
            chi_rad: best.2,
        });
    }
    Ok([out.remove(0), out.remove(0), out.remove(0)])
}

/// An allocation whose exact-chain worst case (as found by [`exact_chain_check`]) is within
/// the original requirement, with the relative safety margin that achieved it.
#[derive(Debug, Clone, PartialEq)]
pub struct ExactSafeAllocation {
    /// The allocation (its `requirement` is the shrunk one).
    pub allocation: Allocation,
    /// The relative margin $m$: the allocation was made for $(1-m)I$.
    pub margin: f64,
    /// The exact-chain check against the original requirement.
    pub check: [ExactAxisCheck; 3],
}

/// Allocate, measure the exact chain's excess, and shrink every requirement by the largest
/// relative excess (plus 1%), up to four times, until the exact chain stays within the
/// original requirement.
///
/// # Errors
/// Those of the allocator and of [`exact_chain_check`]; [`AllocError::NoConvergence`] if four
/// rounds do not suffice.
pub fn allocate_with_exact_margin(
    allocator: &dyn Allocator,
    problem: &AllocationProblem,
) -> Result<ExactSafeAllocation, AllocError> {
    let original = problem.requirement();
    const ROUNDS: usize = 4;
    let mut margin = 0.0_f64;
    let mut last_violation = f64::NAN;
    for _ in 0..ROUNDS {
        let shrunk = problem.with_safety_margin(margin)?;
        let allocation = allocator.allocate(&shrunk)?;
        let mut check = exact_chain_check(&allocation)?;
        let mut worst_rel = f64::NEG_INFINITY;
        for c in &mut check {
            c.requirement_rad = original.get(c.axis);
            c.excess_rad = c.exact_worst_rad - c.requirement_rad;
            worst_rel = worst_rel.max(c.excess_rad / c.requirement_rad);
        }
        if worst_rel <= 0.0 {
            return Ok(ExactSafeAllocation {
                allocation,
                margin,
                check,
            });
        }
        last_violation = worst_rel;
        margin += worst_rel * 1.01;
    }
    Err(AllocError::NoConvergence {
        problem: "exact-chain margin".into(),
        iterations: ROUNDS,
        violation: last_violation,
    })
}
