//! Study files: every input of the analysis in one strict TOML file (`studies/*.toml`).
//!
//! Parsing is strict: an unknown key, a missing key, a value of the wrong type or a
//! non-finite number is an [`InputError`] naming the file, the key and the reason (exit code
//! 2). Units are part of the key names (`latitude_deg`, `earth_rate_rad_per_s`, ...), so a value
//! in another unit needs another key and is rejected as unknown.

use crate::InputError;
use calib_lsq::{Reading, RequirementProblem, Schedule};
use gw_model::{DeltaRKind, DriftCoefficients, Site};
use serde::Deserialize;
use std::path::{Path, PathBuf};
use tt_kinematics::units::{arcmin_to_rad, deg_to_rad};
use tt_kinematics::{CHI_LEN, ErrorComponent};

/// The paper's study, relative to the repository root.
pub const PAPER_STUDY: &str = "studies/gyrowheel-2017.toml";

/// The repository root (xtask lives one level below it).
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf)
}

/// The default study file path.
pub fn paper_study_path() -> PathBuf {
    repo_root().join(PAPER_STUDY)
}

/// x-axis drift coefficients of eq 1 (Table 1 units).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct XAxis {
    /// D(x)_F, deg/h.
    pub d_f_deg_per_h: f64,
    /// D(x)_x, deg/h/g.
    pub d_x_deg_per_h_per_g: f64,
    /// D(x)_y, deg/h/g.
    pub d_y_deg_per_h_per_g: f64,
    /// D(x)_z, deg/h/g.
    pub d_z_deg_per_h_per_g: f64,
    /// D(x)_xx, deg/h/g^2.
    pub d_xx_deg_per_h_per_g2: f64,
    /// D(x)_zz, deg/h/g^2.
    pub d_zz_deg_per_h_per_g2: f64,
    /// D(x)_xy, deg/h/g^2.
    pub d_xy_deg_per_h_per_g2: f64,
}

/// y-axis drift coefficients of eq 1 (Table 1 units).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct YAxis {
    /// D(y)_F, deg/h.
    pub d_f_deg_per_h: f64,
    /// D(y)_x, deg/h/g.
    pub d_x_deg_per_h_per_g: f64,
    /// D(y)_y, deg/h/g.
    pub d_y_deg_per_h_per_g: f64,
    /// D(y)_z, deg/h/g.
    pub d_z_deg_per_h_per_g: f64,
    /// D(y)_yy, deg/h/g^2.
    pub d_yy_deg_per_h_per_g2: f64,
    /// D(y)_zz, deg/h/g^2.
    pub d_zz_deg_per_h_per_g2: f64,
    /// D(y)_yx, deg/h/g^2 (printed D(y)_xy in Table 1).
    pub d_yx_deg_per_h_per_g2: f64,
}

/// Key names of `[sensor.x_axis]`, in the order of eq 1.
const SENSOR_X_KEYS: [&str; 7] = [
    "d_f_deg_per_h",
    "d_x_deg_per_h_per_g",
    "d_y_deg_per_h_per_g",
    "d_z_deg_per_h_per_g",
    "d_xx_deg_per_h_per_g2",
    "d_zz_deg_per_h_per_g2",
    "d_xy_deg_per_h_per_g2",
];

/// Key names of `[sensor.y_axis]`, in the order of eq 1.
const SENSOR_Y_KEYS: [&str; 7] = [
    "d_f_deg_per_h",
    "d_x_deg_per_h_per_g",
    "d_y_deg_per_h_per_g",
    "d_z_deg_per_h_per_g",
    "d_yy_deg_per_h_per_g2",
    "d_zz_deg_per_h_per_g2",
    "d_yx_deg_per_h_per_g2",
];

/// `[sensor]`: Table 1.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sensor {
    /// x-axis coefficients.
    pub x_axis: XAxis,
    /// y-axis coefficients.
    pub y_axis: YAxis,
}

impl Sensor {
    /// Both axes' coefficients as written, in the order of eq 1 (F, x, y, z, then the
    /// g^2 terms), deg/h, deg/h/g, deg/h/g^2.
    pub fn table1_deg_per_h(&self) -> [[f64; 7]; 2] {
        let (x, y) = (&self.x_axis, &self.y_axis);
        [
            [
                x.d_f_deg_per_h,
                x.d_x_deg_per_h_per_g,
                x.d_y_deg_per_h_per_g,
                x.d_z_deg_per_h_per_g,
                x.d_xx_deg_per_h_per_g2,
                x.d_zz_deg_per_h_per_g2,
                x.d_xy_deg_per_h_per_g2,
            ],
            [
                y.d_f_deg_per_h,
                y.d_x_deg_per_h_per_g,
                y.d_y_deg_per_h_per_g,
                y.d_z_deg_per_h_per_g,
                y.d_yy_deg_per_h_per_g2,
                y.d_zz_deg_per_h_per_g2,
                y.d_yx_deg_per_h_per_g2,
            ],
        ]
    }
}

