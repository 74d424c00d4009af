//! Gravity and earth-rate inputs (eq 3) and Table 1 outputs (eq 1) at a few turntable positions.
//!
//! Run: `cargo run -p gw-model --example inputs_at_positions`

use gw_model::units::rad_per_s_to_deg_per_h;
use gw_model::{DriftCoefficients, ModelError, Position, Site};

fn main() -> Result<(), ModelError> {
    let site = Site::paper_default();
    let t1 = DriftCoefficients::table_1();
    println!(
        "site: latitude {} deg, earth rate {:.7e} rad/s",
        site.latitude_deg(),
        site.earth_rate_rad_per_s()
    );
    println!("phi1,phi2 (deg) | a_x a_y a_z (g) | w_x w_y w_z (deg/h) | k_y i_y, k_x i_x (deg/h)");
    for (p1, p2) in [
        (0.0, 0.0),
        (90.0, 0.0),
        (90.0, 45.0),
        (180.0, 90.0),
        (270.0, 135.0),
    ] {
        let inp = site.inputs(&Position::from_deg(p1, p2)?);
        let a = inp.specific_force_g;
        let w = inp.rate_rad_per_s.map(rad_per_s_to_deg_per_h);
        println!(
            "{p1:>5} {p2:>5} | {:+.3} {:+.3} {:+.3} | {:+.4} {:+.4} {:+.4} | {:+.4} {:+.4}",
            a.x,
            a.y,
            a.z,
            w.x,
            w.y,
            w.z,
            rad_per_s_to_deg_per_h(t1.x.output_rad_per_s(&inp)),
            rad_per_s_to_deg_per_h(t1.y.output_rad_per_s(&inp)),
        );
    }
    Ok(())
}
