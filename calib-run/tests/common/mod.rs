//! Shared helpers: the shipped studies and simulated recordings.
#![allow(dead_code)]

use calib_run::simulate::{SimSettings, simulate_recording};
use gw_model::SensorModel;
use study::Study;

pub(crate) fn study(name: &str) -> Study {
    // calib-run's own example studies first (the six-face recording), then the shipped ones
    let own = format!("{}/studies/{name}", env!("CARGO_MANIFEST_DIR"));
    let path = if std::path::Path::new(&own).exists() {
        own
    } else {
        format!("{}/../studies/{name}", env!("CARGO_MANIFEST_DIR"))
    };
    let text = std::fs::read_to_string(&path).expect("shipped study");
    Study::parse(&path, &text).expect("valid study")
}

/// The study's sensor with every estimated coefficient moved by `shift(k, j, value)`.
pub(crate) fn truth(s: &Study, shift: impl Fn(usize, usize, f64) -> f64) -> SensorModel {
    let mut outs = s.sensor.outputs().to_vec();
    for (k, o) in outs.iter_mut().enumerate() {
        let mut j = 0;
        for t in &mut o.terms {
            if !t.known {
                t.value = shift(k, j, t.value);
                j += 1;
            }
        }
    }
    SensorModel::new(outs).expect("model")
}

/// The study's white densities (its noise models), output unit per sqrt(Hz).
pub(crate) fn white(s: &Study) -> Vec<f64> {
    s.noise
        .iter()
        .map(|n| {
            n.as_ref()
                .map_or(0.0, gw_model::noise::NoiseModel::white_per_sqrt_hz)
        })
        .collect()
}

pub(crate) fn record(s: &Study, truth: &SensorModel, settings: &SimSettings) -> Vec<u8> {
    let mut buf = Vec::new();
    simulate_recording(s, truth, settings, &mut buf).expect("simulated");
    buf
}

pub(crate) fn settings(s: &Study, rate_hz: f64, dwell_s: f64, seed: u64) -> SimSettings {
    SimSettings::for_study(s, rate_hz, dwell_s, seed)
}
