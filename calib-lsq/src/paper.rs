//! The paper's calibration inputs that the text leaves open, as this project's documented
//! choices: the 32-position schedule (NOTES item 10).

use crate::error::CalibError;
use crate::schedule::{Position, Schedule};

/// Outer-axis angles of the default schedule, degrees.
pub const DEFAULT_PHI_1_DEG: [f64; 4] = [0.0, 90.0, 180.0, 270.0];
/// Inner-axis angles of the default schedule, degrees.
pub const DEFAULT_PHI_2_DEG: [f64; 8] = [0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0];

/// The default schedule of the paper's two-axis table: the 32 positions
/// $\phi_1 \in \{0, 90, 180, 270\}°$ times $\phi_2 \in \{0, 45, \dots, 315\}°$, with
/// $\mathbf R_d = R_y(\phi_1)R_z(\phi_2)$.
///
/// The paper does not list its positions (it cites a schedule optimised in its reference
/// \[10\]; NOTES item 10). This grid is the usual choice for a two-axis multiposition test:
/// - gravity: $\phi_1 = 0, 180°$ put $z$ up and down; $\phi_1 = 90, 270°$ sweep $x$, $y$
///   around the horizontal in 45° steps, so $a_x^2$, $a_x a_y$ ($\pm 1/2$ at odd multiples
///   of 45°) and $a_z^2$ are separated: all seven coefficients of both axes are identifiable;
/// - earth rate: the set is symmetric under $\phi_2 \to -\phi_2$ and
///   $\phi_2 \to 180° - \phi_2$, which makes the rate-sensing errors even (claim 2 of §2.2).
#[must_use]
pub fn schedule() -> Schedule {
    grid(&DEFAULT_PHI_1_DEG, &DEFAULT_PHI_2_DEG)
        .unwrap_or_else(|_| unreachable!("non-empty constants"))
}