/// `[site]`: eq 3 inputs.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SiteSection {
    /// Latitude, degrees north.
    pub latitude_deg: f64,
    /// Earth rotation rate, rad/s.
    pub earth_rate_rad_per_s: f64,
}

/// `[calibration]`: eq 2-14 inputs.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrationSection {
    /// omega_m, deg/h.
    pub rate_accuracy_deg_per_h: f64,
    /// Reading of eq 13, `outputs/estimate/form`.
    pub reading: String,
    /// Orientation-error matrix of eq 7: `small-angle` or `exact`.
    pub delta_r: String,
    /// Test positions `[phi1_deg, phi2_deg]`.
    pub positions_deg: Vec<[f64; 2]>,
}

/// `[requirement]`: the orientation requirement handed to the allocation.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RequirementSection {
    /// I_psi, deg.
    pub psi_deg: f64,
    /// I_theta, deg.
    pub theta_deg: f64,
    /// I_gamma, deg.
    pub gamma_deg: f64,
}

/// One value per turntable error component, arcmin.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ComponentsArcmin {
    /// dphi_y1.
    pub dphi_y1: f64,
    /// dphi_z2.
    pub dphi_z2: f64,
    /// dalpha_x1.
    pub dalpha_x1: f64,
    /// dalpha_z1.
    pub dalpha_z1: f64,
    /// dalpha_x2.
    pub dalpha_x2: f64,
    /// dalpha_y2.
    pub dalpha_y2: f64,
    /// deps_x.
    pub deps_x: f64,
    /// deps_y.
    pub deps_y: f64,
}

impl ComponentsArcmin {
    /// In the order of chi (eq 25).
    pub fn to_array(&self) -> [f64; CHI_LEN] {
        [
            self.dphi_y1,
            self.dphi_z2,
            self.dalpha_x1,
            self.dalpha_z1,
            self.dalpha_x2,
            self.dalpha_y2,
            self.deps_x,
            self.deps_y,
        ]
    }
}

/// `[allocation]`: eq 29-34 inputs.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AllocationSection {
    /// LB_i, arcmin.
    pub lower_bounds_arcmin: ComponentsArcmin,
}

/// `[monte_carlo]`: §4.3.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MonteCarloSection {
    /// Number of random turntables.
    pub samples: u64,
    /// Seed of the random streams.
    pub seed: u64,
}

/// A whole study file, as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StudyFile {
    /// A short name printed in reports.
    pub name: String,
    /// Table 1.
    pub sensor: Sensor,
    /// Site.
    pub site: SiteSection,
    /// Calibration.
    pub calibration: CalibrationSection,
    /// Requirement handed to the allocation.
    pub requirement: RequirementSection,
    /// Allocation.
    pub allocation: AllocationSection,
    /// Monte Carlo.
    pub monte_carlo: MonteCarloSection,
}

/// A validated study: the file as written plus the library values built from it.
#[derive(Debug, Clone)]
pub struct Study {
    /// Where it was read from.
    pub path: PathBuf,
    /// The file as written.
    pub file: StudyFile,
    /// Table 1 as library coefficients.
    pub coefficients: DriftCoefficients,
    /// The site.
    pub site: Site,
    /// The calibration schedule.
    pub schedule: Schedule,
    /// The reading of eq 13.
    pub reading: Reading,
    /// The eq-7 matrix kind.
    pub delta_r_kind: DeltaRKind,
    /// omega_m, rad/s.
    pub omega_m_rad_per_s: f64,
    /// Requirement handed to the allocation, rad, order (psi, theta, gamma).
    pub requirement_rad: [f64; 3],
    /// Lower bounds LB_i, rad, order of eq 25.
    pub lower_bounds_rad: [f64; CHI_LEN],
}

impl Study {
    /// Read the paper's study from the repository.
    pub fn paper() -> Result<Self, InputError> {
        Self::load(&paper_study_path())
    }

    /// Read `path`, or the paper's study when `None`.
    pub fn load_or_paper(path: Option<&Path>) -> Result<Self, InputError> {
        match path {
            Some(p) => Self::load(p),
            None => Self::paper(),
        }
    }

    /// Read and validate a study file.
    pub fn load(path: &Path) -> Result<Self, InputError> {
        let shown = path.display().to_string();
        let text = std::fs::read_to_string(path)
            .map_err(|e| InputError::new(&shown, format!("cannot read study file: {e}")))?;
        Self::parse(&shown, &text).map(|mut s| {
            s.path = path.to_path_buf();
            s
        })
    }

