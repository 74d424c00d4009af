//! Sensors as data: outputs linear in their coefficients, regressors as products of the
//! inputs in the sensor frame. Eq 1 of the paper (the GyroWheel) is one instance
//! (`paper::gyrowheel`).
//!
//! # Formula
//! Output $k$ at inputs $(\mathbf a, \boldsymbol\omega)$ in the sensor frame is
//! $$y_k = \sum_{t \in \text{terms}(k)} \beta_t\, r_t(\mathbf a, \boldsymbol\omega),$$
//! each regressor $r_t$ being $1$ or a monomial in $a_x, a_y, a_z$ (specific force, g) and
//! $w_x, w_y, w_z$ (angular rate, deg/h). Terms marked known (the rate input itself, a unit
//! scale factor) are not estimated: they form the vector $\mathbf b_2$ of eq 2/5; the other
//! terms form the regression matrix $\mathbf A$ and the unknowns $\boldsymbol\beta$.
//!
//! # Units
//! An output carries its own unit label (`deg_per_h`, `g`, ...); each coefficient is in
//! output unit per regressor unit (deg/h/g for a g-sensitivity of a gyro in deg/h). The
//! model is evaluated in those units; angular rates enter regressors in deg/h (converted once,
//! from the rad/s of [`crate::Inputs`]).

use crate::error::{ModelError, finite, positive};
use crate::site::Inputs;
use nalgebra::Vector3;
use std::fmt;
use tt_core::units::rad_per_s_to_deg_per_h;

/// An input component in the sensor frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Input {
    /// Specific force along $x$, g.
    Ax,
    /// Specific force along $y$, g.
    Ay,
    /// Specific force along $z$, g.
    Az,
    /// Angular rate about $x$, deg/h.
    Wx,
    /// Angular rate about $y$, deg/h.
    Wy,
    /// Angular rate about $z$, deg/h.
    Wz,
}

impl Input {
    /// All six, in the order $a_x, a_y, a_z, w_x, w_y, w_z$.
    pub const ALL: [Input; 6] = [
        Input::Ax,
        Input::Ay,
        Input::Az,
        Input::Wx,
        Input::Wy,
        Input::Wz,
    ];

    /// The symbol used in study files (`a_x`, ..., `w_z`).
    #[must_use]
    pub fn symbol(self) -> &'static str {
        match self {
            Input::Ax => "a_x",
            Input::Ay => "a_y",
            Input::Az => "a_z",
            Input::Wx => "w_x",
            Input::Wy => "w_y",
            Input::Wz => "w_z",
        }
    }

    /// The unit of the input (`g` or `deg/h`).
    #[must_use]
    pub fn unit(self) -> &'static str {
        match self {
            Input::Ax | Input::Ay | Input::Az => "g",
            _ => "deg/h",
        }
    }

    fn index(self) -> usize {
        self as usize
    }
}

/// The six input values in the units of the regressors: $\mathbf a$ in g, $\boldsymbol\omega$
/// in deg/h.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InputValues(pub [f64; 6]);

impl InputValues {
    /// From body-frame inputs (specific force in g, rate in rad/s).
    #[must_use]
    pub fn from_inputs(inputs: &Inputs) -> Self {
        let a = inputs.specific_force_g;
        let w = inputs.rate_rad_per_s.map(rad_per_s_to_deg_per_h);
        Self([a.x, a.y, a.z, w.x, w.y, w.z])
    }

    /// The inputs seen from a frame turned by $\Delta\mathbf R$ (eq 8):
    /// $\mathbf v' = \Delta\mathbf R^T\mathbf v$ for both vectors.
    #[must_use]
    pub fn rotated(&self, delta_r: &nalgebra::Matrix3<f64>) -> Self {
        let [ax, ay, az, wx, wy, wz] = self.0;
        let t = delta_r.transpose();
        let a = t * Vector3::new(ax, ay, az);
        let w = t * Vector3::new(wx, wy, wz);
        Self([a.x, a.y, a.z, w.x, w.y, w.z])
    }

