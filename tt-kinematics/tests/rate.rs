//! Rate steps: the closed-form revolution averages of `Turntable::rate_step_average` against
//! independent computations (a time-domain average over sampled angles, omega^2 r by hand).

use approx::assert_relative_eq;
use nalgebra::{Matrix3, Vector3, Vector4};
use std::f64::consts::TAU;
use tt_kinematics::{
    Axis, ChainKind, FactorSpec, Pose, RateEnvironment, RateErrorValues, RateStep,
    STANDARD_GRAVITY_M_PER_S2, SignedAxis, Turntable, TurntableDescription, TurntableErrors,
};

/// Agreement of the closed form with the sampled time average (relative, the 1e-9).
const TIME_DOMAIN_REL: f64 = 1e-9;
/// Rounding of a handful of 3x3 products (relative).
const ROUNDING_REL: f64 = 1e-14;

/// A two-axis table with tilts, position errors and a non-intersection of its axes.
fn table() -> Turntable {
    let d = TurntableDescription::new(vec![
        FactorSpec::Error {
            name: "tilt_x".into(),
            about: SignedAxis::X,
        },
        FactorSpec::Joint {
            name: "outer".into(),
            about: SignedAxis::Y,
        },
        FactorSpec::Error {
            name: "d_outer".into(),
            about: SignedAxis::Y,
        },
        FactorSpec::Translation {
            name: "offset_x".into(),
            along: SignedAxis::X,
        },
        FactorSpec::Error {
            name: "wobble".into(),
            about: SignedAxis::X,
        },
        FactorSpec::Joint {
            name: "inner".into(),
            about: SignedAxis {
                axis: Axis::Z,
                negative: true,
            },
        },
        FactorSpec::Error {
            name: "d_inner".into(),
            about: SignedAxis::Z,
        },
        FactorSpec::Translation {
            name: "offset_y".into(),
            along: SignedAxis::Y,
        },
        FactorSpec::Error {
            name: "mount".into(),
            about: SignedAxis::X,
        },
    ]);
    Turntable::new(&d).expect("valid table")
}

fn errors() -> TurntableErrors {
    TurntableErrors::new(vec![4e-4, -7e-4, 9e-4, 3e-4, -5e-4], vec![2.5e-3, -1.5e-3])
        .expect("finite")
}

fn env(latitude_rad: f64, lever: [f64; 3]) -> RateEnvironment {
    let (s, c) = latitude_rad.sin_cos();
    RateEnvironment {
        specific_force_base_g: Vector3::z(),
        earth_rate_base_rad_per_s: 7.292_115e-5 * Vector3::new(c, 0.0, s),
        lever_arm_m: Vector3::from(lever),
    }
}

fn vee(m: &Matrix3<f64>) -> Vector3<f64> {
    Vector3::new(m[(2, 1)], m[(0, 2)], m[(1, 0)])
}

