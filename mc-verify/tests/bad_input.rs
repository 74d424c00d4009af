//! Bad input gets a typed error naming the field (angular errors by their name in the
//! turntable), never a panic.

mod common;

use common::{config, paper_table, table4, theta_only_run, three_axis, three_axis_box};
use mc_verify::{BoundKind, ErrorBox, MAX_HISTOGRAM_BINS, McError, MonteCarlo};
use tt_core::Requirement;
use tt_kinematics::{
    ExactChain, KinematicsError, OrientationError, OrientationErrorModel, Pose, TurntableErrors,
};

#[test]
fn zero_samples_is_rejected() {
    let e = MonteCarlo::new(&paper_table(), table4(), config(0, 1)).unwrap_err();
    assert_eq!(e, McError::ZeroSamples);
    assert!(e.to_string().contains("samples"));
}

#[test]
fn zero_chunk_size_is_rejected() {
    let mut cfg = config(10, 1);
    cfg.chunk_size = 0;
    let e = MonteCarlo::new(&paper_table(), table4(), cfg).unwrap_err();
    assert_eq!(e, McError::ZeroChunkSize);
    assert!(e.to_string().contains("chunk_size"));
}

#[test]
fn lower_bound_above_upper_bound_names_the_component() {
    let mut lb = vec![0.0; 8];
    lb[3] = 0.9;
    let e = ErrorBox::from_arcmin(&paper_table(), lb, vec![0.5; 8]).unwrap_err();
    assert!(
        matches!(&e, McError::LowerAboveUpper { component, .. } if component == "dalpha_z1"),
        "{e:?}"
    );
    assert!(e.to_string().contains("dalpha_z1"));
    // the three-axis table names its own errors
    let mut lb = vec![0.0; 13];
    lb[11] = 2.0;
    let e = ErrorBox::from_arcmin(&three_axis(), lb, vec![1.0; 13]).unwrap_err();
    assert!(
        e.to_string()
            .contains("LB of dalpha_ix (2) exceeds its UB (1)"),
        "{e}"
    );
}

#[test]
fn negative_bounds_name_component_and_kind() {
    let mut ub = vec![1e-4; 8];
    ub[5] = -1e-4;
    let e = ErrorBox::from_upper_rad(&paper_table(), ub).unwrap_err();
    assert!(
        matches!(
            &e,
            McError::NegativeBound { component, kind: BoundKind::Upper, .. } if component == "dalpha_y2"
        ),
        "{e:?}"
    );
    let mut lb = vec![0.0; 8];
    lb[0] = -1e-5;
    let e = ErrorBox::new(&paper_table(), lb, vec![1e-4; 8]).unwrap_err();
    assert!(matches!(
        &e,
        McError::NegativeBound { component, kind: BoundKind::Lower, .. } if component == "dphi_y1"
    ));
    assert!(e.to_string().contains("LB of dphi_y1"));
}

#[test]
fn non_finite_bounds_name_component_and_kind() {
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let mut ub = vec![1e-4; 8];
        ub[7] = bad;
        let e = ErrorBox::from_upper_rad(&paper_table(), ub).unwrap_err();
        assert!(
            matches!(
                &e,
                McError::NonFiniteBound { component, kind: BoundKind::Upper, .. } if component == "deps_y"
            ),
            "{e:?}"
        );
        let mut lb = vec![0.0; 13];
        lb[2] = bad;
        let e = ErrorBox::from_arcmin(&three_axis(), lb, vec![1.0; 13]).unwrap_err();
        assert!(matches!(
            &e,
            McError::NonFiniteBound { component, kind: BoundKind::Lower, .. } if component == "dalpha_oy"
        ));
    }
}

#[test]
fn bounds_of_the_wrong_length_are_rejected() {
    let e = ErrorBox::from_upper_rad(&paper_table(), vec![1e-4; 9]).unwrap_err();
    assert_eq!(
        e,
        McError::BoundsLength {
            kind: BoundKind::Lower,
            expected: 8,
            found: 9
        }
    );
    let e = ErrorBox::new(&three_axis(), vec![0.0; 13], vec![1e-4; 12]).unwrap_err();
    assert_eq!(
        e,
        McError::BoundsLength {
            kind: BoundKind::Upper,
            expected: 13,
            found: 12
        }
    );
    assert!(
        e.to_string()
            .contains("UB needs one value per angular error")
    );
}

/// A box made for one turntable cannot be verified on another.
#[test]
fn bounds_of_another_turntable_are_rejected() {
    let e = MonteCarlo::new(&paper_table(), three_axis_box(), config(10, 1)).unwrap_err();
    assert_eq!(
        e,
        McError::BoundsForAnotherTurntable {
            position: 0,
            expected: "dphi_y1".into(),
            found: "dphi_o".into()
        }
    );
    let e = MonteCarlo::histogram_half_range_rad(&three_axis(), &table4()).unwrap_err();
    assert!(matches!(e, McError::BoundsForAnotherTurntable { .. }));
}

