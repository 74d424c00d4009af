//! The paper's example (§4.3): its requirement (eq 16), its table (Table 3, whose linear model
//! is eq 26) and its published allocation (Table 4), as golden data with provenance. Nothing
//! here is used by the general code paths.

use crate::error::AllocError;
use crate::problem::AllocationProblem;
use tt_core::Requirement;
use tt_core::units::RAD_PER_ARCMIN;
use tt_kinematics::{LinearModel, paper as tt_paper};

/// The orientation requirement of eq 16 as printed: $|\Delta\psi|, |\Delta\theta|,
/// |\Delta\gamma| \le 0.027^\circ$ (= 1.62 arcmin).
///
/// # Reference
/// Zhao et al. 2017, §2.3, eq 16.
pub const REQUIREMENT_DEG: f64 = 0.027;

/// Table 4 of the paper: the published upper bounds $\mathrm{UB}_i$ in arcminutes, in the order
/// of $\chi$ in eq 25 ($\Delta\phi_{y1}, \Delta\phi_{z2}, \Delta\alpha_{x1}, \Delta\alpha_{z1},
/// \Delta\alpha_{x2}, \Delta\alpha_{y2}, \Delta\varepsilon_x, \Delta\varepsilon_y$, the error
/// order of [`tt_kinematics::paper::table3`]; the table's garbled first column is read as in
/// NOTES item 6).
///
/// These are NOT the optimum of the stated problem (31)-(34): they use 91.4% of $I_\psi$ and
/// $I_\gamma$ and 96.3% of $I_\theta$ (see the crate documentation, "Table 4").
///
/// # Reference
/// Zhao et al. 2017, §4.3, Table 4 ("Accuracy requirements (arc minute)").
pub const TABLE4_ARCMIN: [f64; 8] = [
    0.4235, 0.7800, 0.4234, 0.7800, 0.2825, 0.2824, 0.4234, 0.4233,
];

/// [`TABLE4_ARCMIN`] in radians.
#[must_use]
pub fn table4_rad() -> Vec<f64> {
    TABLE4_ARCMIN.iter().map(|v| v * RAD_PER_ARCMIN).collect()
}

/// The paper's example (§4.3): the linear model of Table 3 (eq 26), $I = 0.027^\circ$ for all
/// three angles (eq 16 as printed), and $\mathrm{LB} = 0$ because the paper gives no lower
/// bounds (NOTES item 11; the NumPy Monte Carlo anchor also draws from zero).
///
/// # Errors
/// Never in practice (the inputs are constants); kept fallible for uniformity.
pub fn example_problem() -> Result<AllocationProblem, AllocError> {
    let model = LinearModel::new(&tt_paper::table3());
    let n = model.n_errors();
    AllocationProblem::new(
        model,
        Requirement::uniform_deg(REQUIREMENT_DEG)?,
        vec![0.0; n],
    )
}

/// The paper's claims about the allocation (§4.2-4.3, Lemma 1, Table 4, §5 conclusions 1-2),
/// each a function returning its evidence (the numbers a report prints, with `Display`) and
/// whether it holds. The claim tests of this crate (`tests/paper_claims.rs`) call them and
/// assert; the reproduction report calls the same functions and prints them.
pub mod claims {
    use crate::allocation::{Allocation, Certificate};
    use crate::error::AllocError;
    use crate::problem::{AllocationProblem, Weights};
    use std::fmt;

    /// The three angles' shares of a turntable's allocation.
    fn three(s: &[Option<f64>]) -> [Option<f64>; 3] {
        [0, 1, 2].map(|k| s.get(k).copied().flatten())
    }

    /// Half a unit of Table 4's last printed digit (arcmin): two bounds that agree to the
    /// printing agree within this.
    pub(crate) const TABLE4_PRINT_HALF_UNIT_ARCMIN: f64 = 5e-5;

    /// The shares of the requirement a certificate uses, as `91.4% / 96.3% / 91.4%` (`-`
    /// where an angle has no requirement).
    fn shares(s: &[Option<f64>; 3]) -> String {
        s.iter()
            .map(|v| v.map_or("-".into(), |v| format!("{:.1}%", 100.0 * v)))
            .collect::<Vec<_>>()
            .join(" / ")
    }

    fn arcmin2(objective_rad: f64) -> f64 {
        tt_core::units::objective_to_arcmin(objective_rad)
    }

    /// §4.3: Table 4 against the optimum of problems (31)-(34).
    #[derive(Debug, Clone, PartialEq)]
    pub struct Table4Evidence {
        /// Error names (order of $\chi$).
        pub names: Vec<String>,
        /// Table 4 as printed, arcmin.
        pub table4_arcmin: Vec<f64>,
        /// The optimum of (31)-(34), arcmin.
        pub optimum_arcmin: Vec<f64>,
        /// Shares of $I_\psi, I_\theta, I_\gamma$ Table 4 uses (its Lemma 1 certificate).
        pub table4_shares: [Option<f64>; 3],
        /// Shares the optimum uses.
        pub optimum_shares: [Option<f64>; 3],
        /// $J$ of Table 4 with the paper's weights, arcmin$^{-2}$.
        pub table4_objective_arcmin: f64,
        /// $J$ of the optimum, arcmin$^{-2}$.
        pub optimum_objective_arcmin: f64,
    }

