//! The paper's claims in one place: the end-to-end claim (the paper's implicit promise that a
//! turntable within Table 4 calibrates the GyroWheel to $\omega_m$), and the registry of every
//! claim of the paper with its section, statement, the library function that evaluates it,
//! the test that proves it, and its evaluation on a run ([`registry::evaluate`]).
//!
//! A claim whose verdict depends on the reading of eq 13 (NOTES item 3) is evaluated under
//! both: [`Reading::PAPER`] (outputs simulated at the intended orientation: reproduces §2)
//! and [`Reading::USER`] (outputs at the actual orientation: what a calibrating lab gets).

use crate::answer::{BoxAnswer, BuyersAnswer, EndToEndInputs, answer_with_two_step};
use crate::error::E2eError;
use crate::simulate::EndToEnd;
use alloc_opt::{Allocation, AllocationProblem, Allocator, EqualEffects, SensitivityWeighted};
use calib_lsq::{Calibration, Reading, RequirementProblem};
use mc_verify::{ErrorBox, McConfig, McResult, MonteCarlo};
use tt_core::DeltaRKind;
use tt_kinematics::{Pose, Turntable};

/// The name of the paper's Table 4 box in an end-to-end answer (an extra box of
/// [`EndToEndInputs::extra_boxes`]).
pub const TABLE4_BOX: &str = "Table 4";

/// The paper's end-to-end claim.
pub mod claims {
    use super::*;
    use std::fmt;

    /// One output under one reading.
    #[derive(Debug, Clone, PartialEq)]
    pub struct OutputOutcome {
        /// The output's name.
        pub name: String,
        /// Its unit label.
        pub unit: String,
        /// Its accuracy $\omega_m$ (output unit).
        pub accuracy: f64,
        /// The worst turntable of the box: $\Delta\omega$ at the linearised worst vertex,
        /// evaluated on the exact chain (output unit).
        pub worst_case: f64,
    }

    /// The box under one reading of eq 13.
    #[derive(Debug, Clone, PartialEq)]
    pub struct ReadingOutcome {
        /// The reading.
        pub reading: Reading,
        /// Per output.
        pub outputs: Vec<OutputOutcome>,
        /// Fraction of random turntables of the box meeting every accuracy.
        pub yield_fraction: f64,
        /// Its 95% Wilson interval.
        pub yield_interval_95: (f64, f64),
        /// Random turntables drawn.
        pub samples: u64,
    }

    impl ReadingOutcome {
        /// The worst turntable meets every output's accuracy.
        #[must_use]
        pub fn meets(&self) -> bool {
            self.outputs.iter().all(|o| o.worst_case <= o.accuracy)
        }
    }

