//! Orientation-error models that are linear in $\chi$ with coefficients that are first
//! harmonics of the inner-axis angle $\phi_2$, such as the closed form of eq 26.
//!
//! Every first-order model of a two-axis turntable has this shape: $\phi_1$ cancels in
//! $\mathbf R_d^T\mathbf R_t$ and $\phi_2$ enters only through $R_z(\mp\phi_2)$, so
//!
//! $$f_k(\phi_2, \chi) = \sum_{i=1}^{8} \big(a_{ki}\cos\phi_2 + b_{ki}\sin\phi_2 + c_{ki}\big)\,\chi_i,
//! \qquad k \in \{\psi, \theta, \gamma\}.$$
//!
//! Because each coefficient is a sinusoid plus a constant, the worst case over the pose of a
//! weighted sum of coefficients can be found exactly ([`LinearModel::max_abs_weighted`]) and
//! their average magnitudes have a closed form ([`LinearModel::average_abs_coefficients`]).

use crate::error::{KinematicsError, finite};
use crate::errors::{CHI_LEN, ErrorComponent, TurntableErrors};
use crate::model::OrientationError;
use nalgebra::SMatrix;
use std::f64::consts::{PI, TAU};

/// One of the three orientation-error angles, in the order of eq 24-26.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum OrientationAxis {
    /// $\Delta\psi$, rotation error about $y$.
    Psi,
    /// $\Delta\theta$, rotation error about $z$.
    Theta,
    /// $\Delta\gamma$, rotation error about $x$.
    Gamma,
}

impl OrientationAxis {
    /// All three, in the order $\psi, \theta, \gamma$.
    pub const ALL: [OrientationAxis; 3] = [
        OrientationAxis::Psi,
        OrientationAxis::Theta,
        OrientationAxis::Gamma,
    ];

    /// Row index (0, 1, 2).
    #[must_use]
    pub fn index(self) -> usize {
        self as usize
    }

    /// `"psi"`, `"theta"` or `"gamma"`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            OrientationAxis::Psi => "psi",
            OrientationAxis::Theta => "theta",
            OrientationAxis::Gamma => "gamma",
        }
    }
}

/// The worst pose of a weighted coefficient sum and its value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorstPose {
    /// The maximum value (in the unit of the weights, radians for error bounds).
    pub value: f64,
    /// An inner-axis angle $\phi_2$ (rad) where it is reached.
    pub phi2_rad: f64,
}

/// A linear orientation-error model with first-harmonic coefficients in $\phi_2$
/// (rows $\psi, \theta, \gamma$; columns the components of $\chi$ in the order of eq 25).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearModel {
    cos: SMatrix<f64, 3, CHI_LEN>,
    sin: SMatrix<f64, 3, CHI_LEN>,
    constant: SMatrix<f64, 3, CHI_LEN>,
}

impl LinearModel {
    /// A model $c_{ki}(\phi_2) = \text{cos}_{ki}\cos\phi_2 + \text{sin}_{ki}\sin\phi_2 + \text{constant}_{ki}$.
    /// Rejects non-finite coefficients.
    pub fn new(
        cos: SMatrix<f64, 3, CHI_LEN>,
        sin: SMatrix<f64, 3, CHI_LEN>,
        constant: SMatrix<f64, 3, CHI_LEN>,
    ) -> Result<Self, KinematicsError> {
        for (name, m) in [("cos", &cos), ("sin", &sin), ("constant", &constant)] {
            for v in m.iter() {
                finite(name, *v)?;
            }
        }
        Ok(Self { cos, sin, constant })
    }

