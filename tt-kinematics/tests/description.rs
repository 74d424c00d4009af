//! Strict validation of turntable descriptions: every bad description is a typed error naming
//! the key and the reason.

mod common;

use common::three_axis_description;
use tt_kinematics::{FactorSpec, KinematicsError, SignedAxis, Turntable, TurntableDescription};

fn key_of(d: &TurntableDescription) -> (String, String) {
    match Turntable::new(d).unwrap_err() {
        KinematicsError::Description { key, reason } => (key, reason),
        other => panic!("not a description error: {other}"),
    }
}

#[test]
fn bad_descriptions_name_the_key_and_the_reason() {
    let mut d = three_axis_description();
    d.factors[3] = FactorSpec::Error {
        name: "dphi_o".into(),
        about: SignedAxis::X,
    };
    let (key, reason) = key_of(&d);
    assert_eq!(key, "factors[3].error");
    assert!(
        reason.contains("already the name of factors[1]"),
        "{reason}"
    );

    let mut d = three_axis_description();
    d.factors[0] = FactorSpec::Joint {
        name: "Phi".into(),
        about: SignedAxis::Z,
    };
    assert_eq!(key_of(&d).0, "factors[0].joint");

    let d = TurntableDescription::new(vec![FactorSpec::Error {
        name: "e".into(),
        about: SignedAxis::X,
    }]);
    assert!(key_of(&d).1.contains("at least one joint"));

    let d = TurntableDescription::new(vec![]);
    assert_eq!(key_of(&d).0, "factors");

    let mut d = three_axis_description();
    d.factors.push(FactorSpec::Fixed {
        angle_rad: f64::NAN,
        about: SignedAxis::X,
    });
    assert_eq!(
        key_of(&d).0,
        format!("factors[{}].fixed_deg", d.factors.len() - 1)
    );

    let mut d = three_axis_description();
    d.joint_ranges_rad = vec![("phi_m".into(), [1.0, 1.0])];
    let (key, reason) = key_of(&d);
    assert_eq!(key, "joint_ranges_deg.phi_m");
    assert!(reason.contains("min must be below max"), "{reason}");

    let mut d = three_axis_description();
    d.joint_ranges_rad = vec![("dphi_o".into(), [0.0, 1.0])];
    assert!(key_of(&d).1.contains("not a joint"));

    let mut d = three_axis_description();
    d.joint_ranges_rad = vec![("phi_o".into(), [0.0, 7.0])];
    assert!(key_of(&d).1.contains("at most one turn"));

    let mut d = three_axis_description();
    d.descriptions = vec![("nope".into(), "x".into())];
    assert_eq!(key_of(&d).0, "descriptions.nope");
}

#[test]
fn error_order_must_be_a_permutation_of_the_errors() {
    let t = Turntable::new(&three_axis_description()).unwrap();
    let all: Vec<String> = t
        .rotation_error_names()
        .into_iter()
        .chain(t.translation_error_names())
        .map(String::from)
        .collect();

    let mut d = three_axis_description();
    let mut order = all.clone();
    order.reverse();
    d.error_order = Some(order.clone());
    let rev = Turntable::new(&d).unwrap();
    assert_eq!(rev.rotation_error_names()[0], "dalpha_iz");

    let mut d = three_axis_description();
    d.error_order = Some(all[1..].to_vec());
    let (key, reason) = key_of(&d);
    assert_eq!(key, "error_order");
    assert!(reason.contains("missing: dphi_o"), "{reason}");

    let mut d = three_axis_description();
    let mut twice = all.clone();
    twice[1] = twice[0].clone();
    d.error_order = Some(twice);
    assert_eq!(key_of(&d).0, "error_order[1]");

    let mut d = three_axis_description();
    let mut joint = all.clone();
    joint[0] = "phi_o".into();
    d.error_order = Some(joint);
    assert!(key_of(&d).1.contains("is a joint"));
}

#[test]
fn signed_axes_parse_and_negative_axes_turn_the_other_way() {
    assert_eq!(
        SignedAxis::parse("-y"),
        Some(SignedAxis {
            axis: tt_kinematics::Axis::Y,
            negative: true
        })
    );
    assert_eq!(SignedAxis::parse("w"), None);
    assert_eq!(SignedAxis::parse("--x"), None);
    // a joint about -z by a is the joint about z by -a
    let mk = |about| {
        Turntable::new(&TurntableDescription::new(vec![
            FactorSpec::Error {
                name: "e".into(),
                about: SignedAxis::X,
            },
            FactorSpec::Joint {
                name: "j".into(),
                about,
            },
            FactorSpec::Error {
                name: "f".into(),
                about: SignedAxis::Y,
            },
        ]))
        .unwrap()
    };
    let pos = mk(SignedAxis::Z);
    let neg = mk(SignedAxis::parse("-z").unwrap());
    let chi = tt_kinematics::TurntableErrors::new(vec![1e-3, 2e-3], vec![]).unwrap();
    let a = pos
        .delta_r(
            &tt_kinematics::Pose::new(vec![0.7]).unwrap(),
            &chi,
            tt_kinematics::ChainKind::Exact,
        )
        .unwrap();
    let b = neg
        .delta_r(
            &tt_kinematics::Pose::new(vec![-0.7]).unwrap(),
            &chi,
            tt_kinematics::ChainKind::Exact,
        )
        .unwrap();
    assert!((a - b).amax() <= 1e-15);
}