    /// The specific force, g.
    #[must_use]
    pub fn specific_force_g(&self) -> Vector3<f64> {
        Vector3::new(self.0[0], self.0[1], self.0[2])
    }

    /// The angular rate, deg/h.
    #[must_use]
    pub fn rate_deg_per_h(&self) -> Vector3<f64> {
        Vector3::new(self.0[3], self.0[4], self.0[5])
    }

    /// From a specific force (g) and a rate already in deg/h.
    #[must_use]
    pub fn new(specific_force_g: &Vector3<f64>, rate_deg_per_h: &Vector3<f64>) -> Self {
        let (a, w) = (specific_force_g, rate_deg_per_h);
        Self([a.x, a.y, a.z, w.x, w.y, w.z])
    }
}

/// A regressor: $1$ or a monomial $\prod_j u_j^{p_j}$ of the inputs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Regressor {
    powers: [u8; 6],
}

/// Largest total degree of a regressor.
pub const MAX_REGRESSOR_DEGREE: u32 = 6;

impl Regressor {
    /// The constant regressor $1$ (a bias).
    pub const ONE: Regressor = Regressor { powers: [0; 6] };

    /// A single input.
    #[must_use]
    pub fn input(u: Input) -> Self {
        let mut powers = [0; 6];
        powers[u.index()] = 1;
        Self { powers }
    }

    /// The product of two regressors.
    #[must_use]
    pub fn times(self, other: Regressor) -> Self {
        let mut powers = self.powers;
        for (p, q) in powers.iter_mut().zip(other.powers) {
            *p = p.saturating_add(q);
        }
        Self { powers }
    }

    /// Parse `1`, `a_x`, `a_x*a_y`, `a_z^2`, `w_x * a_y` (spaces allowed; `^` with a positive
    /// integer power).
    ///
    /// # Errors
    /// A reason naming the unknown symbol or the malformed factor, and the total degree
    /// limit ([`MAX_REGRESSOR_DEGREE`]).
    pub fn parse(s: &str) -> Result<Self, String> {
        let t = s.trim();
        if t == "1" {
            return Ok(Self::ONE);
        }
        if t.is_empty() {
            return Err("an empty regressor; write `1` for a constant term".into());
        }
        let mut r = Self::ONE;
        for factor in t.split('*') {
            let f = factor.trim();
            let (sym, power) = match f.split_once('^') {
                Some((sym, p)) => {
                    let p: u8 = p.trim().parse().ok().filter(|&p| p >= 1).ok_or_else(|| {
                        format!("`{f}`: the power after `^` must be a positive integer")
                    })?;
                    (sym.trim(), p)
                }
                None => (f, 1),
            };
            let u = Input::ALL.into_iter().find(|u| u.symbol() == sym).ok_or_else(|| {
                if sym == "1" {
                    "`1` cannot be a factor of a product".to_string()
                } else {
                    format!(
                        "unknown input symbol `{sym}`; expected 1, a_x, a_y, a_z, w_x, w_y or w_z"
                    )
                }
            })?;
            r.powers[u.index()] = r.powers[u.index()].saturating_add(power);
        }
        if r.degree() > MAX_REGRESSOR_DEGREE {
            return Err(format!(
                "total degree {} is above the limit of {MAX_REGRESSOR_DEGREE}",
                r.degree()
            ));
        }
        Ok(r)
    }

    /// Total degree (0 for the constant).
    #[must_use]
    pub fn degree(&self) -> u32 {
        self.powers.iter().map(|&p| u32::from(p)).sum()
    }

    /// The power of one input.
    #[must_use]
    pub fn power(&self, u: Input) -> u8 {
        self.powers[u.index()]
    }

    /// Whether the regressor involves an angular rate.
    #[must_use]
    pub fn involves_rate(&self) -> bool {
        self.powers[3..].iter().any(|&p| p > 0)
    }

    /// Value at `v`.
    #[must_use]
    #[inline]
    pub fn eval(&self, v: &InputValues) -> f64 {
        let mut out = 1.0;
        for (&p, &x) in self.powers.iter().zip(&v.0) {
            match p {
                0 => {}
                1 => out *= x,
                2 => out *= x * x,
                p => out *= x.powi(i32::from(p)),
            }
        }
        out
    }