/// The time average over one revolution by sampling `n` angles: rotation and position of the
/// sensor from the turntable's own matrix chain at each angle, rates and accelerations by
/// five-point differences in the angle, every sample weighted by dt = dtheta / Omega(theta).
fn time_domain(
    t: &Turntable,
    step: &RateStep,
    e: &TurntableErrors,
    re: &RateErrorValues,
    env: &RateEnvironment,
    n: usize,
) -> (Vector3<f64>, Vector3<f64>) {
    let base = step.pose.angles_rad().to_vec();
    let at = |theta: f64| {
        let mut a = base.clone();
        a[step.joint] = theta;
        let pose = Pose::new(a).expect("finite");
        let r = t.actual_rotation(&pose, e, ChainKind::Exact).expect("ok");
        let l = env.lever_arm_m;
        let p =
            (t.actual_transform(&pose, e).expect("ok") * Vector4::new(l.x, l.y, l.z, 1.0)).xyz();
        (r, p)
    };
    let shape = |theta: f64| 1.0 + re.ripple[0] * theta.cos() + re.ripple[1] * theta.sin();
    let dshape = |theta: f64| -re.ripple[0] * theta.sin() + re.ripple[1] * theta.cos();
    let thetas: Vec<f64> = (0..n).map(|k| TAU * k as f64 / n as f64 + 0.3).collect();
    // Omega_bar such that 2 pi / (time of a revolution) = commanded (1 + accuracy)
    let mean_inverse_shape = thetas.iter().map(|&th| 1.0 / shape(th)).sum::<f64>() / n as f64;
    let omega_bar = step.rate_rad_per_s * (1.0 + re.accuracy) * mean_inverse_shape;
    let h = 1e-3;
    let (mut wsum, mut rate, mut force) = (0.0, Vector3::zeros(), Vector3::zeros());
    for &th in &thetas {
        let s: Vec<(Matrix3<f64>, Vector3<f64>)> = [-2.0, -1.0, 0.0, 1.0, 2.0]
            .iter()
            .map(|k| at(th + k * h))
            .collect();
        let (r, _) = s[2];
        let dr = (s[0].0 - s[1].0 * 8.0 + s[3].0 * 8.0 - s[4].0) / (12.0 * h);
        let dp = (s[0].1 - s[1].1 * 8.0 + s[3].1 * 8.0 - s[4].1) / (12.0 * h);
        let ddp =
            (-s[0].1 + s[1].1 * 16.0 - s[2].1 * 30.0 + s[3].1 * 16.0 - s[4].1) / (12.0 * h * h);
        let omega = omega_bar * shape(th);
        let domega = omega_bar * dshape(th);
        let w_body =
            vee(&(r.transpose() * dr)) * omega + r.transpose() * env.earth_rate_base_rad_per_s;
        let vel = dp * omega;
        let acc = ddp * omega * omega + dp * omega * domega;
        let f = r.transpose()
            * (env.specific_force_base_g
                + (acc + 2.0 * env.earth_rate_base_rad_per_s.cross(&vel))
                    / STANDARD_GRAVITY_M_PER_S2);
        let w = 1.0 / omega;
        wsum += w;
        rate += w_body * w;
        force += f * w;
    }
    (force / wsum, rate / wsum)
}

/// With every table error zero and no earth rate, the gyro sees the commanded rate exactly,
/// about the joint's nominal axis in the sensor frame.
#[test]
fn rate_step_with_zero_table_errors_gives_the_commanded_rate_exactly() {
    let t = table();
    let mut env = env(0.8, [0.0; 3]);
    env.earth_rate_base_rad_per_s = Vector3::zeros();
    for (joint, rate) in [(0, 0.7), (1, -2.3)] {
        let pose = Pose::from_deg(&[30.0, 75.0]).expect("finite");
        let step = RateStep {
            joint,
            rate_rad_per_s: rate,
            pose: pose.clone(),
            revolutions: 3,
        };
        let avg = t
            .rate_step_average(&step, &t.zero_errors(), &RateErrorValues::default(), &env)
            .expect("ok");
        // the nominal axis in the sensor frame, by hand: outer is y of the base, seen from the
        // sensor through the inner joint (-z by 75 deg); inner is -z of the platform
        let axis = if joint == 0 {
            // S = R_z(-75 deg), S^T y = R_z(75 deg) y
            let (s, c) = 75f64.to_radians().sin_cos();
            Vector3::new(-s, c, 0.0)
        } else {
            -Vector3::z()
        };
        assert_relative_eq!(
            avg.rate_rad_per_s,
            axis * rate,
            max_relative = ROUNDING_REL,
            epsilon = 1e-15
        );
    }
}