/// The product grid of the given outer and inner angles (degrees) on the paper's table.
///
/// # Errors
/// [`CalibError::Field`] (not finite) for a non-finite angle, [`CalibError::Field`] ([`tt_core::FieldError::Length`]) for an
/// empty grid.
pub fn grid(phi1_deg: &[f64], phi2_deg: &[f64]) -> Result<Schedule, CalibError> {
    let positions = phi1_deg
        .iter()
        .flat_map(|&p1| {
            phi2_deg.iter().map(move |&p2| {
                Position::new(
                    gw_model::paper::base_from_sensor(p1.to_radians(), p2.to_radians()),
                    vec![p1, p2],
                )
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    Schedule::new(positions)
}

/// The paper's claims about the calibration (§2.2-2.3), each a function of a requirement
/// problem (the study's sensor, site, schedule and reading) returning its evidence and
/// whether it holds. The claim tests call them and assert; the report prints them.
pub mod claims {
    use crate::error::CalibError;
    use crate::requirement::RequirementProblem;
    use std::fmt;
    use tt_core::OrientationAxis;

    /// The paper's outputs (0 = x, 1 = y) and the angle each is claimed not to depend on
    /// (claim 1: $\Delta\omega_x$ ignores $\Delta\gamma$, $\Delta\omega_y$ ignores $\Delta\psi$).
    pub const PAPER_IGNORED_ANGLES: [(usize, usize); 2] = [(0, 2), (1, 0)];

    /// The plane of each of the paper's outputs (claims 2-3: x over $\Delta\psi,
    /// \Delta\theta$; y over $\Delta\theta, \Delta\gamma$).
    pub const PAPER_PLANES: [(usize, [usize; 2]); 2] = [(0, [0, 1]), (1, [1, 2])];

    /// Eq 16 as printed: 0.027 deg ...
    pub const EQ16_PRINTED_DEG: f64 = 0.027;

    /// ... to three decimals.
    pub const EQ16_PRINTED_DECIMALS: i32 = 3;

    /// Rounding allowed where two rate errors are equal in exact arithmetic: a few ulps of
    /// outputs of ~100 deg/h (Table 1), in the output's unit.
    pub const RATE_EQ_TOL: f64 = 3e-12;

    /// A small magnitude for people: `0` when exactly zero, else `5.6e-14`.
    fn short(v: f64) -> String {
        if v == 0.0 {
            "0".into()
        } else {
            format!("{v:.1e}")
        }
    }

    /// The Greek letter of an angle name (`psi` → `ψ`), for evidence printed to people.
    fn greek(name: &str) -> &'static str {
        match name {
            "psi" => "ψ",
            "theta" => "θ",
            _ => "γ",
        }
    }

    /// Orientation errors probed by claims (1)-(3): a 7 x 7 grid up to 0.1 deg (Figure 4's
    /// scale), rad.
    fn grid() -> Vec<f64> {
        (-3..=3)
            .map(|k| f64::from(k) * (0.1f64 / 3.0).to_radians())
            .collect()
    }

    /// Claim (1): each output ignores one angle (the paper: $\Delta\omega_x$ is not affected by
    /// $\Delta\gamma$, $\Delta\omega_y$ not by $\Delta\psi$).
    #[derive(Debug, Clone, PartialEq)]
    pub struct Claim1Evidence {
        /// Per output: its name, the angle claimed not to matter, and the largest change of
        /// $\Delta\omega$ when that angle varies over the grid (output unit).
        pub outputs: Vec<(String, &'static str, f64)>,
    }

    impl Claim1Evidence {
        /// Holds when every change is rounding.
        #[must_use]
        pub fn holds(&self) -> bool {
            self.outputs.iter().all(|(_, _, c)| *c <= RATE_EQ_TOL)
        }
    }

    impl fmt::Display for Claim1Evidence {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            let parts: Vec<String> = self
                .outputs
                .iter()
                .map(|(o, a, c)| {
                    format!(
                        "Δω_{o} changes by at most {} when Δ{} varies",
                        short(*c),
                        greek(a)
                    )
                })
                .collect();
            f.write_str(&parts.join("; "))
        }
    }

    /// Claim (1) for the outputs and the angle each is claimed to ignore (`(output index,
    /// angle index)`; the paper: `[(0, 2), (1, 0)]`).
    ///
    /// # Errors
    /// As [`RequirementProblem::region`].
    pub fn claim1_each_output_ignores_one_angle(
        p: &RequirementProblem,
        ignored: &[(usize, usize)],
    ) -> Result<Claim1Evidence, CalibError> {
        let g = grid();
        let mut outputs = Vec::new();
        for &(k, j) in ignored {
            let r = p.region(k)?;
            let mut change: f64 = 0.0;
            for &u in &g {
                for &v in &g {
                    let others: Vec<usize> = (0..3).filter(|&i| i != j).collect();
                    let mut d = [0.0; 3];
                    d[others[0]] = u;
                    d[others[1]] = v;
                    let base = r.rate_error(d)?;
                    for &w in &g {
                        d[j] = w;
                        change = change.max((r.rate_error(d)? - base).abs());
                    }
                }
            }
            outputs.push((
                r.output().to_string(),
                OrientationAxis::ALL[j].name(),
                change,
            ));
        }
        Ok(Claim1Evidence { outputs })
    }

    /// Claims (2) and (3): the surfaces are even in each plane angle and rise with the angles'
    /// magnitudes.
    #[derive(Debug, Clone, PartialEq)]
    pub struct ShapeEvidence {
        /// Largest difference between $\Delta\omega(u, v)$ and its mirror images (output unit).
        pub max_asymmetry: f64,
        /// Checks of monotonic growth along rays and axes made, and how many failed.
        pub growth_checks: usize,
        /// Failed growth checks.
        pub growth_failures: usize,
    }

    impl ShapeEvidence {
        /// Claim (2) holds: even to rounding.
        #[must_use]
        pub fn even(&self) -> bool {
            self.max_asymmetry <= RATE_EQ_TOL
        }

        /// Claim (3) holds: no failed growth check.
        #[must_use]
        pub fn rising(&self) -> bool {
            self.growth_failures == 0
        }
    }

    impl fmt::Display for ShapeEvidence {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            write!(
                f,
                "largest asymmetry {}; {} of {} growth checks fail",
                short(self.max_asymmetry),
                self.growth_failures,
                self.growth_checks
            )
        }
    }

    /// Claims (2)-(3) in the plane of each output's two sensitive angles (`planes`: output
    /// index and angle pair; the paper: `[(0, [0, 1]), (1, [1, 2])]`).
    ///
    /// # Errors
    /// As [`RequirementProblem::region`].
    pub fn claims2_3_surface_shape(
        p: &RequirementProblem,
        planes: &[(usize, [usize; 2])],
    ) -> Result<ShapeEvidence, CalibError> {
        let g = grid();
        let (mut asym, mut checks, mut fails): (f64, usize, usize) = (0.0, 0, 0);
        for &(k, [a, b]) in planes {
            let r = p.region(k)?;
            let at = |u: f64, v: f64| {
                let mut d = [0.0; 3];
                d[a] = u;
                d[b] = v;
                r.rate_error(d)
            };
            for &u in &g {
                for &v in &g {
                    let f0 = at(u, v)?;
                    asym = asym
                        .max((f0 - at(-u, v)?).abs())
                        .max((f0 - at(u, -v)?).abs());
                    if u == 0.0 && v == 0.0 {
                        continue;
                    }
                    for grow in [1.5, 2.0] {
                        checks += 3;
                        fails += usize::from(at(grow * u, grow * v)? <= f0);
                        fails += usize::from(at(grow * u, v)? < f0);
                        fails += usize::from(at(u, grow * v)? < f0);
                    }
                }
            }
        }
        Ok(ShapeEvidence {
            max_asymmetry: asym,
            growth_checks: checks,
            growth_failures: fails,
        })
    }

    /// Eq 16: the requirement, and whether it rounds to the printed value.
    #[derive(Debug, Clone, PartialEq)]
    pub struct Eq16Evidence {
        /// The computed requirement, deg (`None` where unconstrained).
        pub requirement_deg: [Option<f64>; 3],
        /// The printed value, deg.
        pub printed_deg: f64,
        /// Decimals of the printed value.
        pub printed_decimals: i32,
    }

    impl Eq16Evidence {
        /// Holds when every angle rounds to the printed value.
        #[must_use]
        pub fn holds(&self) -> bool {
            let scale = 10f64.powi(self.printed_decimals);
            self.requirement_deg.iter().all(|r| {
                r.is_some_and(|d| ((d * scale).round() - self.printed_deg * scale).abs() < 0.5)
            })
        }
    }

    impl fmt::Display for Eq16Evidence {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            let r: Vec<String> = self
                .requirement_deg
                .iter()
                .zip(OrientationAxis::ALL.map(OrientationAxis::name))
                .map(|(d, n)| {
                    format!(
                        "I_{} = {}",
                        greek(n),
                        d.map_or("none".into(), |d| format!("{d:.7} deg"))
                    )
                })
                .collect();
            write!(f, "{} (printed {} deg)", r.join(", "), self.printed_deg)
        }
    }

    /// Eq 16 for a problem against the printed value (0.027 deg, 3 decimals).
    ///
    /// # Errors
    /// As [`RequirementProblem::requirement`].
    pub fn eq16_requirement(
        p: &RequirementProblem,
        printed_deg: f64,
        printed_decimals: i32,
    ) -> Result<Eq16Evidence, CalibError> {
        Ok(Eq16Evidence {
            requirement_deg: p.requirement()?.requirement.deg(),
            printed_deg,
            printed_decimals,
        })
    }
}
