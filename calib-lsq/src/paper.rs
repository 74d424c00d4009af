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
/// [`CalibError::NonFinite`] for a non-finite angle, [`CalibError::LengthMismatch`] for an
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