    impl fmt::Display for ReadingOutcome {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            let worst: Vec<String> = self
                .outputs
                .iter()
                .map(|o| {
                    format!(
                        "Δω_{} {:.5} {} (ω_m {})",
                        o.name,
                        o.worst_case,
                        o.unit.replace("_per_", "/"),
                        o.accuracy
                    )
                })
                .collect();
            let (lo, hi) = self.yield_interval_95;
            write!(
                f,
                "worst turntable {}; {:.2}% of {} random turntables meet it [95%: {:.2}%, {:.2}%]",
                worst.join(", "),
                100.0 * self.yield_fraction,
                self.samples,
                100.0 * lo,
                100.0 * hi
            )
        }
    }

    /// The end-to-end claim: a turntable within a box (Table 4) calibrates the sensor to
    /// every output's accuracy, under each reading of eq 13.
    #[derive(Debug, Clone, PartialEq)]
    pub struct EndToEndEvidence {
        /// The box's name.
        pub box_name: String,
        /// One outcome per reading ([`Reading::PAPER`], then [`Reading::USER`]).
        pub readings: Vec<ReadingOutcome>,
    }

    impl EndToEndEvidence {
        /// The outcome under `reading`, if evaluated.
        #[must_use]
        pub fn under(&self, reading: Reading) -> Option<&ReadingOutcome> {
            self.readings.iter().find(|r| r.reading == reading)
        }

        /// The verdict under `reading` (`None`: not evaluated).
        #[must_use]
        pub fn holds_under(&self, reading: Reading) -> Option<bool> {
            self.under(reading).map(ReadingOutcome::meets)
        }
    }

    /// Evaluate "a turntable within Table 4 calibrates the GyroWheel to $\omega_m$" from an
    /// end-to-end answer holding the box [`TABLE4_BOX`] under [`Reading::PAPER`] and
    /// [`Reading::USER`] (the answer of a simulator with the paper's reading).
    ///
    /// # Errors
    /// [`E2eError::MissingInAnswer`] naming the box or reading that is absent.
    pub fn table4_calibrates_the_sensor_to_its_accuracy(
        e2e: &EndToEnd,
        answer: &BuyersAnswer,
    ) -> Result<EndToEndEvidence, E2eError> {
        let outputs = e2e.calibration().outputs();
        let readings = [Reading::PAPER, Reading::USER]
            .into_iter()
            .map(|reading| {
                let r = answer
                    .readings
                    .iter()
                    .find(|r| r.reading == reading)
                    .ok_or_else(|| E2eError::MissingInAnswer {
                        what: format!("reading {reading}"),
                    })?;
                let b: &BoxAnswer =
                    r.boxes
                        .iter()
                        .find(|b| b.name == TABLE4_BOX)
                        .ok_or_else(|| E2eError::MissingInAnswer {
                            what: format!("box \"{TABLE4_BOX}\" under reading {reading}"),
                        })?;
                Ok(ReadingOutcome {
                    reading,
                    outputs: b
                        .worst_case
                        .outputs
                        .iter()
                        .map(|w| {
                            let o = outputs[w.output].output();
                            OutputOutcome {
                                name: o.name.clone(),
                                unit: o.unit.clone(),
                                accuracy: o.accuracy,
                                worst_case: w.exact_at_vertex,
                            }
                        })
                        .collect(),
                    yield_fraction: b.distribution.count.fraction(),
                    yield_interval_95: b.distribution.count.interval_95(),
                    samples: b.distribution.count.samples(),
                })
            })
            .collect::<Result<Vec<_>, E2eError>>()?;
        Ok(EndToEndEvidence {
            box_name: TABLE4_BOX.to_string(),
            readings,
        })
    }
}

/// Every claim of the paper: what it says, where, the function that evaluates it, the test
/// that proves it, and its evaluation on a run.
pub mod registry {
    use super::*;
    use std::fmt;

    /// A test of the workspace: `cargo test -p KRATE --test FILE_STEM NAME`.
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    pub struct TestRef {
        /// The package (`calib-lsq`).
        pub krate: &'static str,
        /// The test file, relative to the package (`tests/paper_claims.rs`).
        pub file: &'static str,
        /// The test function's name.
        pub name: &'static str,
    }

    impl TestRef {
        /// The command that runs it.
        #[must_use]
        pub fn command(&self) -> String {
            let stem = self
                .file
                .trim_start_matches("tests/")
                .trim_end_matches(".rs");
            format!("cargo test -p {} --test {stem} {}", self.krate, self.name)
        }
    }