    /// The gradient with respect to the six inputs at `v` (in regressor units per input unit).
    #[must_use]
    pub fn gradient(&self, v: &InputValues) -> [f64; 6] {
        std::array::from_fn(|j| {
            let p = self.powers[j];
            if p == 0 {
                return 0.0;
            }
            let mut out = f64::from(p);
            for (k, (q, x)) in self.powers.iter().zip(v.0).enumerate() {
                let e = if k == j { q - 1 } else { *q };
                for _ in 0..e {
                    out *= x;
                }
            }
            out
        })
    }

    /// A rigorous bound on the second-order remainder
    /// $|r(u + d) - r(u) - \nabla r(u)\cdot d|$ over all $|u_j| \le M_j$, $|d_j| \le D_j$: the
    /// sum of the absolute terms of degree two and more in $d$ of the expanded product,
    /// $\prod_j (M_j + D_j)^{p_j} - \prod_j M_j^{p_j} - \sum_j p_j D_j M_j^{p_j-1}\prod_{k\ne j} M_k^{p_k}$.
    #[must_use]
    pub fn remainder_bound(&self, m: &[f64; 6], d: &[f64; 6]) -> f64 {
        let mono = |x: &[f64; 6]| -> f64 {
            self.powers
                .iter()
                .zip(x)
                .map(|(&p, &v)| v.powi(i32::from(p)))
                .product()
        };
        let plus: [f64; 6] = std::array::from_fn(|j| m[j] + d[j]);
        let first: f64 = (0..6)
            .map(|j| {
                let p = self.powers[j];
                if p == 0 {
                    0.0
                } else {
                    f64::from(p)
                        * d[j]
                        * (0..6)
                            .map(|k| {
                                let e = if k == j { p - 1 } else { self.powers[k] };
                                m[k].powi(i32::from(e))
                            })
                            .product::<f64>()
                }
            })
            .sum();
        (mono(&plus) - mono(m) - first).max(0.0)
    }

    /// Its unit as a product of input units (`1`, `g`, `g^2`, `deg/h*g`, ...).
    #[must_use]
    pub fn unit(&self) -> String {
        let g: u32 = self.powers[..3].iter().map(|&p| u32::from(p)).sum();
        let w: u32 = self.powers[3..].iter().map(|&p| u32::from(p)).sum();
        let part = |u: &str, n: u32| match n {
            0 => None,
            1 => Some(u.to_string()),
            n => Some(format!("{u}^{n}")),
        };
        let parts: Vec<String> = [part("deg/h", w), part("g", g)]
            .into_iter()
            .flatten()
            .collect();
        if parts.is_empty() {
            "1".into()
        } else {
            parts.join("*")
        }
    }
}

impl fmt::Display for Regressor {
    /// The canonical form, parsed back by [`Regressor::parse`]: `1`, `a_x`, `a_x*a_y`, `a_z^2`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let parts: Vec<String> = Input::ALL
            .into_iter()
            .filter(|u| self.power(*u) > 0)
            .map(|u| match self.power(u) {
                1 => u.symbol().to_string(),
                p => format!("{}^{p}", u.symbol()),
            })
            .collect();
        if parts.is_empty() {
            f.write_str("1")
        } else {
            f.write_str(&parts.join("*"))
        }
    }
}

/// One term of an output: a named coefficient times a regressor.
#[derive(Debug, Clone, PartialEq)]
pub struct Term {
    /// Coefficient name (`[a-z][a-z0-9_]*`, unique in the sensor).
    pub coefficient: String,
    /// The regressor it multiplies.
    pub regressor: Regressor,
    /// Its true (nominal) value, output unit per regressor unit.
    pub value: f64,
    /// Whether it is known (not estimated).
    pub known: bool,
}

/// One output of a sensor.
#[derive(Debug, Clone, PartialEq)]
pub struct Output {
    /// Output name (`[a-z][a-z0-9_]*`, unique).
    pub name: String,
    /// Label of the output unit, printed in reports (`deg_per_h`, `g`, ...).
    pub unit: String,
    /// The calibration accuracy this output must reach ($\omega_m$), in `unit`.
    pub accuracy: f64,
    /// The terms.
    pub terms: Vec<Term>,
}

