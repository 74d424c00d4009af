//! A Monte Carlo built from any orientation-error model: no turntable demanded, the model
//! itself evaluated on the same draws as a turntable's run.

mod common;

use common::{config, fingerprint, paper_table, table4, three_axis, three_axis_box};
use mc_verify::{ErrorBox, McError, MonteCarlo};
use tt_kinematics::TurntableErrors;
use tt_kinematics::{ExactChain, KinematicsError, OrientationError, OrientationErrorModel, Pose};

#[test]
fn a_model_built_monte_carlo_evaluates_the_model_on_the_turntables_draws() {
    for (t, b) in [(paper_table(), table4()), (three_axis(), three_axis_box())] {
        let table_mc = MonteCarlo::new(&t, b.clone(), config(5_000, 7)).unwrap();
        // the same box by names, the same histogram range: the model's run is the plain
        // chain's run on the turntable's Monte Carlo, bit for bit
        let mut cfg = config(5_000, 7);
        cfg.histogram_half_range_rad = Some(table_mc.half_range_rad());
        let named =
            ErrorBox::with_names(b.names().to_vec(), b.lb_rad().to_vec(), b.ub_rad().to_vec())
                .unwrap();
        let model_mc =
            MonteCarlo::for_model(ExactChain::new(&t), t.joint_ranges_rad(), named, cfg).unwrap();
        assert!(model_mc.turntable().is_none());
        let want = table_mc.run_model(&ExactChain::new(&t)).unwrap();
        let got = model_mc.try_run().unwrap();
        assert_eq!(fingerprint(&got), fingerprint(&want));
        assert_eq!(fingerprint(&model_mc.run()), fingerprint(&want));
    }
}

#[test]
fn a_models_default_histogram_range_comes_from_its_own_first_order() {
    let t = paper_table();
    let b = table4();
    let named =
        ErrorBox::with_names(b.names().to_vec(), b.lb_rad().to_vec(), b.ub_rad().to_vec()).unwrap();
    let mc = MonteCarlo::for_model(
        ExactChain::new(&t),
        t.joint_ranges_rad(),
        named,
        config(20_000, 3),
    )
    .unwrap();
    let table_h = MonteCarlo::histogram_half_range_rad(&t, &b).unwrap();
    let s = b.sum_ub_rad();
    let r = mc.try_run().unwrap();
    for (k, th) in table_h.iter().enumerate() {
        let h = mc.half_range_rad()[k];
        // the grid contains the paper table's worst poses (multiples of 45 deg), so the
        // estimate is the certified worst case times 1.05 plus the same remainder
        let first = th - (s.exp_m1() - s);
        approx::assert_relative_eq!(h, 1.05 * first + (s.exp_m1() - s), max_relative = 1e-12);
        assert_eq!(
            r.axes()[k].histogram().overflow() + r.axes()[k].histogram().underflow(),
            0
        );
    }
}

/// A model that rejects every pose.
struct Refuses;

impl OrientationErrorModel for Refuses {
    fn error_names(&self) -> Vec<String> {
        vec!["a".into()]
    }
    fn orientation_error(
        &self,
        _pose: &Pose,
        _errors: &TurntableErrors,
    ) -> Result<OrientationError, KinematicsError> {
        Err(tt_core::FieldError::OutOfRange {
            field: "pose".into(),
            value: 0.0,
            range: "none".into(),
        }
        .into())
    }
}

#[test]
fn a_failing_model_is_a_typed_error_naming_the_sample_and_bad_ranges_are_refused() {
    let named = ErrorBox::with_names(vec!["a".into()], vec![0.0], vec![1e-4]).unwrap();
    let mut cfg = config(100, 1);
    cfg.histogram_half_range_rad = Some([1.0; 3]);
    let mc = MonteCarlo::for_model(Refuses, vec![[0.0, 1.0]], named.clone(), cfg).unwrap();
    assert!(matches!(
        mc.try_run(),
        Err(McError::Model { sample: 0, .. })
    ));
    // without a given range the estimate evaluates the model's first order: refused there
    assert!(matches!(
        MonteCarlo::for_model(Refuses, vec![[0.0, 1.0]], named.clone(), config(100, 1)),
        Err(McError::Model { .. })
    ));
    let e = MonteCarlo::for_model(Refuses, vec![[1.0, 0.0]], named, config(100, 1)).unwrap_err();
    assert!(e.to_string().contains("joint_ranges[0]"), "{e}");
}

/// A box of the wrong size for the model (the paper's 8 errors for the three-axis table's
/// 13): a typed error naming both sizes and the model's errors, never an index out of
/// bounds (it panicked in the histogram-range estimate before the model owned its count).
#[test]
fn a_box_of_the_wrong_size_is_a_typed_error_naming_both_sizes_not_a_panic() {
    let t = three_axis();
    let b = table4();
    let named =
        ErrorBox::with_names(b.names().to_vec(), b.lb_rad().to_vec(), b.ub_rad().to_vec()).unwrap();
    let e = MonteCarlo::for_model(
        ExactChain::new(&t),
        t.joint_ranges_rad(),
        named.clone(),
        config(100, 1),
    )
    .unwrap_err();
    assert_eq!(
        e,
        McError::ModelErrorCount {
            expected: 13,
            found: 8,
            names: t.rotation_error_names().join(", "),
        }
    );
    let text = e.to_string();
    assert!(text.contains("13") && text.contains("has 8"), "{text}");
    // the right count with other names: the first differing name
    let renamed = ErrorBox::with_names(
        (0..8).map(|j| format!("e{j}")).collect(),
        vec![0.0; 8],
        b.ub_rad().to_vec(),
    )
    .unwrap();
    let e = MonteCarlo::for_model(
        ExactChain::new(&paper_table()),
        paper_table().joint_ranges_rad(),
        renamed,
        config(100, 1),
    )
    .unwrap_err();
    assert!(
        matches!(e, McError::BoundsForAnotherTurntable { position: 0, .. }),
        "{e}"
    );
}