    impl fmt::Display for TestRef {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            write!(f, "{}::{}", self.krate, self.name)
        }
    }

    /// One claim of the paper.
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    pub struct ClaimInfo {
        /// Short identifier (`eq16`).
        pub id: &'static str,
        /// Section, equation or figure of the paper.
        pub section: &'static str,
        /// The claim, in the paper's terms.
        pub statement: &'static str,
        /// The library function that evaluates it (path).
        pub function: &'static str,
        /// The test that proves it (it calls [`ClaimInfo::function`]).
        pub test: TestRef,
        /// Whether the verdict can depend on the reading of eq 13 (evaluated under both).
        pub reading_dependent: bool,
    }

    const fn claim(
        id: &'static str,
        section: &'static str,
        statement: &'static str,
        function: &'static str,
        krate: &'static str,
        name: &'static str,
        reading_dependent: bool,
    ) -> ClaimInfo {
        ClaimInfo {
            id,
            section,
            statement,
            function,
            test: TestRef {
                krate,
                file: "tests/paper_claims.rs",
                name,
            },
            reading_dependent,
        }
    }

    /// The paper's claims, in the order of the paper.
    pub const CLAIMS: [ClaimInfo; 13] = [
        claim(
            "fig4-1",
            "§2.2 (1), Figure 4",
            "Δω_x is caused by Δψ and Δθ and not affected by Δγ; Δω_y by Δθ and Δγ, not by Δψ",
            "calib_lsq::paper::claims::claim1_each_output_ignores_one_angle",
            "calib-lsq",
            "claim1_s2_2_fig4_each_output_ignores_one_angle_under_both_readings",
            true,
        ),
        claim(
            "fig4-2",
            "§2.2 (2), Figure 4",
            "Γ_1 is symmetric about Δψ = 0 and Δθ = 0, Γ_2 about Δθ = 0 and Δγ = 0",
            "calib_lsq::paper::claims::claims2_3_surface_shape",
            "calib-lsq",
            "claim2_s2_2_fig4_rate_errors_are_even_under_both_readings",
            true,
        ),
        claim(
            "fig4-3",
            "§2.2 (3), Figure 4",
            "Δω_x rises with |Δψ| and |Δθ|; Δω_y with |Δθ| and |Δγ|",
            "calib_lsq::paper::claims::claims2_3_surface_shape",
            "calib-lsq",
            "claim3_s2_2_fig4_rate_errors_rise_with_angle_magnitude_only_under_the_paper_reading",
            true,
        ),
        claim(
            "eq16",
            "§2.3, eq 16",
            "the orientation requirement is |Δψ|, |Δθ|, |Δγ| ≤ 0.027 deg",
            "calib_lsq::paper::claims::eq16_requirement",
            "calib-lsq",
            "eq16_claim_s2_3_requirement_rounds_to_0_027_deg_only_under_the_paper_reading",
            true,
        ),
        claim(
            "eq25",
            "§3.2, under eq 25",
            "the intersection error has no effect on the orientation error",
            "tt_kinematics::paper::claims::eq25_intersection_error_has_no_effect",
            "tt-kinematics",
            "eq25_claim_s3_2_intersection_error_has_no_effect_on_the_orientation_error",
            false,
        ),
        claim(
            "eq26",
            "§3.2, eq 26",
            "the small-angle model (26) approximates the exact orientation error (25)",
            "tt_kinematics::paper::claims::eq26_approximates_the_exact_chain",
            "tt-kinematics",
            "eq26_claim_s3_2_closed_form_approximates_the_exact_chain_to_second_order",
            false,
        ),
        claim(
            "fig8",
            "§4.1, §4.3, Figure 8",
            "only Δθ is sensitive to Δφ_z2 and Δα_z1, and Δθ only to them",
            "tt_kinematics::paper::claims::fig8_theta_depends_only_on_dphi_z2_and_dalpha_z1",
            "tt-kinematics",
            "fig8_claim_s4_1_delta_theta_depends_only_on_dphi_z2_and_dalpha_z1",
            false,
        ),
        claim(
            "lemma1",
            "§4.2, Lemma 1",
            "for every pose and every χ with LB_i ≤ |χ_i| ≤ UB_i: |f_ψ| ≤ I_ψ, |f_θ| ≤ I_θ, |f_γ| ≤ I_γ (model 26)",
            "alloc_opt::paper::claims::lemma1_every_pose_and_admissible_error_meets_the_requirement",
            "alloc-opt",
            "lemma1_claim_s4_2_every_pose_and_admissible_error_meets_the_requirement",
            false,
        ),
        claim(
            "table4",
            "§4.3, Table 4",
            "Table 4 is the solution of problems (31)-(34) for the requirement of eq 16",
            "alloc_opt::paper::claims::table4_is_the_optimum_of_problems_31_to_34",
            "alloc-opt",
            "table4_claim_s4_3_table4_is_not_the_optimum_of_problems_31_to_34",
            false,
        ),
        claim(
            "conclusion1",
            "§4.3, §5 (1)",
            "the wobble error of the inner axis contributes most: Δα_x2 and Δα_y2 get the tightest bounds",
            "alloc_opt::paper::claims::conclusion1_inner_axis_wobbles_get_the_tightest_bounds",
            "alloc-opt",
            "conclusion1_claim_s5_inner_axis_wobbles_get_the_tightest_bounds",
            false,
        ),
        claim(
            "conclusion2",
            "§5 (2)",
            "at the same guarantee the proposed allocation costs less than the equal-effects method",
            "alloc_opt::paper::claims::conclusion2_proposed_allocation_beats_equal_effects",
            "alloc-opt",
            "conclusion2_claim_s5_proposed_allocation_beats_equal_effects",
            false,
        ),
        claim(
            "fig9",
            "§4.3, Figure 9",
            "every random turntable within Table 4 meets the orientation requirement of eq 16",
            "mc_verify::paper::claims::figure9_every_turntable_of_the_box_meets_the_requirement",
            "mc-verify",
            "figure9_claim_s4_3_every_table4_turntable_meets_eq16_by_the_certified_worst_case",
            false,
        ),
        claim(
            "e2e",
            "§2-§4 (implicit)",
            "a turntable within the Table 4 tolerances calibrates the GyroWheel to ω_m = 0.01 deg/h",
            "e2e_verify::paper::claims::table4_calibrates_the_sensor_to_its_accuracy",
            "e2e-verify",
            "e2e_claim_table4_calibrates_to_omega_m_under_the_paper_reading_but_not_the_users",
            true,
        ),
    ];

    /// A verdict with the evidence behind it.
    #[derive(Debug, Clone, PartialEq, Eq)]
    pub struct Outcome {
        /// Whether the claim holds.
        pub holds: bool,
        /// The numbers behind it, for people.
        pub evidence: String,
    }

    impl Outcome {
        fn new(holds: bool, evidence: impl fmt::Display) -> Self {
            Self {
                holds,
                evidence: evidence.to_string(),
            }
        }
    }

    /// One claim evaluated on a run.
    #[derive(Debug, Clone, PartialEq, Eq)]
    pub struct ClaimEvaluation {
        /// The claim.
        pub info: &'static ClaimInfo,
        /// Under [`Reading::PAPER`] (for a claim that does not involve eq 13: its only
        /// verdict).
        pub paper: Outcome,
        /// Under [`Reading::USER`], for a reading-dependent claim.
        pub user: Option<Outcome>,
    }

    impl ClaimEvaluation {
        /// Holds under every reading it was evaluated under.
        #[must_use]
        pub(crate) fn holds_everywhere(&self) -> bool {
            self.paper.holds && self.user.as_ref().is_none_or(|u| u.holds)
        }

        /// The verdict differs between the readings.
        #[must_use]
        pub(crate) fn verdict_depends_on_reading(&self) -> bool {
            self.user
                .as_ref()
                .is_some_and(|u| u.holds != self.paper.holds)
        }
    }

    /// What the claims are evaluated on: one run of the paper's study (borrowed, so a report
    /// that prints these results does not compute them twice).
    #[derive(Debug, Clone, Copy)]
    pub struct PaperRun<'a> {
        /// The requirement problem of the study (sensor, site, schedule; its reading is
        /// replaced by [`Reading::PAPER`] and [`Reading::USER`]).
        pub requirement: &'a RequirementProblem,
        /// The turntable (Table 3).
        pub turntable: &'a Turntable,
        /// The allocation problem (the first-order model, eq 16, the lower bounds).
        pub allocation_problem: &'a AllocationProblem,
        /// The proposed (sensitivity-weighted) allocation of that problem.
        pub proposed: &'a Allocation,
        /// The equal-effects allocation of that problem.
        pub equal_effects: &'a Allocation,
        /// The Monte Carlo of Table 4's box with the requirement of eq 16, and its result.
        pub table4_monte_carlo: (&'a MonteCarlo, &'a McResult),
        /// The end-to-end simulator (the study's reading) and its answer, holding the box
        /// [`TABLE4_BOX`] under [`Reading::PAPER`] and [`Reading::USER`].
        pub end_to_end: (&'a EndToEnd, &'a BuyersAnswer),
    }

    /// Evaluate every claim of [`CLAIMS`] on `run`, in order.
    ///
    /// # Errors
    /// The first error of a claim function (a run that is not the paper's shape: wrong
    /// number of outputs, errors, or a missing box).
    pub fn evaluate(run: &PaperRun<'_>) -> Result<Vec<ClaimEvaluation>, E2eError> {
        use calib_lsq::paper::claims as cal;
        let under = |reading: Reading| RequirementProblem {
            reading,
            ..run.requirement.clone()
        };
        let (paper_p, user_p) = (under(Reading::PAPER), under(Reading::USER));
        let mut out = Vec::with_capacity(CLAIMS.len());
        let mut push = |i: usize, paper: Outcome, user: Option<Outcome>| {
            debug_assert_eq!(CLAIMS[i].reading_dependent, user.is_some());
            out.push(ClaimEvaluation {
                info: &CLAIMS[i],
                paper,
                user,
            });
        };
        let c1 = |p| cal::claim1_each_output_ignores_one_angle(p, &cal::PAPER_IGNORED_ANGLES);
        let (a, b) = (c1(&paper_p)?, c1(&user_p)?);
        push(
            0,
            Outcome::new(a.holds(), &a),
            Some(Outcome::new(b.holds(), &b)),
        );
        let shape = |p| cal::claims2_3_surface_shape(p, &cal::PAPER_PLANES);
        let (a, b) = (shape(&paper_p)?, shape(&user_p)?);
        let asym = |e: &cal::ShapeEvidence| format!("largest asymmetry {:.1e}", e.max_asymmetry);
        push(
            1,
            Outcome::new(a.even(), asym(&a)),
            Some(Outcome::new(b.even(), asym(&b))),
        );
        let growth = |e: &cal::ShapeEvidence| {
            format!(
                "{} of {} growth checks fail",
                e.growth_failures, e.growth_checks
            )
        };
        push(
            2,
            Outcome::new(a.rising(), growth(&a)),
            Some(Outcome::new(b.rising(), growth(&b))),
        );
        let eq16 = |p| cal::eq16_requirement(p, cal::EQ16_PRINTED_DEG, cal::EQ16_PRINTED_DECIMALS);
        let (a, b) = (eq16(&paper_p)?, eq16(&user_p)?);
        push(
            3,
            Outcome::new(a.holds(), &a),
            Some(Outcome::new(b.holds(), &b)),
        );

        use tt_kinematics::paper::claims as tt;
        let e = tt::eq25_intersection_error_has_no_effect(run.turntable)?;
        push(4, Outcome::new(e.holds(), &e), None);
        let e = tt::eq26_approximates_the_exact_chain(run.turntable)?;
        push(5, Outcome::new(e.holds(), &e), None);
        let e = tt::fig8_theta_depends_only_on_dphi_z2_and_dalpha_z1(run.turntable);
        push(6, Outcome::new(e.holds(), &e), None);

        use alloc_opt::paper::claims as al;
        let table4 = alloc_opt::paper::table4_rad();
        let e = al::lemma1_every_pose_and_admissible_error_meets_the_requirement(
            run.allocation_problem,
            &[
                ("optimum", run.proposed.upper_bounds_rad()),
                (TABLE4_BOX, &table4),
            ],
        )?;
        push(7, Outcome::new(e.holds(), &e), None);
        let e =
            al::table4_is_the_optimum_of_problems_31_to_34(run.allocation_problem, run.proposed)?;
        push(8, Outcome::new(e.holds(), &e), None);
        let e = al::conclusion1_inner_axis_wobbles_get_the_tightest_bounds(run.proposed);
        push(9, Outcome::new(e.holds(), &e), None);
        let e = al::conclusion2_proposed_allocation_beats_equal_effects(
            run.proposed,
            run.equal_effects,
        );
        push(10, Outcome::new(e.holds(), &e), None);

        let (mc, r) = run.table4_monte_carlo;
        let e = mc_verify::paper::claims::figure9_every_turntable_of_the_box_meets_the_requirement(
            mc, r,
        )?;
        push(11, Outcome::new(e.holds(), &e), None);

        let (e2e, answer) = run.end_to_end;
        let e = claims::table4_calibrates_the_sensor_to_its_accuracy(e2e, answer)?;
        let outcome = |reading| -> Result<Outcome, E2eError> {
            let r = e.under(reading).ok_or_else(|| E2eError::MissingInAnswer {
                what: format!("reading {reading}"),
            })?;
            Ok(Outcome::new(r.meets(), r))
        };
        push(12, outcome(Reading::PAPER)?, Some(outcome(Reading::USER)?));
        Ok(out)
    }

    /// The first sentence of [`summary`]: how many claims hold under both readings.
    #[must_use]
    pub fn count_line(evaluations: &[ClaimEvaluation]) -> String {
        let both = evaluations.iter().filter(|c| c.holds_everywhere()).count();
        format!(
            "{both} of {} claims hold under both readings of eq 13.",
            evaluations.len()
        )
    }

    /// For each claim that does not hold under some reading: `id (section): why`, with the
    /// evidence of the failing verdict.
    #[must_use]
    pub fn failing(evaluations: &[ClaimEvaluation]) -> Vec<String> {
        evaluations
            .iter()
            .filter(|c| !c.holds_everywhere())
            .map(|c| {
                let why = if c.verdict_depends_on_reading() {
                    let (good, bad) = if c.paper.holds {
                        ("the paper's", "the user's")
                    } else {
                        ("the user's", "the paper's")
                    };
                    let failing = if c.paper.holds {
                        c.user.as_ref().map_or("", |u| u.evidence.as_str())
                    } else {
                        c.paper.evidence.as_str()
                    };
                    format!("holds under {good} reading, not under {bad} ({failing})")
                } else if c.user.is_some() {
                    format!("holds under neither reading ({})", c.paper.evidence)
                } else {
                    format!("does not hold ({})", c.paper.evidence)
                };
                format!("{} ({}): {why}", c.info.id, c.info.section)
            })
            .collect()
    }

    /// One line for people: how many claims hold, and for each that does not (under some
    /// reading), which and why.
    #[must_use]
    pub fn summary(evaluations: &[ClaimEvaluation]) -> String {
        let mut s = count_line(evaluations);
        for f in failing(evaluations) {
            s.push(' ');
            s.push_str(&f);
            s.push('.');
        }
        s
    }
}

