//! Recordings with a known truth, for tests and benchmarks: the study's schedule played on a
//! table with given errors, every sample the sensor model's output at the actual orientation
//! and rate plus white noise.
//!
//! Timeline: each static position for its dwell, a move of [`SimSettings::move_s`] between
//! positions (joint angles interpolated smoothly), then for each rate step a move to its
//! start, a rest of [`SimSettings::rest_s`], the step's whole revolutions in
//! [`SimSettings::rotation_s`] with a smooth, non-uniform rate profile
//! $\theta(t) = \Theta\,(t/T - \sin(2\pi t/T)/2\pi)$ (a hand-turned rotation: the mean rate is
//! not the commanded one), and a rest. The rate each sample sees is the rotation between
//! consecutive orientations over the interval (so a rotation's samples integrate exactly to
//! its angle) plus the earth's. Written as CSV `t_s,<outputs>[,<joint>_deg...]`; memory does
//! not depend on the length.

use crate::error::RunError;
use gw_model::{InputValues, Inputs, SensorModel};
use nalgebra::Matrix3;
use rand_chacha::ChaCha8Rng;
use rand_core::{Rng, SeedableRng};
use std::io::Write;
use study::Study;
use tt_kinematics::{ChainKind, Pose, TurntableErrors};

/// How to simulate.
#[derive(Debug, Clone, PartialEq)]
pub struct SimSettings {
    /// Sample rate, Hz.
    pub sample_rate_hz: f64,
    /// Dwell at each static position, s.
    pub dwell_s: f64,
    /// Move between positions, s.
    pub move_s: f64,
    /// Rest before and after each rotation, s.
    pub rest_s: f64,
    /// Duration of each rate step's revolutions, s.
    pub rotation_s: f64,
    /// White noise density per output, output unit per sqrt(Hz).
    pub white_per_sqrt_hz: Vec<f64>,
    /// The table's rotation errors chi, rad (`None`: a perfect table).
    pub table_errors_rad: Option<Vec<f64>>,
    /// Write the table's (commanded) angles as columns `<joint>_deg`.
    pub log_angles: bool,
    /// Noise seed.
    pub seed: u64,
    /// Repeat the whole schedule this many times (long recordings for benchmarks).
    pub repeats: u32,
}

impl SimSettings {
    /// A recording of `study` at `sample_rate_hz` with `dwell_s` at each position, 2 s moves,
    /// 3 s rests around 8 s rotations, the study's white noise densities (0 where it gives
    /// none), a perfect table, no logged angles, one pass.
    #[must_use]
    pub fn for_study(study: &Study, sample_rate_hz: f64, dwell_s: f64, seed: u64) -> Self {
        SimSettings {
            sample_rate_hz,
            dwell_s,
            move_s: 2.0,
            rest_s: 3.0,
            rotation_s: 8.0,
            white_per_sqrt_hz: study
                .noise
                .iter()
                .map(|n| {
                    n.as_ref()
                        .map_or(0.0, gw_model::noise::NoiseModel::white_per_sqrt_hz)
                })
                .collect(),
            table_errors_rad: None,
            log_angles: false,
            seed,
            repeats: 1,
        }
    }
}

struct Writer<'a, W: Write> {
    out: W,
    study: &'a Study,
    truth: &'a SensorModel,
    s: &'a SimSettings,
    errors: TurntableErrors,
    rng: ChaCha8Rng,
    prev: Option<Matrix3<f64>>,
    n: u64,
    line: String,
    sigma: Vec<f64>,
}

