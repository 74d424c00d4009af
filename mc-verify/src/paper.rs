//! The paper's Monte Carlo claim (§4.3, Figure 9) as library code.

/// The paper's claims about the Monte Carlo verification, each a function returning its
/// evidence (the numbers a report prints, with `Display`) and whether it holds. The claim
/// test (`tests/paper_claims.rs`) calls it and asserts; the reproduction report calls the
/// same function and prints it.
pub mod claims {
    use crate::error::McError;
    use crate::run::{McResult, MonteCarlo};
    use std::fmt;
    use tt_core::units::RAD_PER_ARCMIN;
    use tt_kinematics::{LinearModel, OrientationAxis};

    /// One angle of the Figure 9 claim.
    #[derive(Debug, Clone, PartialEq)]
    pub struct Figure9Axis {
        /// The angle.
        pub axis: OrientationAxis,
        /// The requirement $I_k$ (rad), if the angle has one.
        pub requirement_rad: Option<f64>,
        /// The largest $|\Delta|$ of the random turntables (exact chain), rad.
        pub max_abs_rad: f64,
        /// The worst case of the first-order model over the box and every pose (Lemma 1's
        /// quantity, certified: exact for one free joint), rad.
        pub linear_worst_rad: f64,
        /// A rigorous bound on $|\Delta|$ of the exact chain over the box: the certified
        /// first-order bound plus the remainder $e^S - 1 - S$ ([`MonteCarlo::half_range_rad`]),
        /// rad.
        pub rigorous_bound_rad: f64,
    }

    impl Figure9Axis {
        /// The drawn maximum as a fraction of the first-order worst case.
        #[must_use]
        pub fn reached(&self) -> f64 {
            self.max_abs_rad / self.linear_worst_rad
        }

        /// Holds for this angle: no draw beyond the rigorous bound, and the bound within the
        /// requirement (so every turntable of the box meets it, drawn or not).
        #[must_use]
        pub(crate) fn holds(&self) -> bool {
            self.max_abs_rad <= self.rigorous_bound_rad
                && self
                    .requirement_rad
                    .is_none_or(|i| self.rigorous_bound_rad <= i)
        }
    }

    /// §4.3, Figure 9: every random turntable of the allocation meets the requirement; judged
    /// against the certificate's worst case, not by counting samples inside (an allocation
    /// that uses 96% of $I$ keeps every sample inside whatever the draws).
    #[derive(Debug, Clone, PartialEq)]
    pub struct Figure9Evidence {
        /// Random turntables drawn.
        pub samples: u64,
        /// Draws with all three angles inside the requirement.
        pub inside: u64,
        /// Per angle, $\psi, \theta, \gamma$.
        pub axes: [Figure9Axis; 3],
    }

    impl Figure9Evidence {
        /// Holds when every angle holds ([`Figure9Axis::holds`]).
        #[must_use]
        pub fn holds(&self) -> bool {
            self.axes.iter().all(Figure9Axis::holds)
        }
    }

    impl fmt::Display for Figure9Evidence {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            let sym = ["Δψ", "Δθ", "Δγ"];
            let parts: Vec<String> = self
                .axes
                .iter()
                .map(|a| {
                    let am = |v: f64| v / RAD_PER_ARCMIN;
                    let share = a.requirement_rad.map_or(String::new(), |i| format!(", {:.1}% of I", 100.0 * a.rigorous_bound_rad / i));
                    format!(
                        "|{}| ≤ {:.4} arcmin proven ({:.4} first order{share}), drawn max {:.4} ({:.1}% of the worst case)",
                        sym[a.axis.index()],
                        am(a.rigorous_bound_rad),
                        am(a.linear_worst_rad),
                        am(a.max_abs_rad),
                        100.0 * a.reached()
                    )
                })
                .collect();
            write!(
                f,
                "{}; {} of {} draws inside",
                parts.join("; "),
                self.inside,
                self.samples
            )
        }
    }

    /// Evaluate the Figure 9 claim for a run `result` of `mc` (the paper: Table 4's box, the
    /// requirement of eq 16).
    ///
    /// # Errors
    /// [`McError::Kinematics`] from the worst-case search (never for a valid run).
    pub fn figure9_every_turntable_of_the_box_meets_the_requirement(
        mc: &MonteCarlo,
        result: &McResult,
    ) -> Result<Figure9Evidence, McError> {
        let model = LinearModel::new(mc.turntable().ok_or(McError::NotThePaperTable)?);
        let bound = mc.half_range_rad();
        let mut axes = Vec::with_capacity(3);
        for axis in OrientationAxis::ALL {
            let w = model.worst_pose_certified(axis, mc.bounds().ub_rad(), true, None)?;
            axes.push(Figure9Axis {
                axis,
                requirement_rad: result.requirement.get(axis),
                max_abs_rad: result.axis(axis).max_abs_rad,
                linear_worst_rad: w.value(),
                rigorous_bound_rad: bound[axis.index()],
            });
        }
        let [a, b, c]: [Figure9Axis; 3] = axes
            .try_into()
            .unwrap_or_else(|_| unreachable!("three angles"));
        Ok(Figure9Evidence {
            samples: result.count.samples(),
            inside: result.count.meeting(),
            axes: [a, b, c],
        })
    }
}
