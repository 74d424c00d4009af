//! The paper's example (§4.3): allocate with the sensitivity-weighted and the equal-effects
//! methods and print them beside Table 4, with the objective and the share of each requirement.
//!
//! Run: `cargo run -p alloc-opt --example paper_allocation`

use alloc_opt::{
    AllocError, Allocator, Certificate, EqualEffects, SensitivityWeighted, Weights,
    allocate_with_exact_margin, exact_chain_check, paper,
};
use tt_core::units::RAD_PER_ARCMIN;

fn main() -> Result<(), AllocError> {
    let problem = paper::example_problem()?;
    let ours = SensitivityWeighted::paper().allocate(&problem)?;
    let equal = EqualEffects.allocate(&problem)?;
    let table4 = paper::table4_rad();
    let table4_cert = Certificate::compute(
        problem.model(),
        problem.limits(),
        problem.lower_bounds_rad(),
        &table4,
    )?;
    let table4_j = Weights::inverse_average_sensitivity(problem.model()).objective(&table4)
        * RAD_PER_ARCMIN
        * RAD_PER_ARCMIN;
    println!(
        "{:<10} {:>10} {:>10} {:>10}",
        "error", "ours'", "Table 4'", "equal'"
    );
    for (i, name) in ours.error_names().iter().enumerate() {
        println!(
            "{:<10} {:>10.4} {:>10.4} {:>10.4}",
            name,
            ours.upper_bounds_arcmin()[i],
            paper::TABLE4_ARCMIN[i],
            equal.upper_bounds_arcmin()[i]
        );
    }
    println!(
        "{:<10} {:>10.3} {:>10.3} {:>10.3}",
        "J",
        ours.objective_arcmin(),
        table4_j,
        equal.objective_arcmin()
    );
    let share = |c: &Certificate, k: usize| c.axes()[k].share().unwrap_or(f64::NAN);
    for (k, name) in ["psi", "theta", "gamma"].iter().enumerate() {
        println!(
            "share {:<4} {:>10.4} {:>10.4} {:>10.4}",
            name,
            share(ours.certificate(), k),
            share(&table4_cert, k),
            share(equal.certificate(), k)
        );
    }
    for c in exact_chain_check(&problem, &ours)? {
        println!(
            "exact chain {:?}: worst {:.6e} rad, requirement {:.6e} rad, excess {:+.3e} rad",
            c.axis(),
            c.exact_worst_rad(),
            c.requirement_rad().unwrap_or(f64::NAN),
            c.excess_rad().unwrap_or(f64::NAN)
        );
    }
    let safe = allocate_with_exact_margin(&SensitivityWeighted::paper(), &problem)?;
    println!(
        "exact-chain-safe allocation: margin {:.3e}, bounds (arcmin) {:.5?}",
        safe.margin(),
        safe.allocation().upper_bounds_arcmin()
    );
    for s in ours.subproblems() {
        println!(
            "problem {:?}: worst pose {:.6?} rad, load {:.15}, {} conic solves",
            s.name(),
            s.worst_pose_rad(),
            s.load(),
            s.iterations()
        );
    }
    Ok(())
}