    /// The closed form of eq 26 (the first-order expansion of eq 23-24 about $\chi = 0$):
    ///
    /// # Formula
    /// $$\begin{aligned}
    /// \Delta\psi &= \Delta\phi_{y1}\cos\phi_2 - \Delta\alpha_{x1}\sin\phi_2 + \Delta\alpha_{y2} -
    ///   \Delta\varepsilon_x\sin\phi_2 + \Delta\varepsilon_y\cos\phi_2,\\
    /// \Delta\theta &= \Delta\phi_{z2} + \Delta\alpha_{z1},\\
    /// \Delta\gamma &= \Delta\phi_{y1}\sin\phi_2 + \Delta\alpha_{x1}\cos\phi_2 + \Delta\alpha_{x2} +
    ///   \Delta\varepsilon_x\cos\phi_2 + \Delta\varepsilon_y\sin\phi_2.
    /// \end{aligned}$$
    ///
    /// # Reference
    /// Zhao et al. 2017, eq 26-27.
    #[must_use]
    pub fn paper_eq26() -> Self {
        use ErrorComponent as C;
        use OrientationAxis as A;
        let mut cos = SMatrix::zeros();
        let mut sin = SMatrix::zeros();
        let mut constant = SMatrix::zeros();
        let set = |m: &mut SMatrix<f64, 3, CHI_LEN>, a: A, c: C, v: f64| {
            m[(a.index(), c.index())] = v;
        };
        // delta_psi
        set(&mut cos, A::Psi, C::DphiY1, 1.0);
        set(&mut sin, A::Psi, C::DalphaX1, -1.0);
        set(&mut constant, A::Psi, C::DalphaY2, 1.0);
        set(&mut sin, A::Psi, C::DepsX, -1.0);
        set(&mut cos, A::Psi, C::DepsY, 1.0);
        // delta_theta
        set(&mut constant, A::Theta, C::DphiZ2, 1.0);
        set(&mut constant, A::Theta, C::DalphaZ1, 1.0);
        // delta_gamma
        set(&mut sin, A::Gamma, C::DphiY1, 1.0);
        set(&mut cos, A::Gamma, C::DalphaX1, 1.0);
        set(&mut constant, A::Gamma, C::DalphaX2, 1.0);
        set(&mut cos, A::Gamma, C::DepsX, 1.0);
        set(&mut sin, A::Gamma, C::DepsY, 1.0);
        Self { cos, sin, constant }
    }

    /// The harmonic parts $(a, b, c)$ of one coefficient.
    #[must_use]
    pub fn harmonics(&self, axis: OrientationAxis, c: ErrorComponent) -> (f64, f64, f64) {
        let ij = (axis.index(), c.index());
        (self.cos[ij], self.sin[ij], self.constant[ij])
    }

    /// $\partial f_k / \partial \chi_i$ at inner-axis angle `phi2_rad`.
    #[must_use]
    pub fn coefficient(&self, axis: OrientationAxis, c: ErrorComponent, phi2_rad: f64) -> f64 {
        let (a, b, k) = self.harmonics(axis, c);
        let (s, co) = phi2_rad.sin_cos();
        a * co + b * s + k
    }

    /// The 3x8 coefficient (Jacobian) matrix at inner-axis angle `phi2_rad`.
    #[must_use]
    pub fn coefficients(&self, phi2_rad: f64) -> SMatrix<f64, 3, CHI_LEN> {
        let (s, c) = phi2_rad.sin_cos();
        self.cos * c + self.sin * s + self.constant
    }

    /// $f(\phi_2, \chi)$ for all three angles.
    #[must_use]
    pub fn evaluate(&self, phi2_rad: f64, errors: &TurntableErrors) -> OrientationError {
        let v = self.coefficients(phi2_rad) * errors.chi_vector();
        OrientationError::from_array([v[0], v[1], v[2]])
    }

    /// The components an angle depends on (coefficient not identically zero): $\chi_\psi$,
    /// $\chi_\theta$, $\chi_\gamma$ of eq 27 for [`LinearModel::paper_eq26`].
    #[must_use]
    pub fn involved(&self, axis: OrientationAxis) -> Vec<ErrorComponent> {
        ErrorComponent::ALL
            .into_iter()
            .filter(|&c| {
                let (a, b, k) = self.harmonics(axis, c);
                a != 0.0 || b != 0.0 || k != 0.0
            })
            .collect()
    }

    /// Average of $|\partial f_k/\partial\chi_i|$ over $\phi_2 \in [0, 2\pi)$ (and over
    /// $\phi_1$, on which it does not depend): the sensitivities of eq 28 averaged over the
    /// rotation angles, the data of Figure 8.
    ///
    /// # Formula
    /// With $R = \sqrt{a^2+b^2}$, the mean of $|R\cos u + c|$ over a period is $|c|$ if
    /// $|c| \ge R$ and $\tfrac{2}{\pi}\big(\sqrt{R^2-c^2} + c\arcsin(c/R)\big)$ otherwise;
    /// for eq 26 this is $2/\pi$ for every $\sin\phi_2$/$\cos\phi_2$ term and 1 for a constant.
    #[must_use]
    pub fn average_abs_coefficients(&self) -> SMatrix<f64, 3, CHI_LEN> {
        SMatrix::from_fn(|i, j| {
            let (a, b, c) = (self.cos[(i, j)], self.sin[(i, j)], self.constant[(i, j)]);
            let r = a.hypot(b);
            if c.abs() >= r {
                c.abs()
            } else {
                2.0 / PI * ((r * r - c * c).sqrt() + c * (c / r).asin())
            }
        })
    }

