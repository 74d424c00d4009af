//! The paper's example (§4.3): allocate with the sensitivity-weighted and the equal-effects
//! methods and print them beside Table 4, with the objective and the share of each requirement.
//!
//! Run: `cargo run -p alloc-opt --example paper_allocation`

use alloc_opt::{
    AllocError, AllocationProblem, Allocator, Certificate, EqualEffects, PAPER_TABLE4_ARCMIN,
    SensitivityWeighted, Weights, allocate_with_exact_margin, exact_chain_check, paper_table4_rad,
};
use tt_kinematics::units::RAD_PER_ARCMIN;
use tt_kinematics::{ErrorComponent, LinearModel};

fn main() -> Result<(), AllocError> {
    let problem = AllocationProblem::paper_example()?;
    let ours = SensitivityWeighted::paper().allocate(&problem)?;
    let equal = EqualEffects.allocate(&problem)?;
    let paper_ub = paper_table4_rad();
    let paper_cert = Certificate::compute(
        problem.model(),
        &problem.requirement(),
        &problem.lower_bounds_rad(),
        &paper_ub,
    );
    let paper_j = Weights::inverse_average_sensitivity(&LinearModel::paper_eq26())
        .objective(&paper_ub)
        * RAD_PER_ARCMIN
        * RAD_PER_ARCMIN;
    println!(
        "{:<10} {:>10} {:>10} {:>10}",
        "component", "ours'", "Table 4'", "equal'"
    );
    for c in ErrorComponent::ALL {
        let i = c.index();
        println!(
            "{:<10} {:>10.4} {:>10.4} {:>10.4}",
            c.name(),
            ours.upper_bounds_arcmin()[i],
            PAPER_TABLE4_ARCMIN[i],
            equal.upper_bounds_arcmin()[i]
        );
    }
    println!(
        "{:<10} {:>10.3} {:>10.3} {:>10.3}",
        "J",
        ours.objective_arcmin(),
        paper_j,
        equal.objective_arcmin()
    );
    for (k, name) in ["psi", "theta", "gamma"].iter().enumerate() {
        println!(
            "share {:<4} {:>10.4} {:>10.4} {:>10.4}",
            name,
            ours.shares()[k],
            paper_cert.axes[k].share,
            equal.shares()[k]
        );
    }
    for c in exact_chain_check(&ours)? {
        println!(
            "exact chain {:?}: worst {:.6e} rad, requirement {:.6e} rad, excess {:+.3e} rad",
            c.axis, c.exact_worst_rad, c.requirement_rad, c.excess_rad
        );
    }
    let safe = allocate_with_exact_margin(&SensitivityWeighted::paper(), &problem)?;
    println!(
        "exact-chain-safe allocation: margin {:.3e}, bounds (arcmin) {:?}",
        safe.margin,
        safe.allocation.upper_bounds_arcmin()
    );
    for s in &ours.subproblems {
        println!(
            "problem {:?}: worst phi2 {:.6} rad, load {:.15}, {} conic solves",
            s.axis, s.worst_phi2_rad, s.load, s.iterations
        );
    }
    Ok(())
}
