//! Calibration schedules: the orientations of the sensor on the turntable, as intended.

use crate::error::{CalibError, finite};
use gw_model::{Inputs, Site};
use nalgebra::Matrix3;

/// One test position: the intended orientation $\mathbf R_d$ (sensor frame to base frame) and
/// the commanded joint angles it comes from (degrees, for reports and messages); for a rate
/// step also the motion and the nominal inputs averaged over it ([`RateMotion`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Position {
    base_from_sensor: Matrix3<f64>,
    joint_angles_deg: Vec<f64>,
    motion: Option<RateMotion>,
}

/// A rate step of a schedule: joint `joint` turns at `rate_rad_per_s` for `revolutions` whole
/// revolutions from the position's joint angles, the sensor at `lever_arm_m` from the platform's
/// origin; `nominal` holds the inputs averaged over the revolutions on the intended table
/// (every error zero), which the regressions use. A constant orientation error $\Delta\mathbf
/// R$ of the sensor frame (eq 7-8) turns these averages as it turns a static position's inputs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RateMotion {
    /// Index of the turning joint (pose order).
    pub joint: usize,
    /// Commanded rate, rad/s (signed, non-zero).
    pub rate_rad_per_s: f64,
    /// Whole revolutions.
    pub revolutions: u32,
    /// The sensor's mounting lever arm in the platform frame, m.
    pub lever_arm_m: [f64; 3],
    /// The nominal inputs averaged over the revolutions.
    pub nominal: Inputs,
}

impl Position {
    /// A position from its intended orientation and the joint angles (degrees) that command
    /// it. The rotation is checked to be finite.
    ///
    /// # Errors
    /// [`CalibError::Field`] (not finite) naming `base_from_sensor` or `joint_angles_deg[k]`.
    pub fn new(
        base_from_sensor: Matrix3<f64>,
        joint_angles_deg: Vec<f64>,
    ) -> Result<Self, CalibError> {
        for v in base_from_sensor.iter() {
            finite("base_from_sensor", *v)?;
        }
        for (k, v) in joint_angles_deg.iter().enumerate() {
            finite(format!("joint_angles_deg[{k}]"), *v)?;
        }
        Ok(Self {
            base_from_sensor,
            joint_angles_deg,
            motion: None,
        })
    }

    /// A rate step starting at the joint angles `joint_angles_deg` (orientation
    /// `base_from_sensor` there), with its motion and nominal averaged inputs.
    ///
    /// # Errors
    /// As [`Position::new`]; [`CalibError::Field`] (not finite) naming `rate_rad_per_s`,
    /// `lever_arm_m` or `nominal` for a non-finite value.
    pub fn rate_step(
        base_from_sensor: Matrix3<f64>,
        joint_angles_deg: Vec<f64>,
        motion: RateMotion,
    ) -> Result<Self, CalibError> {
        finite("rate_rad_per_s", motion.rate_rad_per_s)?;
        for v in motion.lever_arm_m {
            finite("lever_arm_m", v)?;
        }
        for v in motion
            .nominal
            .specific_force_g
            .iter()
            .chain(motion.nominal.rate_rad_per_s.iter())
        {
            finite("nominal", *v)?;
        }
        let mut p = Self::new(base_from_sensor, joint_angles_deg)?;
        p.motion = Some(motion);
        Ok(p)
    }

    /// The rate step's motion, `None` for a static position.
    #[must_use]
    pub fn motion(&self) -> Option<&RateMotion> {
        self.motion.as_ref()
    }

    /// $\mathbf R_d$, sensor to base.
    #[must_use]
    pub fn base_from_sensor(&self) -> &Matrix3<f64> {
        &self.base_from_sensor
    }

    /// The commanded joint angles, degrees.
    #[must_use]
    pub fn joint_angles_deg(&self) -> &[f64] {
        &self.joint_angles_deg
    }
}

/// A list of test positions. Whether it identifies a sensor's coefficients is checked when a
/// [`crate::Calibration`] is prepared for that sensor.
#[derive(Debug, Clone, PartialEq)]
pub struct Schedule {
    positions: Vec<Position>,
}

impl Schedule {
    /// A schedule from positions (at least one).
    ///
    /// # Errors
    /// [`CalibError::Field`] ([`tt_core::FieldError::Length`]) naming `positions` when empty.
    pub fn new(positions: Vec<Position>) -> Result<Self, CalibError> {
        if positions.is_empty() {
            return Err(CalibError::Field(tt_core::FieldError::Length {
                field: "positions".into(),
                expected: 1,
                found: 0,
            }));
        }
        Ok(Self { positions })
    }

    /// The positions.
    #[must_use]
    pub fn positions(&self) -> &[Position] {
        &self.positions
    }

    /// Number of positions $n$.
    #[must_use]
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// Whether there are no positions (never true for a constructed schedule).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// The same schedule with the positions in another order; `order[i]` is the index of the
    /// position placed at `i`.
    ///
    /// # Errors
    /// [`CalibError::Field`] ([`tt_core::FieldError::Length`]) unless `order` is a permutation of `0..n`.
    pub fn permuted(&self, order: &[usize]) -> Result<Self, CalibError> {
        let n = self.len();
        let mut seen = vec![false; n];
        let bad = || {
            CalibError::Field(tt_core::FieldError::Length {
                field: "permutation".into(),
                expected: n,
                found: order.len(),
            })
        };
        if order.len() != n {
            return Err(bad());
        }
        for &k in order {
            if k >= n || seen[k] {
                return Err(bad());
            }
            seen[k] = true;
        }
        Ok(Self {
            positions: order.iter().map(|&k| self.positions[k].clone()).collect(),
        })
    }

    /// The nominal inputs at every position (eq 3; a rate step's averages,
    /// [`RateMotion::nominal`]).
    #[must_use]
    pub fn inputs(&self, site: &Site) -> Vec<Inputs> {
        self.positions
            .iter()
            .map(|p| match p.motion() {
                Some(m) => m.nominal,
                None => site.inputs(p.base_from_sensor()),
            })
            .collect()
    }

    /// Whether any entry is a rate step.
    #[must_use]
    pub fn has_rate_steps(&self) -> bool {
        self.positions.iter().any(|p| p.motion.is_some())
    }

    /// The actual inputs (eq 8) at every position for per-position $\Delta\mathbf R$ (at a
    /// rate step, its nominal averages turned by $\Delta\mathbf R$: a constant orientation
    /// error of the sensor frame).
    ///
    /// # Errors
    /// [`CalibError::Field`] ([`tt_core::FieldError::Length`]) unless there is one matrix per position.
    pub fn actual_inputs(
        &self,
        site: &Site,
        delta_r: &[Matrix3<f64>],
    ) -> Result<Vec<Inputs>, CalibError> {
        if delta_r.len() != self.len() {
            return Err(CalibError::Field(tt_core::FieldError::Length {
                field: "delta_r".into(),
                expected: self.len(),
                found: delta_r.len(),
            }));
        }
        Ok(self
            .positions
            .iter()
            .zip(delta_r)
            .map(|(p, d)| match p.motion() {
                Some(m) => m.nominal.rotated(d),
                None => site.inputs_with_error(p.base_from_sensor(), d),
            })
            .collect())
    }
}