    /// $\max_{\phi_2 \in [\text{lo}, \text{hi}]} \sum_i w_i\,|c_{ki}(\phi_2)|$, found exactly.
    ///
    /// With $w = \mathrm{UB}$ this is the worst case of $|f_k|$ over all $\chi$ with
    /// $|\chi_i| \le \mathrm{UB}_i$ (signs chosen adversarially) and all poses in the range:
    /// the quantity Lemma 1 bounds. The function is a sinusoid plus a constant between the
    /// zero crossings of the coefficients, so its maximum is at a crossing, an end of the range,
    /// or a stationary point $\operatorname{atan2}(B, A)$ of one piece.
    #[must_use]
    pub fn max_abs_weighted(
        &self,
        axis: OrientationAxis,
        weights: &[f64; CHI_LEN],
        lo_rad: f64,
        hi_rad: f64,
    ) -> WorstPose {
        self.max_piecewise(axis, weights, true, lo_rad, hi_rad)
    }

    /// $\max_{\phi_2 \in [\text{lo}, \text{hi}]} \sum_i x_i\,c_{ki}(\phi_2)$ (no absolute values),
    /// found exactly: the left side of the constraints of problems (31)-(33).
    #[must_use]
    pub fn max_signed_weighted(
        &self,
        axis: OrientationAxis,
        x: &[f64; CHI_LEN],
        lo_rad: f64,
        hi_rad: f64,
    ) -> WorstPose {
        self.max_piecewise(axis, x, false, lo_rad, hi_rad)
    }

    fn weighted_value(
        &self,
        axis: OrientationAxis,
        w: &[f64; CHI_LEN],
        abs: bool,
        phi: f64,
    ) -> f64 {
        ErrorComponent::ALL
            .into_iter()
            .map(|c| {
                let v = self.coefficient(axis, c, phi);
                w[c.index()] * if abs { v.abs() } else { v }
            })
            .sum()
    }

    fn max_piecewise(
        &self,
        axis: OrientationAxis,
        w: &[f64; CHI_LEN],
        abs: bool,
        lo: f64,
        hi: f64,
    ) -> WorstPose {
        let (lo, hi) = if lo <= hi { (lo, hi) } else { (hi, lo) };
        let mut cuts = vec![lo, hi];
        if abs {
            for c in ErrorComponent::ALL {
                let (a, b, k) = self.harmonics(axis, c);
                let r = a.hypot(b);
                if w[c.index()] == 0.0 || r == 0.0 || k.abs() > r {
                    continue;
                }
                let delta = b.atan2(a);
                let half = (-k / r).clamp(-1.0, 1.0).acos();
                for base in [delta + half, delta - half] {
                    push_periodic(&mut cuts, base, lo, hi);
                }
            }
        }
        cuts.sort_by(f64::total_cmp);
        let mut best = WorstPose {
            value: f64::NEG_INFINITY,
            phi2_rad: lo,
        };
        let consider = |phi: f64, best: &mut WorstPose| {
            let v = self.weighted_value(axis, w, abs, phi);
            if v > best.value {
                *best = WorstPose {
                    value: v,
                    phi2_rad: phi,
                };
            }
        };
        for pair in cuts.windows(2) {
            let (p, q) = (pair[0], pair[1]);
            consider(p, &mut best);
            consider(q, &mut best);
            if q <= p {
                continue;
            }
            // One smooth piece: sum_i s_i w_i (a_i cos + b_i sin + k_i) = A cos + B sin + C.
            let mid = 0.5 * (p + q);
            let (mut big_a, mut big_b) = (0.0, 0.0);
            for c in ErrorComponent::ALL {
                let (a, b, _) = self.harmonics(axis, c);
                let s = if abs {
                    self.coefficient(axis, c, mid).signum()
                } else {
                    1.0
                };
                big_a += s * w[c.index()] * a;
                big_b += s * w[c.index()] * b;
            }
            if big_a != 0.0 || big_b != 0.0 {
                let mut stationary = Vec::new();
                push_periodic(&mut stationary, big_b.atan2(big_a), p, q);
                for phi in stationary {
                    consider(phi, &mut best);
                }
            }
        }
        best
    }
}

/// Push every `base + 2 pi k` that lies in `[lo, hi]`.
fn push_periodic(out: &mut Vec<f64>, base: f64, lo: f64, hi: f64) {
    let k0 = ((lo - base) / TAU).ceil();
    let mut phi = base + k0 * TAU;
    while phi <= hi {
        if phi >= lo {
            out.push(phi);
        }
        phi += TAU;
    }
}
