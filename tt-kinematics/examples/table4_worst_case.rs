//! Evaluate a turntable built to the paper's Table 4 tolerances: the orientation error at a
//! few poses with all three models, the Figure 8 sensitivities, and the exact worst case of
//! the linear model over all poses and signs.
//!
//! Run: `cargo run -p tt-kinematics --example table4_worst_case`

use tt_kinematics::sensitivity::average_sensitivity_closed_form;
use tt_kinematics::units::{arcmin_to_rad, rad_to_arcmin};
use tt_kinematics::{
    ClosedForm, ErrorComponent, ExactChain, LinearModel, OrientationAxis, OrientationErrorModel,
    Pose, SmallAngleChain, TurntableErrors,
};

fn main() -> Result<(), tt_kinematics::KinematicsError> {
    let table4_arcmin = [
        0.4235, 0.7800, 0.4234, 0.7800, 0.2825, 0.2824, 0.4234, 0.4233,
    ];
    let chi = TurntableErrors::from_arcmin(table4_arcmin, 0.0)?;
    println!("pose (deg)      model         dpsi'     dtheta'   dgamma'");
    for (p1, p2) in [(0.0, 0.0), (30.0, 45.0), (90.0, 135.0)] {
        let pose = Pose::from_deg(p1, p2)?;
        let models: [(&str, &dyn OrientationErrorModel); 3] = [
            ("exact", &ExactChain::default()),
            ("small-angle", &SmallAngleChain),
            ("closed form", &ClosedForm),
        ];
        for (name, m) in models {
            let e = m.orientation_error(&pose, &chi);
            println!(
                "({p1:>5},{p2:>5})  {name:<12} {:>9.6} {:>9.6} {:>9.6}",
                rad_to_arcmin(e.delta_psi_rad),
                rad_to_arcmin(e.delta_theta_rad),
                rad_to_arcmin(e.delta_gamma_rad)
            );
        }
    }
    let model = LinearModel::paper_eq26();
    let s = average_sensitivity_closed_form(&model);
    println!("\nFigure 8: average sensitivity (rows psi, theta, gamma)");
    for c in ErrorComponent::ALL {
        println!(
            "  {:<10} {:.4} {:.4} {:.4}",
            c.name(),
            s[(0, c.index())],
            s[(1, c.index())],
            s[(2, c.index())]
        );
    }
    let ub = table4_arcmin.map(arcmin_to_rad);
    println!("\nworst case over all poses and signs, |chi_i| <= Table 4 (eq 26):");
    for axis in OrientationAxis::ALL {
        let w = model.max_abs_weighted(axis, &ub, 0.0, std::f64::consts::TAU);
        println!(
            "  {:<6} {:.5} arcmin at phi2 = {:.2} deg",
            axis.name(),
            rad_to_arcmin(w.value),
            w.phi2_rad.to_degrees()
        );
    }
    Ok(())
}
