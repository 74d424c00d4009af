//! What sensor noise does to a calibration: the paper's GyroWheel on its 32 positions,
//! 60 s per position, with an assumed noise (white 0.05 (deg/h)/sqrt(Hz), bias instability
//! 0.005 deg/h over 10 min; the paper gives none). Prints each coefficient's 1-sigma (white
//! and correlated parts), the largest rate-error sigma at the test positions, and what
//! visiting the positions column by column of the grid does (phi2 first). Run:
//! `cargo run -p calib-lsq --example noise_covariance`.

use calib_lsq::{Calibration, Timing};
use gw_model::noise::{GaussMarkov, NoiseModel};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let cal = Calibration::new(
        &gw_model::paper::gyrowheel(),
        &gw_model::paper::site(),
        &calib_lsq::paper::schedule(),
    )?;
    let bias = GaussMarkov::from_bias_instability(0.005, 600.0)?; // deg/h, s (assumption)
    let noise = NoiseModel::new(0.05, Some(bias), 0.0)?; // (deg/h)/sqrt(Hz) (assumption)
    let timing = Timing::uniform(32, 60.0, 10.0, 1000.0)?; // dwell, move (s), sample rate (Hz)
    let all = cal.noise_covariances(&[Some(noise.clone()), Some(noise.clone())], &timing)?;
    for (out, cov) in cal.outputs().iter().zip(&all) {
        let cov = cov.as_ref().expect("every output has noise here");
        let c = cov.coefficients();
        println!("output {} (deg/h per regressor unit):", out.output().name);
        for (j, name) in c.names().iter().enumerate() {
            println!(
                "  {name:>6}: sigma {:.5} (white {:.5}, correlated {:.5})",
                c.sigma()[j],
                c.white_sigma()[j],
                c.correlated_sigma()[j]
            );
        }
        let (i, s) = cov.rate_error().max_sigma();
        println!("  largest rate-error sigma {s:.5} deg/h at position {i}");
        // The same positions, phi1 varying fastest: only the correlated part changes.
        // (Reversing an order changes nothing: the Gauss-Markov process is time-reversible.)
        let by_phi2: Vec<usize> = (0..8)
            .flat_map(|j| (0..4).map(move |i| 8 * i + j))
            .collect();
        let r = out.noise_covariance_in_order(&noise, &timing, &by_phi2)?;
        println!(
            "  phi1 fastest: bias sigma {:.5}, correlated {:.5} (schedule order {:.5}, {:.5})",
            r.coefficients().sigma()[0],
            r.coefficients().correlated_sigma()[0],
            c.sigma()[0],
            c.correlated_sigma()[0]
        );
    }
    Ok(())
}
