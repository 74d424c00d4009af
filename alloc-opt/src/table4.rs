//! The paper's published numbers, as golden data with provenance.

use tt_kinematics::CHI_LEN;
use tt_kinematics::units::RAD_PER_ARCMIN;

/// The orientation requirement of eq 16 as printed: $|\Delta\psi|, |\Delta\theta|,
/// |\Delta\gamma| \le 0.027^\circ$ (= 1.62 arcmin).
///
/// # Reference
/// Zhao et al. 2017, §2.3, eq 16.
pub const PAPER_REQUIREMENT_DEG: f64 = 0.027;

/// Table 4 of the paper: the published upper bounds $\mathrm{UB}_i$ in arcminutes, in the order
/// of $\chi$ in eq 25 ($\Delta\phi_{y1}, \Delta\phi_{z2}, \Delta\alpha_{x1}, \Delta\alpha_{z1},
/// \Delta\alpha_{x2}, \Delta\alpha_{y2}, \Delta\varepsilon_x, \Delta\varepsilon_y$; the table's
/// garbled first column is read as in NOTES item 6).
///
/// These are NOT the optimum of the stated problem (31)-(34): they use 91.4% of $I_\psi$ and
/// $I_\gamma$ and 96.3% of $I_\theta$ (see the crate documentation, "Table 4").
///
/// # Reference
/// Zhao et al. 2017, §4.3, Table 4 ("Accuracy requirements (arc minute)").
pub const PAPER_TABLE4_ARCMIN: [f64; CHI_LEN] = [
    0.4235, 0.7800, 0.4234, 0.7800, 0.2825, 0.2824, 0.4234, 0.4233,
];

/// [`PAPER_TABLE4_ARCMIN`] in radians.
#[must_use]
pub fn paper_table4_rad() -> [f64; CHI_LEN] {
    PAPER_TABLE4_ARCMIN.map(|v| v * RAD_PER_ARCMIN)
}