/// The centripetal term is omega^2 r: a sensor 5 cm and 2 cm off a vertical axis (30 cm up,
/// which does not count) feels (omega^2 r) / g0 towards the axis, against the same step
/// without a lever arm; r and omega^2 r computed here by hand.
#[test]
fn centripetal_term_equals_omega_squared_r() {
    let d = TurntableDescription::new(vec![FactorSpec::Joint {
        name: "phi".into(),
        about: SignedAxis::Z,
    }]);
    let t = Turntable::new(&d).expect("valid");
    let omega = 2.0 * TAU; // 2 rev/s
    let step = RateStep {
        joint: 0,
        rate_rad_per_s: omega,
        pose: Pose::from_deg(&[0.0]).expect("finite"),
        revolutions: 10,
    };
    let mut with_lever = env(0.0, [0.05, -0.02, 0.3]);
    with_lever.earth_rate_base_rad_per_s = Vector3::zeros();
    let mut without = with_lever;
    without.lever_arm_m = Vector3::zeros();
    let re = RateErrorValues::default();
    let a = t
        .rate_step_average(&step, &t.zero_errors(), &re, &with_lever)
        .expect("ok");
    let b = t
        .rate_step_average(&step, &t.zero_errors(), &re, &without)
        .expect("ok");
    let radius = (0.05f64 * 0.05 + 0.02 * 0.02).sqrt();
    let magnitude_g = omega * omega * radius / 9.806_65;
    let inward = -Vector3::new(0.05, -0.02, 0.0) / radius;
    assert_relative_eq!(
        a.specific_force_g - b.specific_force_g,
        inward * magnitude_g,
        max_relative = ROUNDING_REL,
        epsilon = 1e-15
    );
    assert_relative_eq!(b.specific_force_g, Vector3::z(), epsilon = 1e-15);
}

/// A non-intersection of the axes (a translation error) moves the accelerometers' average at
/// a rate step of the outer axis (by omega^2 times the offset) and has no effect at all on the
/// inputs at a static position (the orientation does not see a translation).
#[test]
fn non_intersection_changes_the_accelerometers_at_a_rate_step_not_at_a_static_position() {
    let t = table();
    let pose = Pose::from_deg(&[40.0, 10.0]).expect("finite");
    let e0 = TurntableErrors::new(vec![0.0; 5], vec![0.0, 0.0]).expect("finite");
    let e1 = TurntableErrors::new(vec![0.0; 5], vec![0.05, 0.0]).expect("finite");
    let env = env(0.8, [0.0; 3]);
    let step = RateStep {
        joint: 0,
        rate_rad_per_s: TAU,
        pose: pose.clone(),
        revolutions: 1,
    };
    let re = RateErrorValues::default();
    let a0 = t.rate_step_average(&step, &e0, &re, &env).expect("ok");
    let a1 = t.rate_step_average(&step, &e1, &re, &env).expect("ok");
    // the offset is along x of the frame after the outer joint, perpendicular to its y axis
    let expected = TAU * TAU * 0.05 / STANDARD_GRAVITY_M_PER_S2;
    assert_relative_eq!(
        (a1.specific_force_g - a0.specific_force_g).norm(),
        expected,
        max_relative = 1e-6 // the Coriolis part: 2 omega_e / omega of it
    );
    assert_eq!(a1.rate_rad_per_s, a0.rate_rad_per_s);
    let r0 = t.actual_rotation(&pose, &e0, ChainKind::Exact).expect("ok");
    let r1 = t.actual_rotation(&pose, &e1, ChainKind::Exact).expect("ok");
    assert_eq!(
        r0, r1,
        "a static position's inputs follow the rotation alone"
    );
}

