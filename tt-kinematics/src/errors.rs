//! The turntable error vector $\chi$ (Table 2, eq 25) and the intersection error $\Delta\eta$.

use crate::error::{KinematicsError, finite};
use crate::units::{RAD_PER_ARCMIN, RAD_PER_ARCSEC, RAD_PER_DEG};
use nalgebra::SVector;

/// Number of angular error components in $\chi$ (eq 25).
pub const CHI_LEN: usize = 8;

/// One angular error component of a two-axis turntable (Table 2), in the order of $\chi$ (eq 25).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ErrorComponent {
    /// $\Delta\phi_{y1}$: position error of the outer axis (about $y$).
    DphiY1,
    /// $\Delta\phi_{z2}$: position error of the inner axis (about $z$).
    DphiZ2,
    /// $\Delta\alpha_{x1}$: wobble of the outer axis about $x$.
    DalphaX1,
    /// $\Delta\alpha_{z1}$: wobble of the outer axis about $z$.
    DalphaZ1,
    /// $\Delta\alpha_{x2}$: wobble of the inner axis about $x$.
    DalphaX2,
    /// $\Delta\alpha_{y2}$: wobble of the inner axis about $y$.
    DalphaY2,
    /// $\Delta\varepsilon_x$: orthogonality error between the axes, about $x$.
    DepsX,
    /// $\Delta\varepsilon_y$: orthogonality error between the axes, about $y$.
    DepsY,
}

impl ErrorComponent {
    /// All components in the order of $\chi$ (eq 25).
    pub const ALL: [ErrorComponent; CHI_LEN] = [
        ErrorComponent::DphiY1,
        ErrorComponent::DphiZ2,
        ErrorComponent::DalphaX1,
        ErrorComponent::DalphaZ1,
        ErrorComponent::DalphaX2,
        ErrorComponent::DalphaY2,
        ErrorComponent::DepsX,
        ErrorComponent::DepsY,
    ];

    /// Position of this component in $\chi$ (0-based).
    #[must_use]
    pub fn index(self) -> usize {
        self as usize
    }

    /// The snake_case name used in files and on the command line (`dphi_y1`, ..., `deps_y`).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            ErrorComponent::DphiY1 => "dphi_y1",
            ErrorComponent::DphiZ2 => "dphi_z2",
            ErrorComponent::DalphaX1 => "dalpha_x1",
            ErrorComponent::DalphaZ1 => "dalpha_z1",
            ErrorComponent::DalphaX2 => "dalpha_x2",
            ErrorComponent::DalphaY2 => "dalpha_y2",
            ErrorComponent::DepsX => "deps_x",
            ErrorComponent::DepsY => "deps_y",
        }
    }

    /// The component with this snake_case name, if any.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.name() == name)
    }

    /// Table 2's definition of the component.
    #[must_use]
    pub fn definition(self) -> &'static str {
        match self {
            ErrorComponent::DphiY1 => "position error of outer axis",
            ErrorComponent::DphiZ2 => "position error of inner axis",
            ErrorComponent::DalphaX1 => "wobble error of outer axis about x",
            ErrorComponent::DalphaZ1 => "wobble error of outer axis about z",
            ErrorComponent::DalphaX2 => "wobble error of inner axis about x",
            ErrorComponent::DalphaY2 => "wobble error of inner axis about y",
            ErrorComponent::DepsX => "orthogonality error about x",
            ErrorComponent::DepsY => "orthogonality error about y",
        }
    }
}

/// The geometric errors of a two-axis turntable: the angular vector $\chi$ of eq 25 (radians)
/// and the intersection error $\Delta\eta$ (metres, a translation along $x$ in eq 18).
///
/// $$\chi = [\Delta\phi_{y1}\ \Delta\phi_{z2}\ \Delta\alpha_{x1}\ \Delta\alpha_{z1}\
///   \Delta\alpha_{x2}\ \Delta\alpha_{y2}\ \Delta\varepsilon_x\ \Delta\varepsilon_y]^T.$$
///
/// Invariant: every value is finite (checked by the constructors).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TurntableErrors {
    chi_rad: [f64; CHI_LEN],
    deta_m: f64,
}

impl TurntableErrors {
    /// No error at all.
    pub const ZERO: TurntableErrors = TurntableErrors {
        chi_rad: [0.0; CHI_LEN],
        deta_m: 0.0,
    };

    /// From $\chi$ in radians (order of eq 25) and $\Delta\eta$ in metres.
    pub fn from_rad(chi_rad: [f64; CHI_LEN], deta_m: f64) -> Result<Self, KinematicsError> {
        for c in ErrorComponent::ALL {
            finite(c.name(), chi_rad[c.index()])?;
        }
        Ok(Self {
            chi_rad,
            deta_m: finite("deta", deta_m)?,
        })
    }

    fn scaled(chi: [f64; CHI_LEN], scale: f64, deta_m: f64) -> Result<Self, KinematicsError> {
        for c in ErrorComponent::ALL {
            finite(c.name(), chi[c.index()])?;
        }
        Self::from_rad(chi.map(|x| x * scale), deta_m)
    }

    /// From $\chi$ in arcminutes (the unit of Table 4) and $\Delta\eta$ in metres.
    pub fn from_arcmin(chi_arcmin: [f64; CHI_LEN], deta_m: f64) -> Result<Self, KinematicsError> {
        Self::scaled(chi_arcmin, RAD_PER_ARCMIN, deta_m)
    }

    /// From $\chi$ in arcseconds and $\Delta\eta$ in metres.
    pub fn from_arcsec(chi_arcsec: [f64; CHI_LEN], deta_m: f64) -> Result<Self, KinematicsError> {
        Self::scaled(chi_arcsec, RAD_PER_ARCSEC, deta_m)
    }

    /// From $\chi$ in degrees and $\Delta\eta$ in metres.
    pub fn from_deg(chi_deg: [f64; CHI_LEN], deta_m: f64) -> Result<Self, KinematicsError> {
        Self::scaled(chi_deg, RAD_PER_DEG, deta_m)
    }

    /// $\chi$ in radians, order of eq 25.
    #[must_use]
    pub fn chi_rad(&self) -> [f64; CHI_LEN] {
        self.chi_rad
    }

    /// $\chi$ as a column vector (radians).
    #[must_use]
    pub fn chi_vector(&self) -> SVector<f64, CHI_LEN> {
        SVector::from(self.chi_rad)
    }

    /// One component of $\chi$, radians.
    #[must_use]
    pub fn get(&self, c: ErrorComponent) -> f64 {
        self.chi_rad[c.index()]
    }

    /// The intersection error $\Delta\eta$, metres.
    #[must_use]
    pub fn deta_m(&self) -> f64 {
        self.deta_m
    }

    /// The same errors with one component replaced (radians); rejects a non-finite value.
    pub fn with(self, c: ErrorComponent, value_rad: f64) -> Result<Self, KinematicsError> {
        let mut chi = self.chi_rad;
        chi[c.index()] = finite(c.name(), value_rad)?;
        Ok(Self {
            chi_rad: chi,
            ..self
        })
    }

    /// The same angular errors with another intersection error (metres).
    pub fn with_deta_m(self, deta_m: f64) -> Result<Self, KinematicsError> {
        Ok(Self {
            deta_m: finite("deta", deta_m)?,
            ..self
        })
    }

    /// $\max_i |\chi_i|$, radians.
    #[must_use]
    pub fn max_abs_rad(&self) -> f64 {
        self.chi_rad.iter().fold(0.0_f64, |m, x| m.max(x.abs()))
    }
}