#[test]
fn bad_requirement_histogram_bins_and_range_are_rejected() {
    // the smallest normal number as a half-range would give an infinite inverse bin width
    for bad in [f64::MIN_POSITIVE, 1e-307] {
        let mut cfg = config(10, 1);
        cfg.histogram_half_range_rad = Some([bad, 1e-3, 1e-3]);
        let e = MonteCarlo::new(&paper_table(), table4(), cfg).unwrap_err();
        assert!(
            matches!(e, McError::HistogramRange { axis: "psi", .. }),
            "{e:?}"
        );
    }
    for bad in [0.0, -1e-4, f64::NAN, f64::INFINITY] {
        // a requirement is checked where it is made (the configuration cannot hold a bad one)
        let e = Requirement::from_options([None, Some(bad), None]).unwrap_err();
        assert_eq!(e.field(), "requirement.theta", "{e:?}");

        let mut cfg = config(10, 1);
        cfg.histogram_half_range_rad = Some([1e-3, 1e-3, bad]);
        let e = MonteCarlo::new(&paper_table(), table4(), cfg).unwrap_err();
        assert!(
            matches!(e, McError::HistogramRange { axis: "gamma", .. }),
            "{e:?}"
        );
    }
    for bins in [0, MAX_HISTOGRAM_BINS + 1] {
        let mut cfg = config(10, 1);
        cfg.histogram_bins = bins;
        let e = MonteCarlo::new(&paper_table(), table4(), cfg).unwrap_err();
        assert_eq!(
            e,
            McError::HistogramBins {
                bins,
                max: MAX_HISTOGRAM_BINS
            }
        );
    }
}

/// A model that returns NaN at some poses.
struct NanAbovePi;

impl OrientationErrorModel for NanAbovePi {
    fn error_names(&self) -> Vec<String> {
        table4().names().to_vec()
    }
    fn orientation_error(
        &self,
        pose: &Pose,
        _errors: &TurntableErrors,
    ) -> Result<OrientationError, KinematicsError> {
        let v = if pose.angles_rad()[1] > 3.0 {
            f64::NAN
        } else {
            0.0
        };
        Ok(OrientationError::from_array([0.0, 0.0, v]))
    }
}

#[test]
fn non_finite_model_output_is_an_error_naming_the_sample_and_axis() {
    let mc = MonteCarlo::new(&paper_table(), table4(), config(1_000, 1)).unwrap();
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

/// A model of another turntable (13 errors against the paper's box of 8) is refused before
/// any sample: a typed error naming both sizes.
#[test]
fn a_model_of_another_error_count_is_a_typed_error_naming_both_sizes() {
    let mc = MonteCarlo::new(&paper_table(), table4(), config(1_000, 1)).unwrap();
    let e = mc.run_model(&ExactChain::new(&three_axis())).unwrap_err();
    let McError::ModelErrorCount {
        expected, found, ..
    } = &e
    else {
        panic!("{e}")
    };
    assert_eq!((*expected, *found), (13, 8));
    assert!(
        e.to_string().contains("13") && e.to_string().contains('8'),
        "{e}"
    );
}

/// A histogram range the caller chose too small: values land in the overflow counts, not
/// out of bounds.
#[test]
fn values_outside_a_caller_histogram_range_are_counted_not_lost() {
    let mut cfg = config(10_000, 1);
    cfg.histogram_half_range_rad = Some([1e-6; 3]);
    let r = MonteCarlo::new(&paper_table(), table4(), cfg)
        .unwrap()
        .run();
    for a in r.axes() {
        assert!(a.histogram().underflow() > 0 && a.histogram().overflow() > 0);
        assert_eq!(a.histogram().total(), 10_000);
    }
}

/// Requirements are optional per angle: `None` counts every sample as within.
#[test]
fn an_angle_without_requirement_counts_every_sample_as_within() {
    let r = theta_only_run();
    let within = r.count().meeting_per_output();
    assert_eq!(within[0], 20_000);
    assert_eq!(within[2], 20_000);
    assert!(within[1] < 20_000);
    assert_eq!(r.count().meeting(), within[1]);
    assert_eq!(r.requirement().to_array(), [None, Some(1e-4), None]);
}

/// Huge and degenerate boxes still give finite results (no NaN reaches a result): errors of
/// up to 3 rad (the histogram range is then capped at the rotation-matrix bound), a box of
/// zero width, and one sample.
#[test]
fn extreme_boxes_give_finite_results_and_keep_every_sample_in_the_histogram() {
    let t = paper_table();
    let boxes = [
        ErrorBox::from_upper_rad(&t, vec![3.0; 8]).unwrap(),
        ErrorBox::new(&t, vec![1.0; 8], vec![1.0; 8]).unwrap(),
        ErrorBox::from_upper_rad(&t, vec![0.0; 8]).unwrap(),
        ErrorBox::from_upper_rad(&t, vec![1e300; 8]).unwrap(),
    ];
    for b in boxes {
        for samples in [1, 5_000] {
            let mc = MonteCarlo::new(&t, b.clone(), config(samples, 9)).unwrap();
            let h = mc.half_range_rad();
            assert!(h.iter().all(|h| h.is_finite() && *h > 0.0), "{h:?}");
            for r in [mc.run(), mc.run_model(&ExactChain::new(&t)).unwrap()] {
                for (a, std) in r.axes().iter().zip(r.std_rad()) {
                    assert!(a.max_abs_rad().is_finite() && a.mean_rad().is_finite());
                    assert!(a.m2_rad2().is_finite() && std.is_finite());
                    assert!(a.worst().chi_rad().iter().all(|x| x.is_finite()));
                    assert_eq!(
                        a.histogram().underflow() + a.histogram().overflow(),
                        0,
                        "UB {:e}, {samples} samples: max {:e}, H {:e}",
                        b.ub_rad()[0],
                        a.max_abs_rad(),
                        a.histogram().hi()
                    );
                    assert_eq!(a.histogram().total(), samples);
                }
                assert!(r.count().fraction().is_finite());
            }
        }
    }
}