/// Everything [`registry::evaluate`] needs, computed from the paper's inputs without a study
/// file (the library's own tests and examples; the reproduction report builds the same from
/// `studies/gyrowheel-2017.toml`): Table 1, Harbin, the 32-position schedule, the paper's
/// reading and small-angle $\Delta\mathbf R$, Table 3, eq 16 as printed, LB = 0.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct PaperComputation {
    /// See [`registry::PaperRun::requirement`].
    pub(crate) requirement: RequirementProblem,
    /// Table 3.
    pub(crate) turntable: Turntable,
    /// The paper's allocation problem ([`alloc_opt::paper::example_problem`]).
    pub(crate) allocation_problem: AllocationProblem,
    /// The proposed allocation (full-range form: the same optimum as the paper's quarter
    /// ranges for eq 26).
    pub(crate) proposed: Allocation,
    /// The equal-effects allocation.
    pub(crate) equal_effects: Allocation,
    /// The Monte Carlo of Table 4.
    pub(crate) monte_carlo: MonteCarlo,
    /// Its result.
    pub(crate) monte_carlo_result: McResult,
    /// The end-to-end simulator (paper's reading).
    pub(crate) end_to_end: EndToEnd,
    /// Its answer, with the box [`TABLE4_BOX`].
    pub(crate) answer: BuyersAnswer,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl PaperComputation {
    /// See [`registry::PaperRun::requirement`].
    #[must_use]
    pub fn requirement(&self) -> &RequirementProblem {
        &self.requirement
    }

    /// Table 3.
    #[must_use]
    pub fn turntable(&self) -> &Turntable {
        &self.turntable
    }

    /// The paper's allocation problem ([`alloc_opt::paper::example_problem`]).
    #[must_use]
    pub fn allocation_problem(&self) -> &AllocationProblem {
        &self.allocation_problem
    }

    /// The proposed allocation (full-range form: the same optimum as the paper's quarter
    /// ranges for eq 26).
    #[must_use]
    pub fn proposed(&self) -> &Allocation {
        &self.proposed
    }

    /// The equal-effects allocation.
    #[must_use]
    pub fn equal_effects(&self) -> &Allocation {
        &self.equal_effects
    }

    /// The Monte Carlo of Table 4.
    #[must_use]
    pub fn monte_carlo(&self) -> &MonteCarlo {
        &self.monte_carlo
    }

    /// Its result.
    #[must_use]
    pub fn monte_carlo_result(&self) -> &McResult {
        &self.monte_carlo_result
    }

    /// The end-to-end simulator (paper's reading).
    #[must_use]
    pub fn end_to_end(&self) -> &EndToEnd {
        &self.end_to_end
    }

    /// Its answer, with the box [`TABLE4_BOX`].
    #[must_use]
    pub fn answer(&self) -> &BuyersAnswer {
        &self.answer
    }
}