    impl Table4Evidence {
        /// Holds when every printed bound equals the optimum to the printing
        /// ([`TABLE4_PRINT_HALF_UNIT_ARCMIN`]).
        #[must_use]
        pub fn holds(&self) -> bool {
            self.table4_arcmin
                .iter()
                .zip(&self.optimum_arcmin)
                .all(|(t, o)| (t - o).abs() <= TABLE4_PRINT_HALF_UNIT_ARCMIN)
        }

        /// The error whose printed bound differs most from the optimum, with both values
        /// (arcmin).
        #[must_use]
        pub fn largest_difference(&self) -> Option<(&str, f64, f64)> {
            self.names
                .iter()
                .zip(self.table4_arcmin.iter().zip(&self.optimum_arcmin))
                .max_by(|a, b| (a.1.0 - a.1.1).abs().total_cmp(&(b.1.0 - b.1.1).abs()))
                .map(|(n, (t, o))| (n.as_str(), *t, *o))
        }
    }

    impl fmt::Display for Table4Evidence {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            write!(
                f,
                "the optimum has J = {:.3} arcmin⁻² and uses {} of I; Table 4 has J = {:.3} and uses {}",
                self.optimum_objective_arcmin,
                shares(&self.optimum_shares),
                self.table4_objective_arcmin,
                shares(&self.table4_shares)
            )?;
            if let Some((n, t, o)) = self.largest_difference() {
                write!(
                    f,
                    "; largest difference {n}: {o:.4} arcmin (optimum) vs {t:.4} (Table 4)"
                )?;
            }
            Ok(())
        }
    }

    /// Evaluate "Table 4 is the solution of problems (31)-(34)" for `problem` (the paper's:
    /// eq 26, the requirement of eq 16) and its optimum `optimum` (the sensitivity-weighted
    /// allocation).
    ///
    /// # Errors
    /// As [`Certificate::compute`] (a turntable that is not the paper's: wrong length).
    pub fn table4_is_the_optimum_of_problems_31_to_34(
        problem: &AllocationProblem,
        optimum: &Allocation,
    ) -> Result<Table4Evidence, AllocError> {
        let table4 = super::table4_rad();
        let cert = Certificate::compute(
            problem.model(),
            problem.limits(),
            problem.lower_bounds_rad(),
            &table4,
        )?;
        let weights = Weights::inverse_average_sensitivity(problem.model());
        Ok(Table4Evidence {
            names: problem.error_names(),
            table4_arcmin: super::TABLE4_ARCMIN.to_vec(),
            optimum_arcmin: optimum.upper_bounds_arcmin(),
            table4_shares: [0, 1, 2].map(|k| cert.axes[k].share),
            optimum_shares: three(&optimum.shares()),
            table4_objective_arcmin: arcmin2(weights.objective(&table4)),
            optimum_objective_arcmin: optimum.objective_arcmin(),
        })
    }

    /// Lemma 1 (§4.2): for every pose and every $\chi$ with $\mathrm{LB}_i \le |\chi_i| \le
    /// \mathrm{UB}_i$, $|f_k| \le I_k$ (first-order model), for each named box of bounds.
    #[derive(Debug, Clone, PartialEq)]
    pub struct Lemma1Evidence {
        /// Per box: its name, the shares of $I_\psi, I_\theta, I_\gamma$ its worst case uses,
        /// and whether the certificate holds.
        pub boxes: Vec<(String, [Option<f64>; 3], bool)>,
    }

    impl Lemma1Evidence {
        /// Holds when every box's certificate holds.
        #[must_use]
        pub fn holds(&self) -> bool {
            self.boxes.iter().all(|b| b.2)
        }
    }

    impl fmt::Display for Lemma1Evidence {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            let parts: Vec<String> = self
                .boxes
                .iter()
                .map(|(n, s, ok)| {
                    format!(
                        "{n}: worst cases use {} of I ({})",
                        shares(s),
                        if *ok { "within" } else { "EXCEEDS" }
                    )
                })
                .collect();
            f.write_str(&parts.join("; "))
        }
    }

    /// Evaluate Lemma 1 for named boxes of upper bounds (rad) on `problem`'s model,
    /// requirement and lower bounds (the worst case over every pose, exact for one free
    /// joint; a rigorous bound otherwise).
    ///
    /// # Errors
    /// As [`Certificate::compute`].
    pub fn lemma1_every_pose_and_admissible_error_meets_the_requirement(
        problem: &AllocationProblem,
        boxes: &[(&str, &[f64])],
    ) -> Result<Lemma1Evidence, AllocError> {
        let boxes = boxes
            .iter()
            .map(|(name, ub)| {
                let c = Certificate::compute(
                    problem.model(),
                    problem.limits(),
                    problem.lower_bounds_rad(),
                    ub,
                )?;
                Ok((
                    (*name).to_string(),
                    [0, 1, 2].map(|k| c.axes[k].share),
                    c.lemma1_holds(),
                ))
            })
            .collect::<Result<Vec<_>, AllocError>>()?;
        Ok(Lemma1Evidence { boxes })
    }

    /// Conclusion 1 (§4.3, §5): the inner axis's wobble errors get the tightest bounds.
    #[derive(Debug, Clone, PartialEq)]
    pub struct Conclusion1Evidence {
        /// The two errors with the smallest finite bounds, in increasing order of bound.
        pub tightest: Vec<(String, f64)>,
        /// The next bound (arcmin), for the gap.
        pub next: Option<(String, f64)>,
        /// The errors the paper names (`dalpha_x2`, `dalpha_y2`).
        pub expected: Vec<String>,
    }

    impl Conclusion1Evidence {
        /// Holds when the two tightest bounds are exactly the expected errors.
        #[must_use]
        pub fn holds(&self) -> bool {
            let mut got: Vec<&str> = self.tightest.iter().map(|(n, _)| n.as_str()).collect();
            let mut want: Vec<&str> = self.expected.iter().map(String::as_str).collect();
            got.sort_unstable();
            want.sort_unstable();
            got == want
        }
    }

    impl fmt::Display for Conclusion1Evidence {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            let t: Vec<String> = self
                .tightest
                .iter()
                .map(|(n, v)| format!("{n} {v:.4}"))
                .collect();
            write!(f, "tightest bounds (arcmin): {}", t.join(", "))?;
            if let Some((n, v)) = &self.next {
                write!(f, "; next {n} {v:.4}")?;
            }
            Ok(())
        }
    }

    /// Evaluate conclusion 1 on an allocation of the paper's table.
    #[must_use]
    pub fn conclusion1_inner_axis_wobbles_get_the_tightest_bounds(
        a: &Allocation,
    ) -> Conclusion1Evidence {
        let ub = a.upper_bounds_arcmin();
        let mut order: Vec<usize> = (0..ub.len()).filter(|&i| ub[i].is_finite()).collect();
        order.sort_by(|x, y| ub[*x].total_cmp(&ub[*y]));
        let named = |i: usize| (a.error_names[i].clone(), ub[i]);
        Conclusion1Evidence {
            tightest: order.iter().take(2).map(|&i| named(i)).collect(),
            next: order.get(2).map(|&i| named(i)),
            expected: vec!["dalpha_x2".into(), "dalpha_y2".into()],
        }
    }

    /// Conclusion 2 (§5): at the same guarantee, the proposed allocation costs less than the
    /// equal-effects method (refs 20-21).
    #[derive(Debug, Clone, PartialEq)]
    pub struct Conclusion2Evidence {
        /// $J$ of the proposed (sensitivity-weighted) allocation, arcmin$^{-2}$.
        pub proposed_objective_arcmin: f64,
        /// $J$ of the equal-effects allocation, arcmin$^{-2}$.
        pub equal_effects_objective_arcmin: f64,
        /// Shares of the requirement used by each (proposed, equal effects).
        pub shares: [[Option<f64>; 3]; 2],
        /// Lemma 1 holds for each (proposed, equal effects).
        pub lemma1: [bool; 2],
    }

    impl Conclusion2Evidence {
        /// Holds when both meet Lemma 1 and the proposed $J$ is lower.
        #[must_use]
        pub fn holds(&self) -> bool {
            self.lemma1.iter().all(|b| *b)
                && self.proposed_objective_arcmin < self.equal_effects_objective_arcmin
        }
    }

    impl fmt::Display for Conclusion2Evidence {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            write!(
                f,
                "J = {:.3} (proposed, uses {} of I) vs {:.3} arcmin⁻² (equal effects, uses {})",
                self.proposed_objective_arcmin,
                shares(&self.shares[0]),
                self.equal_effects_objective_arcmin,
                shares(&self.shares[1])
            )
        }
    }

    /// Evaluate conclusion 2 from the two allocations of the same problem.
    #[must_use]
    pub fn conclusion2_proposed_allocation_beats_equal_effects(
        proposed: &Allocation,
        equal_effects: &Allocation,
    ) -> Conclusion2Evidence {
        Conclusion2Evidence {
            proposed_objective_arcmin: proposed.objective_arcmin(),
            equal_effects_objective_arcmin: equal_effects.objective_arcmin(),
            shares: [three(&proposed.shares()), three(&equal_effects.shares())],
            lemma1: [
                proposed.certificate.lemma1_holds(),
                equal_effects.certificate.lemma1_holds(),
            ],
        }
    }
}
