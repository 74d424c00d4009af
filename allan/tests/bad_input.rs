//! Bad inputs: a typed error naming the field or the sample, never a panic, never an empty
//! result, never a NaN.

use allan::{AllanError, Settings, StreamingAllan};

#[test]
fn non_finite_samples_are_refused_with_their_index() {
    let mut a = StreamingAllan::new(Settings::new(10.0)).unwrap();
    a.extend(&[1.0, 2.0, 3.0]).unwrap();
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let e = a.push(bad).unwrap_err();
        assert!(
            matches!(e, AllanError::NonFiniteSample { index: 3, .. }),
            "{e:?}"
        );
        assert!(e.to_string().starts_with("sample 3:"), "{e}");
    }
    // a slice: the index counts every sample before it; nothing of the slice is added
    let e = a.extend(&[4.0, 5.0, f64::NAN, 6.0]).unwrap_err();
    assert!(
        matches!(e, AllanError::NonFiniteSample { index: 5, .. }),
        "{e:?}"
    );
    assert_eq!(a.samples(), 3);
    a.push(4.0).unwrap();
    assert_eq!(a.samples(), 4);
}

#[test]
fn a_rate_that_is_not_positive_and_finite_is_refused() {
    for rate in [0.0, -1.0, -0.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let e = StreamingAllan::new(Settings::new(rate)).unwrap_err();
        assert!(matches!(e, AllanError::InvalidRate { .. }), "{rate}: {e:?}");
        assert!(e.to_string().starts_with("rate_hz:"), "{e}");
    }
    assert!(StreamingAllan::new(Settings::new(1e-9)).is_ok());
}

#[test]
fn settings_out_of_range_are_refused_naming_them() {
    for c in [0.0, 1.0, -0.5, 1.5, f64::NAN] {
        let e = StreamingAllan::new(Settings::new(1.0).confidence(c)).unwrap_err();
        assert!(
            matches!(
                e,
                AllanError::InvalidSetting {
                    field: "confidence",
                    ..
                }
            ),
            "{c}: {e:?}"
        );
    }
    for r in [0u64, 3, 100, 1 << 17] {
        let e = StreamingAllan::new(Settings::new(1.0).overlap(r)).unwrap_err();
        assert!(
            matches!(
                e,
                AllanError::InvalidSetting {
                    field: "overlap",
                    ..
                }
            ),
            "{r}: {e:?}"
        );
    }
}

/// Fewer than three samples (the shortest cluster, one sample, needs three clusters): a
/// clear error, never an empty curve; three samples give one point.
#[test]
fn too_few_samples_is_an_error_not_an_empty_result() {
    for n in 0..3u64 {
        let mut a = StreamingAllan::new(Settings::new(1.0)).unwrap();
        for i in 0..n {
            a.push(i as f64).unwrap();
        }
        let e = a.analyse().unwrap_err();
        assert_eq!(
            e,
            AllanError::TooFewSamples {
                samples: n,
                needed: 3
            }
        );
        assert!(e.to_string().contains("at least 3"), "{e}");
    }
    let r = allan::analyse(&[1.0, -1.0, 1.0], Settings::new(1.0)).unwrap();
    assert_eq!(r.points().len(), 1);
    assert!(r.points()[0].adev() > 0.0 && r.points()[0].upper().is_finite());
}

/// Samples so large that their squares overflow: an error naming the cluster time, no
/// infinity in a result.
#[test]
fn overflowing_samples_are_an_error() {
    let y: Vec<f64> = (0..100)
        .map(|i| if i % 2 == 0 { 1e300 } else { -1e300 })
        .collect();
    let e = allan::analyse(&y, Settings::new(1.0)).unwrap_err();
    assert!(matches!(e, AllanError::Overflow { .. }), "{e:?}");
}

/// A constant log has a zero curve and zero noise, no NaN anywhere.
#[test]
fn a_constant_log_gives_zeros_not_nan() {
    let r = allan::analyse(&[4.2; 1000], Settings::new(1.0)).unwrap();
    for p in r.points() {
        assert_eq!((p.adev(), p.lower(), p.upper()), (0.0, 0.0, 0.0));
        assert!(p.edf().is_finite() && p.edf() > 0.0);
    }
    assert_eq!(r.fit().white_noise().to_bits(), 0.0f64.to_bits());
    assert_eq!(r.fit().bias_instability().to_bits(), 0.0f64.to_bits());
    assert!(r.fit().white_noise_uncertainty().is_none());
}
