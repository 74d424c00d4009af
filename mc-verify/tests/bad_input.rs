//! Bad input gets a typed error naming the field, never a panic.

mod common;

use common::table4;
use mc_verify::{BoundKind, ErrorBox, MAX_HISTOGRAM_BINS, McConfig, McError, MonteCarlo};
use tt_kinematics::{OrientationError, OrientationErrorModel, Pose, TurntableErrors};

#[test]
fn zero_samples_is_rejected() {
    let e = MonteCarlo::new(table4(), McConfig::new(0, 1)).unwrap_err();
    assert_eq!(e, McError::ZeroSamples);
    assert!(e.to_string().contains("samples"));
}

#[test]
fn zero_chunk_size_is_rejected() {
    let mut cfg = McConfig::new(10, 1);
    cfg.chunk_size = 0;
    let e = MonteCarlo::new(table4(), cfg).unwrap_err();
    assert_eq!(e, McError::ZeroChunkSize);
    assert!(e.to_string().contains("chunk_size"));
}

#[test]
fn lower_bound_above_upper_bound_names_the_component() {
    let mut lb = [0.0; 8];
    lb[3] = 0.9;
    let e = ErrorBox::from_arcmin(lb, [0.5; 8]).unwrap_err();
    assert!(
        matches!(
            e,
            McError::LowerAboveUpper {
                component: "dalpha_z1",
                ..
            }
        ),
        "{e:?}"
    );
    assert!(e.to_string().contains("dalpha_z1"));
}

#[test]
fn negative_bounds_name_component_and_kind() {
    let mut ub = [1e-4; 8];
    ub[5] = -1e-4;
    let e = ErrorBox::from_upper_rad(ub).unwrap_err();
    assert!(
        matches!(
            e,
            McError::NegativeBound {
                component: "dalpha_y2",
                kind: BoundKind::Upper,
                ..
            }
        ),
        "{e:?}"
    );
    let mut lb = [0.0; 8];
    lb[0] = -1e-5;
    let e = ErrorBox::new(lb, [1e-4; 8]).unwrap_err();
    assert!(matches!(
        e,
        McError::NegativeBound {
            component: "dphi_y1",
            kind: BoundKind::Lower,
            ..
        }
    ));
    assert!(e.to_string().contains("LB of dphi_y1"));
}

#[test]
fn non_finite_bounds_name_component_and_kind() {
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let mut ub = [1e-4; 8];
        ub[7] = bad;
        let e = ErrorBox::from_upper_rad(ub).unwrap_err();
        assert!(
            matches!(
                e,
                McError::NonFiniteBound {
                    component: "deps_y",
                    kind: BoundKind::Upper,
                    ..
                }
            ),
            "{e:?}"
        );
        let mut lb = [0.0; 8];
        lb[2] = bad;
        let e = ErrorBox::from_arcmin(lb, [1.0; 8]).unwrap_err();
        assert!(matches!(
            e,
            McError::NonFiniteBound {
                component: "dalpha_x1",
                kind: BoundKind::Lower,
                ..
            }
        ));
    }
}

#[test]
fn bad_requirement_histogram_bins_and_range_are_rejected() {
    for bad in [0.0, -1e-4, f64::NAN, f64::INFINITY] {
        let mut cfg = McConfig::new(10, 1);
        cfg.requirement_rad[1] = bad;
        let e = MonteCarlo::new(table4(), cfg).unwrap_err();
        assert!(
            matches!(e, McError::Requirement { axis: "theta", .. }),
            "{e:?}"
        );

        let mut cfg = McConfig::new(10, 1);
        cfg.histogram_half_range_rad = Some([1e-3, 1e-3, bad]);
        let e = MonteCarlo::new(table4(), cfg).unwrap_err();
        assert!(
            matches!(e, McError::HistogramRange { axis: "gamma", .. }),
            "{e:?}"
        );
    }
    for bins in [0, MAX_HISTOGRAM_BINS + 1] {
        let mut cfg = McConfig::new(10, 1);
        cfg.histogram_bins = bins;
        let e = MonteCarlo::new(table4(), cfg).unwrap_err();
        assert_eq!(
            e,
            McError::HistogramBins {
                bins,
                max: MAX_HISTOGRAM_BINS
            }
        );
    }
}

/// A model that fails at one pose.
struct NanAbovePi;

impl OrientationErrorModel for NanAbovePi {
    fn orientation_error(&self, pose: &Pose, _errors: &TurntableErrors) -> OrientationError {
        let v = if pose.phi2_rad > 3.0 { f64::NAN } else { 0.0 };
        OrientationError::from_array([0.0, 0.0, v])
    }
}

#[test]
fn non_finite_model_output_is_an_error_naming_the_sample_and_axis() {
    let mc = MonteCarlo::new(table4(), McConfig::new(1_000, 1)).unwrap();
    let e = mc.run_model(&NanAbovePi).unwrap_err();
    let McError::NonFiniteModelOutput {
        sample,
        axis,
        value,
    } = e
    else {
        panic!("{e:?}")
    };
    assert_eq!(axis, "gamma");
    assert!(value.is_nan());
    assert!(sample < 1_000);
}

/// A histogram range the caller chose too small: values land in the overflow counts, not
/// out of bounds.
#[test]
fn values_outside_a_caller_histogram_range_are_counted_not_lost() {
    let mut cfg = McConfig::new(10_000, 1);
    cfg.histogram_half_range_rad = Some([1e-6; 3]);
    let r = MonteCarlo::new(table4(), cfg).unwrap().run();
    for a in &r.axes {
        assert!(a.histogram.underflow > 0 && a.histogram.overflow > 0);
        assert_eq!(a.histogram.total(), 10_000);
    }
}
