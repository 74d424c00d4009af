//! Allocation for a table that is not the paper's: a three-axis table (outer axis about z,
//! middle about x, inner about y; 13 rotation errors; two free joints), described as data,
//! with the full-range form of eq 30. Prints the bounds, the certificate (searched worst case,
//! rigorous bound and its gap), the safety scaling and the exact chain's excess.
//!
//! Run: `cargo run --release -p alloc-opt --example three_axis_allocation`

use alloc_opt::{
    AllocationProblem, Allocator, EqualEffects, Requirement, SensitivityWeighted, exact_chain_check,
};
use tt_core::units::{RAD_PER_ARCMIN, arcmin_to_rad};
use tt_kinematics::conformance::three_axis_description;
use tt_kinematics::{LinearModel, Turntable};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // the workspace's reference three-axis table (tt-kinematics' conformance module), a
    // `TurntableDescription` written as data: factors from the base to the platform
    let table = Turntable::new(&three_axis_description())?;
    let model = LinearModel::new(&table);
    let n = model.n_errors();
    let i = arcmin_to_rad(1.62);
    let problem = AllocationProblem::new(model, Requirement::new(i, i, i)?, vec![0.0; n])?;
    let ours = SensitivityWeighted::general().allocate(&problem)?;
    let equal = EqualEffects.allocate(&problem)?;
    println!("{:<10} {:>10} {:>10}", "error", "ours'", "equal'");
    for (k, name) in ours.error_names().iter().enumerate() {
        println!(
            "{:<10} {:>10.7} {:>10.7}",
            name,
            ours.upper_bounds_arcmin()[k],
            equal.upper_bounds_arcmin()[k]
        );
    }
    println!(
        "J (arcmin^-2): ours {:.4}, equal effects {:.4}",
        ours.objective_arcmin(),
        equal.objective_arcmin()
    );
    println!(
        "safety scale (psi, theta, gamma): {:?}",
        ours.safety_scale()
    );
    for c in ours.certificate().axes() {
        println!(
            "{:<5} worst found {:.7}' at pose {:.6?} rad, rigorous bound {:.7}' (gap {:.2e}), \
             share {:.9}, active {}, Lemma 1 {}",
            c.name(),
            c.worst_case_rad() / RAD_PER_ARCMIN,
            c.worst_pose_rad(),
            c.upper_bound_rad() / RAD_PER_ARCMIN,
            c.upper_bound_rad() / c.worst_case_rad() - 1.0,
            c.share().unwrap_or(f64::NAN),
            c.requirement_active(),
            c.satisfied()
        );
    }
    for s in ours.subproblems() {
        println!(
            "problem {:<5}: {} conic solves, load {:.15}, multiplier {:.6e}",
            s.name(),
            s.iterations(),
            s.load(),
            s.multiplier().unwrap_or(f64::NAN)
        );
    }
    for c in exact_chain_check(&problem, &ours)? {
        println!(
            "exact chain {:<5}: worst found {:.9e} rad, excess {:+.3e} rad ({} evaluations)",
            c.axis().name(),
            c.exact_worst_rad(),
            c.excess_rad().unwrap_or(f64::NAN),
            c.evaluations()
        );
    }
    Ok(())
}
