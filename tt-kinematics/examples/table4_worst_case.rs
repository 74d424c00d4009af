//! Evaluate a turntable built to the paper's Table 4 tolerances: the orientation error at a
//! few poses with every model, the Figure 8 sensitivities, and the exact worst case of the
//! linear model over all poses and signs. Then the same for a three-axis table described in
//! a few lines.
//!
//! Run: `cargo run -p tt-kinematics --example table4_worst_case`

use tt_core::units::{arcmin_to_rad, rad_to_arcmin};
use tt_kinematics::paper::{self, ClosedForm};
use tt_kinematics::{
    ExactChain, FactorSpec, LinearChain, LinearModel, OrientationAxis, OrientationErrorModel, Pose,
    SignedAxis, SmallAngleChain, Turntable, TurntableDescription, TurntableErrors,
};

fn main() -> Result<(), tt_kinematics::KinematicsError> {
    let table = paper::table3();
    let table4_arcmin = [
        0.4235, 0.7800, 0.4234, 0.7800, 0.2825, 0.2824, 0.4234, 0.4233,
    ];
    let chi = TurntableErrors::from_arcmin(&table4_arcmin, &[0.0])?;
    println!("pose (deg)      model         dpsi'     dtheta'   dgamma'");
    let models: [(&str, Box<dyn OrientationErrorModel>); 4] = [
        ("exact", Box::new(ExactChain::new(&table))),
        ("small-angle", Box::new(SmallAngleChain::new(&table))),
        ("linear", Box::new(LinearChain::new(&table))),
        ("eq 26", Box::new(ClosedForm)),
    ];
    for (p1, p2) in [(0.0, 0.0), (30.0, 45.0), (90.0, 135.0)] {
        let pose = Pose::from_deg(&[p1, p2])?;
        for (name, m) in &models {
            let e = m.orientation_error(&pose, &chi)?;
            println!(
                "({p1:>5},{p2:>5})  {name:<12} {:>9.6} {:>9.6} {:>9.6}",
                rad_to_arcmin(e.delta_psi_rad),
                rad_to_arcmin(e.delta_theta_rad),
                rad_to_arcmin(e.delta_gamma_rad)
            );
        }
    }
    let linear = LinearModel::new(&table);
    println!("\nFigure 8 (average |d f / d chi|):");
    let avg = linear.average_abs_coefficients();
    for axis in OrientationAxis::ALL {
        let row: Vec<String> = (0..8)
            .map(|i| format!("{:.4}", avg[(axis.index(), i)]))
            .collect();
        println!("  {:<6} {}", axis.name(), row.join(" "));
    }
    let ub: Vec<f64> = table4_arcmin.iter().map(|&a| arcmin_to_rad(a)).collect();
    println!("\nworst case over all poses and signs (arcmin; requirement 1.62'):");
    for axis in OrientationAxis::ALL {
        let w = linear.max_abs_weighted(axis, &ub, None)?;
        println!(
            "  {:<6} {:.5}' at phi2 = {:.2} deg",
            axis.name(),
            rad_to_arcmin(w.value()),
            w.pose_rad()[1].to_degrees()
        );
    }

    // Any table is a list of factors: a three-axis table in a few lines.
    let j = FactorSpec::joint;
    let e = FactorSpec::error;
    let (x, y, z) = (SignedAxis::X, SignedAxis::Y, SignedAxis::Z);
    let three = Turntable::new(&TurntableDescription::new(vec![
        j("outer", z),
        e("d_outer", z),
        e("wob_ox", x),
        e("wob_oy", y),
        e("perp_om", y),
        j("middle", x),
        e("d_middle", x),
        e("wob_my", y),
        e("wob_mz", z),
        e("perp_mi", z),
        j("inner", y),
        e("d_inner", y),
        e("wob_ix", x),
        e("wob_iz", z),
    ]))?;
    let ub = vec![arcmin_to_rad(0.3); three.n_rotation_errors()];
    let lm = LinearModel::new(&three);
    println!("\nthree-axis table, every error within 0.3', certified worst case (arcmin):");
    for axis in OrientationAxis::ALL {
        let w = lm.worst_pose_certified(axis, &ub, true, None)?;
        println!(
            "  {:<6} {:.5}' (bound {:.5}') at middle {:.1} deg, inner {:.1} deg",
            axis.name(),
            rad_to_arcmin(w.value()),
            rad_to_arcmin(w.upper_bound()),
            w.pose_rad()[1].to_degrees(),
            w.pose_rad()[2].to_degrees()
        );
    }
    Ok(())
}