impl<W: Write> Writer<'_, W> {
    fn normal(&mut self) -> f64 {
        // Box-Muller from two 53-bit uniforms in (0, 1]
        let u = |r: &mut ChaCha8Rng| ((r.next_u64() >> 11) + 1) as f64 / (1u64 << 53) as f64;
        let (a, b): (f64, f64) = (u(&mut self.rng), u(&mut self.rng));
        (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos()
    }

    fn sample(&mut self, angles_deg: &[f64]) -> Result<(), RunError> {
        let internal = |e: tt_kinematics::KinematicsError| RunError::Internal(e.to_string());
        let pose = Pose::from_deg(angles_deg).map_err(|e| RunError::Internal(e.to_string()))?;
        let r = self
            .study
            .turntable
            .actual_rotation(&pose, &self.errors, ChainKind::Exact)
            .map_err(internal)?;
        let dt = 1.0 / self.s.sample_rate_hz;
        let mut inputs: Inputs = self.study.site.inputs(&r);
        if let Some(p) = self.prev {
            // body rate: the rotation from the previous orientation, over the interval
            let d = p.transpose() * r;
            let rot = nalgebra::Rotation3::from_matrix_unchecked(d);
            inputs.rate_rad_per_s += rot.scaled_axis() / dt;
        }
        self.prev = Some(r);
        let v = InputValues::from_inputs(&inputs);
        self.line.clear();
        self.line.push_str(&(self.n as f64 * dt).to_string());
        for k in 0..self.truth.n_outputs() {
            let y = self.truth.outputs()[k].value(&v) + self.sigma[k] * self.normal();
            self.line.push(',');
            self.line.push_str(&y.to_string());
        }
        if self.s.log_angles {
            for a in angles_deg {
                self.line.push(',');
                self.line.push_str(&a.to_string());
            }
        }
        self.line.push('\n');
        self.out
            .write_all(self.line.as_bytes())
            .map_err(|e| RunError::Io {
                what: "simulated recording".into(),
                source: e,
            })?;
        self.n += 1;
        Ok(())
    }

    fn hold(&mut self, angles: &[f64], seconds: f64) -> Result<(), RunError> {
        let n = (seconds * self.s.sample_rate_hz).round() as u64;
        for _ in 0..n {
            self.sample(angles)?;
        }
        Ok(())
    }

    /// Move from `a` to `b` over `seconds` along the smooth profile.
    fn go(&mut self, a: &[f64], b: &[f64], seconds: f64) -> Result<(), RunError> {
        let n = (seconds * self.s.sample_rate_hz).round() as u64;
        let mut x = vec![0.0; a.len()];
        for i in 1..=n {
            let u = i as f64 / n as f64;
            let f = u - (std::f64::consts::TAU * u).sin() / std::f64::consts::TAU;
            for j in 0..a.len() {
                x[j] = a[j] + (b[j] - a[j]) * f;
            }
            self.sample(&x)?;
        }
        Ok(())
    }
}

/// Write a recording of `study`'s schedule for a sensor whose true coefficients are `truth`'s
/// term values; returns the number of samples.
///
/// # Errors
/// [`RunError::Option`] for settings of the wrong length; [`RunError::Io`] when writing fails.
pub fn simulate_recording<W: Write>(
    study: &Study,
    truth: &SensorModel,
    s: &SimSettings,
    out: W,
) -> Result<u64, RunError> {
    if s.white_per_sqrt_hz.len() != truth.n_outputs() {
        return Err(RunError::option(
            "white_per_sqrt_hz",
            "one density per output",
        ));
    }
    let n_chi = study.turntable.n_rotation_errors();
    let chi = s
        .table_errors_rad
        .clone()
        .unwrap_or_else(|| vec![0.0; n_chi]);
    let errors = TurntableErrors::new(chi, vec![0.0; study.turntable.n_translation_errors()])
        .map_err(|e| RunError::option("table_errors_rad", e.to_string()))?;
    let mut w = Writer {
        out,
        study,
        truth,
        s,
        errors,
        rng: ChaCha8Rng::seed_from_u64(s.seed),
        prev: None,
        n: 0,
        line: String::new(),
        sigma: s
            .white_per_sqrt_hz
            .iter()
            .map(|n| n * s.sample_rate_hz.sqrt())
            .collect(),
    };
    let mut header = String::from("t_s");
    for o in truth.outputs() {
        header.push(',');
        header.push_str(&o.name);
    }
    if s.log_angles {
        for j in study.turntable.joint_names() {
            header.push_str(&format!(",{j}_deg"));
        }
    }
    header.push('\n');
    w.out
        .write_all(header.as_bytes())
        .map_err(|e| RunError::Io {
            what: "simulated recording".into(),
            source: e,
        })?;
    let positions = &study.positions_deg;
    let mut here = positions[0].clone();
    for _ in 0..s.repeats.max(1) {
        for p in positions {
            if *p != here {
                w.go(&here.clone(), p, s.move_s)?;
                here = p.clone();
            }
            w.hold(p, s.dwell_s)?;
        }
        for step in &study.rate_steps {
            if step.angles_deg != here {
                w.go(&here.clone(), &step.angles_deg, s.move_s)?;
                here = step.angles_deg.clone();
            }
            w.hold(&here.clone(), s.rest_s)?;
            let mut end = here.clone();
            end[step.joint] += 360.0 * f64::from(step.revolutions) * step.rate_deg_per_s.signum();
            w.go(&here.clone(), &end, s.rotation_s)?;
            // the same pose, logged as turned
            w.hold(&end, s.rest_s)?;
            here = step.angles_deg.clone();
        }
    }
    Ok(w.n)
}
