//! Throughput of a Monte Carlo of the paper's table (Figure 9's quantity: the orientation error
//! at a random pose) when the errors vary with the shaft angle (issue 22), against its
//! generator alone, in the same run (interleaved rounds, best rate of each).
//!
//! Every error rides on its shaft with first and second harmonics
//! (`tt_kinematics::on_shafts`); a draw is the coefficients inside Table 4's bounds
//! (`Expansion::draw`, the documented law) and a pose uniform over the full turns. The
//! generator alone draws the same numbers; the full sample also evaluates each error at the
//! pose's joint angle and the exact chain (`Turntable::plan_orientation_error`).
//!
//! Run: `cargo run --release -p e2e-verify --example angle_throughput [-- SAMPLES ROUNDS]`
//! (defaults 2^20, 7).

use mc_verify::McRng;
use rand_core::Rng;
use std::time::Instant;
use tt_kinematics::variation::harmonic_value;
use tt_kinematics::{ErrorVariation, Expansion, GroupShape, Pose, TurntableErrors, paper};

/// A uniform draw in [0, 1) from the top 53 bits of `rng`.
fn uniform(rng: &mut McRng) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// The sum over `samples` draws of `value(rng, c)`: `c` the coefficients drawn within `ub`
/// from the stream of `seed`, which `value` goes on drawing from.
fn sum_over_draws(
    ex: &Expansion,
    ub: &[f64],
    samples: u64,
    seed: u64,
    mut value: impl FnMut(&mut McRng, &[f64]) -> f64,
) -> f64 {
    let mut rng = mc_verify::chunk_rng(seed, 0);
    let mut c = vec![0.0; ex.n_coefficients()];
    let mut acc = 0.0;
    for _ in 0..samples {
        ex.draw(ub, || uniform(&mut rng), &mut c);
        acc += value(&mut rng, &c);
    }
    acc
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize, d: u64| {
        args.get(i)
            .and_then(|s| s.parse::<f64>().ok())
            .map_or(d, |v| v as u64)
    };
    let (samples, rounds) = (arg(0, 1 << 20), arg(1, 7));
    let table = paper::table3();
    let variations = tt_kinematics::on_shafts(&table, |j| ErrorVariation::Harmonics {
        joint: j.into(),
        orders: vec![1, 2],
    });
    let schedule = vec![Pose::from_deg(&[0.0, 0.0])?];
    let ex = Expansion::new(&table, &variations, &schedule)?;
    let ub = alloc_opt::paper::table4_rad();
    let n_joints = table.n_joints();
    let tau = std::f64::consts::TAU;
    // the generator alone: the coefficients and the joint angles, summed as a checksum
    let generator = |seed: u64| -> f64 {
        sum_over_draws(&ex, &ub, samples, seed, |rng, c| {
            (0..n_joints).map(|_| uniform(rng)).sum::<f64>() + c[0]
        })
    };
    let full = |seed: u64| -> f64 {
        sum_over_draws(&ex, &ub, samples, seed, |rng, c| {
            let angles: Vec<f64> = (0..n_joints).map(|_| tau * uniform(rng)).collect();
            let chi: Vec<f64> = ex
                .groups()
                .iter()
                .map(|g| {
                    let cg = &c[g.first..g.first + g.len()];
                    match &g.shape {
                        GroupShape::Harmonics { joint, orders } => {
                            harmonic_value(orders, cg, angles[*joint])
                        }
                        _ => cg[0],
                    }
                })
                .collect();
            let pose = Pose::new(angles).expect("finite");
            let errors = TurntableErrors::new(chi, vec![0.0]).expect("finite");
            let e = table
                .plan_orientation_error(&pose, &errors)
                .expect("checked");
            e[0].abs().max(e[1].abs()).max(e[2].abs())
        })
    };
    let (mut best_gen, mut best_full) = (0.0_f64, 0.0_f64);
    let mut sink = 0.0;
    for r in 0..rounds {
        let t = Instant::now();
        sink += generator(r);
        best_gen = best_gen.max(samples as f64 / t.elapsed().as_secs_f64());
        let t = Instant::now();
        sink += full(r);
        best_full = best_full.max(samples as f64 / t.elapsed().as_secs_f64());
    }
    println!(
        "paper's table, every error first and second harmonics of its shaft, Table 4 bounds, {samples} samples x {rounds} rounds, one thread:"
    );
    println!("  generator alone: {best_gen:.3e} samples/s");
    println!("  Monte Carlo with angle-dependent errors: {best_full:.3e} samples/s");
    println!("  ratio {:.3} (checksum {sink:.3e})", best_full / best_gen);
    Ok(())
}