impl Output {
    /// The estimated terms (columns of $\mathbf A$), in order.
    pub fn estimated(&self) -> impl Iterator<Item = &Term> {
        self.terms.iter().filter(|t| !t.known)
    }

    /// The known terms (forming $\mathbf b_2$), in order.
    pub fn known_terms(&self) -> impl Iterator<Item = &Term> {
        self.terms.iter().filter(|t| t.known)
    }

    /// Number of estimated coefficients.
    #[must_use]
    pub fn n_estimated(&self) -> usize {
        self.estimated().count()
    }

    /// Names of the estimated coefficients, in order.
    #[must_use]
    pub fn estimated_names(&self) -> Vec<&str> {
        self.estimated().map(|t| t.coefficient.as_str()).collect()
    }

    /// The regressor row of the estimated terms at `v` (a row of $\mathbf A$).
    pub fn regressor_row(&self, v: &InputValues) -> impl Iterator<Item = f64> + '_ {
        let v = *v;
        self.estimated().map(move |t| t.regressor.eval(&v))
    }

    /// The known part $\sum_{\text{known}} \beta_t r_t$ at `v` (an entry of $\mathbf b_2$).
    #[must_use]
    pub fn known_part(&self, v: &InputValues) -> f64 {
        self.known_terms()
            .map(|t| t.value * t.regressor.eval(v))
            .sum()
    }

    /// The estimated part $\sum_{\text{estimated}} \beta_t r_t$ at `v` with the true
    /// coefficients (an entry of $\mathbf A\boldsymbol\beta$).
    #[must_use]
    pub fn estimated_part(&self, v: &InputValues) -> f64 {
        self.estimated()
            .map(|t| t.value * t.regressor.eval(v))
            .sum()
    }

    /// The output $y = \sum_t \beta_t r_t$ at `v` (eq 1 solved for the output).
    #[must_use]
    pub fn value(&self, v: &InputValues) -> f64 {
        self.terms
            .iter()
            .map(|t| t.value * t.regressor.eval(v))
            .sum()
    }

    /// The true values of the estimated coefficients, in order.
    #[must_use]
    pub fn estimated_values(&self) -> Vec<f64> {
        self.estimated().map(|t| t.value).collect()
    }

    /// The unit of an estimated coefficient: output unit per regressor unit.
    #[must_use]
    pub fn coefficient_unit(&self, t: &Term) -> String {
        match t.regressor.unit().as_str() {
            "1" => self.unit.clone(),
            r => format!("{}/({r})", self.unit),
        }
    }
}

/// A validated sensor: one or more outputs.
#[derive(Debug, Clone, PartialEq)]
pub struct SensorModel {
    outputs: Vec<Output>,
}