impl PaperComputation {
    /// Compute with `samples` random turntables per Monte Carlo and `seed`.
    ///
    /// # Errors
    /// As the libraries (never for the paper's constants and a valid count).
    pub fn compute(samples: u64, seed: u64) -> Result<Self, E2eError> {
        let calibration = Calibration::new(
            &gw_model::paper::gyrowheel(),
            &gw_model::paper::site(),
            &calib_lsq::paper::schedule(),
        )?;
        let requirement =
            RequirementProblem::new(calibration.clone(), Reading::PAPER, DeltaRKind::SmallAngle);
        let turntable = tt_kinematics::paper::table3();
        let allocation_problem = alloc_opt::paper::example_problem()?;
        let proposed = SensitivityWeighted::general().allocate(&allocation_problem)?;
        let equal_effects = EqualEffects.allocate(&allocation_problem)?;
        let req = allocation_problem.requirement();
        let n = turntable.n_rotation_errors();
        let bounds = ErrorBox::new(&turntable, vec![0.0; n], alloc_opt::paper::table4_rad())?;
        let monte_carlo = MonteCarlo::new(&turntable, bounds, McConfig::new(samples, seed, req))?;
        let monte_carlo_result = monte_carlo.run();
        let poses = calibration
            .schedule()
            .positions()
            .iter()
            .map(|p| Pose::from_deg(p.joint_angles_deg()))
            .collect::<Result<Vec<_>, _>>()?;
        let end_to_end = EndToEnd::new(&turntable, &calibration, &poses, Reading::PAPER)?;
        let mut inputs = EndToEndInputs::new(vec![0.0; n], Some(req), seed);
        inputs.samples = samples;
        inputs
            .extra_boxes
            .push((TABLE4_BOX.to_string(), alloc_opt::paper::table4_rad()));
        let answer = answer_with_two_step(&end_to_end, &inputs, Some(proposed.clone()))?;
        Ok(Self {
            requirement,
            turntable,
            allocation_problem,
            proposed,
            equal_effects,
            monte_carlo,
            monte_carlo_result,
            end_to_end,
            answer,
        })
    }

    /// The run to evaluate.
    #[must_use]
    pub fn run(&self) -> registry::PaperRun<'_> {
        registry::PaperRun {
            requirement: &self.requirement,
            turntable: &self.turntable,
            allocation_problem: &self.allocation_problem,
            proposed: &self.proposed,
            equal_effects: &self.equal_effects,
            table4_monte_carlo: (&self.monte_carlo, &self.monte_carlo_result),
            end_to_end: (&self.end_to_end, &self.answer),
        }
    }
}
