//! Time of the GUM budgets of a 128-position study (issue 34: < 10 ms): the IMU example's
//! sensor on 128 positions (8 headings x 16 attitudes), noise with its timing, a coefficient
//! and eq 14's accuracy specified on each of 4 outputs (8 budgets; the accuracy is evaluated
//! at every position). Baseline in the same run: [`EndToEnd::linearization`] alone (one
//! Jacobian of the rate errors), the figure to read is the ratio.
//!
//! Run: `cargo bench -p e2e-verify --bench spec_budget`.

use criterion::{Criterion, criterion_group, criterion_main};
use e2e_verify::EndToEnd;
use std::hint::black_box;
use tt_kinematics::Pose;

const IMU: &str = include_str!("../../studies/imu-triad-example.toml");

fn bench(c: &mut Criterion) {
    let mut extra = String::new();
    for (o, coef, unit) in [
        ("gx", "bg_x", "deg_per_h"),
        ("gy", "bg_y", "deg_per_h"),
        ("ax", "sf_x", "ppm"),
        ("ay", "mis_yz", "arcsec"),
    ] {
        extra += &format!(
            "[[specifications]]\noutput = \"{o}\"\ncoefficient = \"{coef}\"\nlimit = 1\nunit = \"{unit}\"\n\n[[specifications]]\noutput = \"{o}\"\nquantity = \"accuracy\"\nlimit = 0.1\nunit = \"{}\"\n\n",
            if o.starts_with('g') {
                "deg_per_h"
            } else {
                "mg"
            }
        );
    }
    // the IMU example without its own specifications
    let bare = &IMU[..IMU
        .find("# Specifications per calibrated quantity")
        .expect("marker")];
    let s = study::Study::parse("imu.toml", &format!("{bare}\n{extra}")).expect("valid study");
    let mut positions = Vec::new();
    for h in 0..8 {
        for m in [0.0, 90.0, 180.0, 270.0] {
            for i in [0.0, 90.0, 180.0, 270.0] {
                positions.push(vec![45.0 * f64::from(h), m, i]);
            }
        }
    }
    let s = s
        .with_positions_deg(positions)
        .expect("128 positions identify the IMU");
    assert_eq!(s.calibration.schedule().len(), 128);
    let poses: Vec<Pose> = s
        .positions_deg
        .iter()
        .map(|p| Pose::from_deg(p))
        .collect::<Result<_, _>>()
        .expect("finite");
    let e2e = EndToEnd::new(&s.turntable, &s.calibration, &poses, s.reading).expect("valid");
    let tol = 10.0 * std::f64::consts::PI / (180.0 * 3600.0);
    let table: Vec<metrology::Input> = e2e
        .error_names()
        .iter()
        .map(|n| metrology::Input::rectangular(n, 0.0, tol).expect("valid"))
        .collect();
    let mut g = c.benchmark_group("spec_budget_128_positions");
    g.bench_function("budgets_8_specs_4_outputs", |b| {
        b.iter(|| {
            e2e.budget()
                .specification_budgets(
                    black_box(&s.specifications),
                    &table,
                    &s.noise,
                    s.timing.as_ref(),
                )
                .expect("budgets")
        });
    });
    g.bench_function("linearization_baseline", |b| {
        b.iter(|| black_box(&e2e).linearization());
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
