//! Gravity and earth-rate inputs (eq 3) and the GyroWheel's outputs (eq 1, Table 1) at a few
//! positions of the paper's turntable.
//!
//! Run: `cargo run -p gw-model --example inputs_at_positions`

use gw_model::{InputValues, ModelError, paper};
use tt_core::units::rad_per_s_to_deg_per_h;

fn main() -> Result<(), ModelError> {
    let site = paper::site();
    let sensor = paper::gyrowheel();
    println!(
        "site: latitude {} deg, earth rate {:.7e} rad/s",
        site.latitude_deg(),
        site.earth_rate_rad_per_s()
    );
    println!("phi1,phi2 (deg) | a_x a_y a_z (g) | w_x w_y w_z (deg/h) | outputs x, y (deg/h)");
    for (p1, p2) in [
        (0.0, 0.0),
        (90.0, 0.0),
        (90.0, 45.0),
        (180.0, 90.0),
        (270.0, 135.0),
    ] {
        let inputs = site.inputs(&paper::base_from_sensor(
            f64::to_radians(p1),
            f64::to_radians(p2),
        ));
        let v = InputValues::from_inputs(&inputs);
        let a = inputs.specific_force_g;
        let w = inputs.rate_rad_per_s.map(rad_per_s_to_deg_per_h);
        let out: Vec<String> = sensor
            .outputs()
            .iter()
            .map(|o| format!("{:9.4}", o.value(&v)))
            .collect();
        println!(
            "({p1:>5},{p2:>5})    | {:6.3} {:6.3} {:6.3} | {:7.3} {:7.3} {:7.3} | {}",
            a.x,
            a.y,
            a.z,
            w.x,
            w.y,
            w.z,
            out.join(" ")
        );
    }
    Ok(())
}
