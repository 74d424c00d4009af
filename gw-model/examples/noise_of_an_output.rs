//! The noise of a STIM300-class gyro and accelerometer from their datasheet values: the
//! densities in the outputs' units, the Gauss-Markov bias, and what a 60 s average at one
//! test position keeps of each. Run: `cargo run -p gw-model --example noise_of_an_output`.

use gw_model::noise::{NoiseModel, WhiteDensity, Window};

fn main() -> Result<(), gw_model::ModelError> {
    // Datasheet values in the datasheet's units, converted to each output's unit.
    let gyro = NoiseModel::from_datasheet(
        "deg_per_h",
        Some(WhiteDensity::DegPerSqrtH(0.15)), // angle random walk, deg/sqrt(h)
        Some((0.5, 3600.0)),                   // bias instability 0.5 deg/h, correlation 1 h
        None,                                  // no quantization
    )?;
    let acc = NoiseModel::from_datasheet(
        "mg",
        Some(WhiteDensity::MPerSPerSqrtH(0.07)), // velocity random walk, (m/s)/sqrt(h)
        Some((0.05, 3600.0)),                    // bias instability 0.05 mg
        None,
    )?;
    println!(
        "gyro white density {:.3} (deg/h)/sqrt(Hz)",
        gyro.white_per_sqrt_hz()
    ); // 9.000
    println!(
        "acc  white density {:.4} mg/sqrt(Hz)",
        acc.white_per_sqrt_hz()
    ); // 0.1190

    // Two 60 s dwells 10 s apart (a move between two test positions), sampled at 1000 Hz.
    let (first, second) = (Window::new(0.0, 60.0)?, Window::new(70.0, 60.0)?);
    for (name, unit, noise) in [("gyro", "deg/h", &gyro), ("acc", "mg", &acc)] {
        let white = noise.white_variance_of_average(&first, 1000.0).sqrt();
        let bias = noise.correlated_variance_of_average(&first).sqrt();
        let corr = noise.covariance_of_averages(&first, &second, 1000.0)
            / noise.variance_of_average(&first, 1000.0);
        println!(
            "{name}: 60 s average: white {white:.4} {unit}, bias {bias:.4} {unit}; correlation with the next position {corr:.3}"
        );
    }
    Ok(())
}