impl SensorModel {
    /// Validate a sensor description.
    ///
    /// # Errors
    /// [`ModelError::Sensor`] naming the key (`outputs[1].name`,
    /// `outputs[0].terms[2].coefficient`, `outputs[0].accuracy`) and the reason: no output, an
    /// invalid or duplicate output or coefficient name (coefficient names are unique across
    /// the sensor), a non-finite value, a non-positive accuracy, an output without an
    /// estimated term, or an output with two estimated terms of one regressor (a known term
    /// may share its regressor with an estimated one: a known input plus an estimated
    /// scale-factor error).
    pub fn new(outputs: Vec<Output>) -> Result<Self, ModelError> {
        let err = |key: String, reason: String| ModelError::Sensor { key, reason };
        if outputs.is_empty() {
            return Err(err(
                "outputs".into(),
                "a sensor needs at least one output".into(),
            ));
        }
        let mut output_names = std::collections::BTreeMap::new();
        let mut coefficients = std::collections::BTreeMap::new();
        for (k, o) in outputs.iter().enumerate() {
            let key = |s: &str| format!("outputs[{k}].{s}");
            if !valid_name(&o.name) {
                return Err(err(
                    key("name"),
                    format!(
                        "`{}` is not a valid name (lower-case letter, then lower-case letters, digits or `_`)",
                        o.name
                    ),
                ));
            }
            if let Some(first) = output_names.insert(o.name.clone(), k) {
                return Err(err(
                    key("name"),
                    format!("`{}` is already the name of outputs[{first}]", o.name),
                ));
            }
            if o.unit.trim().is_empty() {
                return Err(err(key("unit"), "must not be empty".into()));
            }
            positive(key("accuracy"), o.accuracy).map_err(|_| {
                err(
                    key("accuracy"),
                    format!("must be positive and finite, found {}", o.accuracy),
                )
            })?;
            if o.terms.is_empty() {
                return Err(err(
                    key("terms"),
                    "an output needs at least one term".into(),
                ));
            }
            for (t, term) in o.terms.iter().enumerate() {
                let tkey = |s: &str| format!("outputs[{k}].terms[{t}].{s}");
                if !valid_name(&term.coefficient) {
                    return Err(err(
                        tkey("coefficient"),
                        format!("`{}` is not a valid name", term.coefficient),
                    ));
                }
                if let Some((ko, kt)) = coefficients.insert(term.coefficient.clone(), (k, t)) {
                    return Err(err(
                        tkey("coefficient"),
                        format!(
                            "`{}` is already the coefficient of outputs[{ko}].terms[{kt}]",
                            term.coefficient
                        ),
                    ));
                }
                finite(tkey("value"), term.value).map_err(|_| {
                    err(
                        tkey("value"),
                        format!("must be finite, found {}", term.value),
                    )
                })?;
            }
            if o.n_estimated() == 0 {
                return Err(err(
                    key("terms"),
                    "no estimated term: mark at least one term `known = false`".into(),
                ));
            }
            // Two estimated coefficients of one regressor are two equal columns of A: they
            // cannot be told apart. A known term only shifts the measurement (b2), so a known
            // input term and an estimated scale-factor error on one regressor are fine.
            for (t, term) in o.terms.iter().enumerate().filter(|(_, x)| !x.known) {
                if let Some((u, other)) = o.terms[..t]
                    .iter()
                    .enumerate()
                    .find(|(_, x)| !x.known && x.regressor == term.regressor)
                {
                    return Err(err(
                        format!("outputs[{k}].terms[{t}].regressor"),
                        format!(
                            "`{}` is already the regressor of the estimated terms[{u}] (`{}`): two estimated coefficients of one regressor cannot be told apart (mark one `known = true`, or merge them)",
                            term.regressor, other.coefficient
                        ),
                    ));
                }
            }
        }
        Ok(Self { outputs })
    }

    /// The outputs.
    #[must_use]
    pub fn outputs(&self) -> &[Output] {
        &self.outputs
    }

    /// Number of outputs.
    #[must_use]
    pub fn n_outputs(&self) -> usize {
        self.outputs.len()
    }

    /// The output called `name`.
    #[must_use]
    pub fn output(&self, name: &str) -> Option<&Output> {
        self.outputs.iter().find(|o| o.name == name)
    }

    /// Every estimated coefficient as `(output index, term)`, in study order.
    pub fn estimated_terms(&self) -> impl Iterator<Item = (usize, &Term)> {
        self.outputs
            .iter()
            .enumerate()
            .flat_map(|(k, o)| o.estimated().map(move |t| (k, t)))
    }

    /// The same sensor with every accuracy multiplied by `factor` (> 0).
    ///
    /// # Errors
    /// [`ModelError::Field`] (not positive) naming `factor`.
    pub fn with_accuracy_scaled(&self, factor: f64) -> Result<Self, ModelError> {
        positive("factor", factor)?;
        let mut outputs = self.outputs.clone();
        for o in &mut outputs {
            o.accuracy *= factor;
        }
        Self::new(outputs)
    }
}

fn valid_name(name: &str) -> bool {
    let mut chars = name.chars();
    matches!(chars.next(), Some('a'..='z'))
        && chars.all(|c| matches!(c, 'a'..='z' | '0'..='9' | '_'))
}