    /// Parse and validate study text; `source` names it in errors.
    pub fn parse(source: &str, text: &str) -> Result<Self, InputError> {
        let file: StudyFile = toml::from_str(text).map_err(|e| {
            InputError::new(source, format!("invalid study: {}", e.to_string().trim()))
        })?;
        let at = |key: &str| format!("{source}: key `{key}`");
        // Every number finite, by key.
        let lb = file.allocation.lower_bounds_arcmin.to_array();
        let mut numbers: Vec<(String, f64)> = Vec::new();
        for ((axis, keys), values) in [("x_axis", SENSOR_X_KEYS), ("y_axis", SENSOR_Y_KEYS)]
            .into_iter()
            .zip(file.sensor.table1_deg_per_h())
        {
            for (key, v) in keys.iter().zip(values) {
                numbers.push((format!("sensor.{axis}.{key}"), v));
            }
        }
        numbers.extend([
            ("site.latitude_deg".into(), file.site.latitude_deg),
            (
                "site.earth_rate_rad_per_s".into(),
                file.site.earth_rate_rad_per_s,
            ),
            (
                "calibration.rate_accuracy_deg_per_h".into(),
                file.calibration.rate_accuracy_deg_per_h,
            ),
            ("requirement.psi_deg".into(), file.requirement.psi_deg),
            ("requirement.theta_deg".into(), file.requirement.theta_deg),
            ("requirement.gamma_deg".into(), file.requirement.gamma_deg),
        ]);
        for c in ErrorComponent::ALL {
            numbers.push((
                format!("allocation.lower_bounds_arcmin.{}", c.name()),
                lb[c.index()],
            ));
        }
        for (i, p) in file.calibration.positions_deg.iter().enumerate() {
            numbers.push((format!("calibration.positions_deg[{i}][0]"), p[0]));
            numbers.push((format!("calibration.positions_deg[{i}][1]"), p[1]));
        }
        for (key, v) in &numbers {
            if !v.is_finite() {
                return Err(InputError::new(
                    at(key),
                    format!("must be finite, found {v}"),
                ));
            }
        }
        let positive = |key: &str, v: f64| {
            if v > 0.0 {
                Ok(v)
            } else {
                Err(InputError::new(
                    at(key),
                    format!("must be positive, found {v}"),
                ))
            }
        };
        positive(
            "calibration.rate_accuracy_deg_per_h",
            file.calibration.rate_accuracy_deg_per_h,
        )?;
        positive("requirement.psi_deg", file.requirement.psi_deg)?;
        positive("requirement.theta_deg", file.requirement.theta_deg)?;
        positive("requirement.gamma_deg", file.requirement.gamma_deg)?;
        if file.monte_carlo.samples == 0 {
            return Err(InputError::new(
                at("monte_carlo.samples"),
                "must be at least 1, found 0",
            ));
        }
        for c in ErrorComponent::ALL {
            let v = lb[c.index()];
            if v < 0.0 {
                return Err(InputError::new(
                    at(&format!("allocation.lower_bounds_arcmin.{}", c.name())),
                    format!("a lower bound on |chi_i| must be >= 0, found {v}"),
                ));
            }
        }
        let [table1_x, table1_y] = file.sensor.table1_deg_per_h();
        let coefficients = DriftCoefficients::from_deg_per_h(table1_x, table1_y)
            .map_err(|e| InputError::new(at("sensor"), e.to_string()))?;
        let site = Site::from_deg(file.site.latitude_deg, file.site.earth_rate_rad_per_s)
            .map_err(|e| InputError::new(at("site"), e.to_string()))?;
        let pairs: Vec<(f64, f64)> = file
            .calibration
            .positions_deg
            .iter()
            .map(|p| (p[0], p[1]))
            .collect();
        let schedule = Schedule::from_deg(&pairs)
            .map_err(|e| InputError::new(at("calibration.positions_deg"), e.to_string()))?;
        let reading: Reading =
            file.calibration
                .reading
                .parse()
                .map_err(|e: calib_lsq::CalibError| {
                    InputError::new(at("calibration.reading"), e.to_string())
                })?;
        let delta_r_kind = match file.calibration.delta_r.as_str() {
            "small-angle" => DeltaRKind::SmallAngle,
            "exact" => DeltaRKind::Exact,
            other => {
                return Err(InputError::new(
                    at("calibration.delta_r"),
                    format!("must be \"small-angle\" or \"exact\", found \"{other}\""),
                ));
            }
        };
        let omega_m_rad_per_s =
            gw_model::units::deg_per_h_to_rad_per_s(file.calibration.rate_accuracy_deg_per_h);
        let requirement_rad = [
            deg_to_rad(file.requirement.psi_deg),
            deg_to_rad(file.requirement.theta_deg),
            deg_to_rad(file.requirement.gamma_deg),
        ];
        let lower_bounds_rad = lb.map(arcmin_to_rad);
        Ok(Self {
            path: PathBuf::from(source),
            file,
            coefficients,
            site,
            schedule,
            reading,
            delta_r_kind,
            omega_m_rad_per_s,
            requirement_rad,
            lower_bounds_rad,
        })
    }

    /// The calibration requirement problem (eq 15-16) of this study.
    pub fn requirement_problem(&self) -> RequirementProblem {
        RequirementProblem {
            coefficients: self.coefficients,
            site: self.site,
            schedule: self.schedule.clone(),
            omega_m_rad_per_s: self.omega_m_rad_per_s,
            reading: self.reading,
            delta_r_kind: self.delta_r_kind,
        }
    }
}