/// The exact chain at a rate step agrees with an independent time-domain evaluation (the
/// turning table sampled at 720 angles over a revolution, each sample weighted by the time it
/// takes) to 1e-9 relative: every error, both translations, a lever arm, a rate error and a
/// ripple at once, for each joint and both directions.
#[test]
fn rate_step_closed_form_agrees_with_a_time_domain_average() {
    let t = table();
    let e = errors();
    let env = env(0.75, [0.03, -0.04, 0.12]);
    let re = RateErrorValues {
        accuracy: 3e-4,
        ripple: [2e-2, -1.5e-2],
    };
    for joint in [0, 1] {
        for rate in [1.3 * TAU, -0.4 * TAU] {
            let step = RateStep {
                joint,
                rate_rad_per_s: rate,
                pose: Pose::from_deg(&[25.0, -60.0]).expect("finite"),
                revolutions: 2,
            };
            let avg = t.rate_step_average(&step, &e, &re, &env).expect("ok");
            let (f, w) = time_domain(&t, &step, &e, &re, &env, 720);
            // relative to the vector's size (a component near zero is compared with it)
            let rel = |a: Vector3<f64>, b: Vector3<f64>| (a - b).norm() / b.norm();
            assert!(
                rel(avg.rate_rad_per_s, w) <= TIME_DOMAIN_REL,
                "{joint} {rate}: {:e}",
                rel(avg.rate_rad_per_s, w)
            );
            assert!(
                rel(avg.specific_force_g, f) <= TIME_DOMAIN_REL,
                "{joint} {rate}: {:e}",
                rel(avg.specific_force_g, f)
            );
        }
    }
}

/// Bad rate steps are refused naming the field: a zero rate, a joint that does not exist, a
/// ripple of 1 or more.
#[test]
fn rate_step_refuses_zero_rate_unknown_joint_and_full_ripple() {
    let t = table();
    let env = env(0.8, [0.0; 3]);
    let pose = Pose::from_deg(&[0.0, 0.0]).expect("finite");
    let re = RateErrorValues::default();
    let zero = RateStep {
        joint: 0,
        rate_rad_per_s: 0.0,
        pose: pose.clone(),
        revolutions: 1,
    };
    let msg = t
        .rate_step_average(&zero, &t.zero_errors(), &re, &env)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("rate_rad_per_s"), "{msg}");
    let bad = RateStep {
        joint: 2,
        rate_rad_per_s: 1.0,
        pose: pose.clone(),
        revolutions: 1,
    };
    let msg = t
        .rate_step_average(&bad, &t.zero_errors(), &re, &env)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("joint"), "{msg}");
    let ok = RateStep {
        joint: 0,
        rate_rad_per_s: 1.0,
        pose,
        revolutions: 1,
    };
    let full = RateErrorValues {
        accuracy: 0.0,
        ripple: [0.8, 0.6],
    };
    let msg = t
        .rate_step_average(&ok, &t.zero_errors(), &full, &env)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("ripple"), "{msg}");
}

/// The compiled step (pose-dependent products once, error rotations once per turntable)
/// equals the direct chain to rounding.
#[test]
fn compiled_rate_step_equals_the_direct_chain() {
    let t = table();
    let e = errors();
    let env = env(0.75, [0.03, -0.04, 0.12]);
    let re = RateErrorValues {
        accuracy: -2e-4,
        ripple: [1e-3, 4e-3],
    };
    let mut rot = vec![Matrix3::identity(); t.n_rotation_errors()];
    t.error_rotations(e.chi_rad(), &mut rot).expect("lengths");
    for joint in [0, 1] {
        let step = RateStep {
            joint,
            rate_rad_per_s: -3.0,
            pose: Pose::from_deg(&[25.0, -60.0]).expect("finite"),
            revolutions: 1,
        };
        let direct = t.rate_step_average(&step, &e, &re, &env).expect("ok");
        let frames = t.rate_step_frames(&step).expect("ok");
        let fast = frames
            .average(&rot, e.translations_m(), &re, &env)
            .expect("ok");
        assert_relative_eq!(fast.rate_rad_per_s, direct.rate_rad_per_s, epsilon = 1e-14);
        assert_relative_eq!(
            fast.specific_force_g,
            direct.specific_force_g,
            epsilon = 1e-14
        );
    }
}
