//! `cargo xtask end-to-end [--study FILE] [--json]`: does the allocated turntable deliver the
//! calibration accuracy? (issue 7, crate `e2e-verify`).
//!
//! For the paper's Table 4 bounds and for the two-step optimum (alloc-opt's sensitivity-weighted
//! allocation against the study's requirement, 0.027 deg): the worst-case end-to-end rate
//! errors $\Delta\omega_x$, $\Delta\omega_y$ (linearised vertex confirmed on the exact chain),
//! the Monte Carlo yield $P(\Delta\omega_x, \Delta\omega_y \le \omega_m)$, and the direct and
//! yield-based allocations against $\omega_m$ itself, under the study's reading of eq 13
//! (default `intended/beta1/printed`, which reproduces §2) and under the user's reading
//! `actual/beta1/printed` (what a calibrating engineer gets).
//!
//! Inputs come from the study file (default `studies/gyrowheel-2017.toml`): sensor, site,
//! schedule, reading, omega_m, lower bounds, requirement, Monte Carlo samples and seed; the
//! flags `--samples`, `--seed`, `--yield-fraction`, `--reading` override them.
//!
//! `--json` prints one object with at least
//! `{"reading", "worst_case_deg_per_h": {"table4": {"x","y"}, "ours": {"x","y"}, ...},
//! "yield": {"table4", "ours", ...}, "direct_allocation_arcmin": {dphi_y1..deps_y},
//! "direct_objective", "two_step_objective", "yield_allocation_arcmin": {...},
//! "user_reading": {...the same per-reading keys...}}`. Objectives are
//! $J = \sum_j w_j^2/\mathrm{UB}_j^2$ with the bounds in arcmin (arcmin$^{-2}$) and the paper's
//! weights (equal to alloc-opt's $J_\psi + J_\theta + J_\gamma$).

use crate::InputError;
use crate::study::Study;
use alloc_opt::AllocError;
use anyhow::Result;
use calib_lsq::Reading;
use clap::Parser;
use e2e_verify::{
    BoxAnswer, BuyersAnswer, E2eError, EndToEnd, EndToEndInputs, McSettings, ReadingAnswer, answer,
    objective_to_arcmin,
};
use gw_model::units::rad_per_s_to_deg_per_h;
use mc_verify::ErrorBox;
use serde_json::{Map, Value, json};
use std::time::Instant;
use tt_kinematics::units::RAD_PER_ARCMIN;
use tt_kinematics::{CHI_LEN, ErrorComponent};

/// Arguments of `end-to-end`.
#[derive(Debug, Parser)]
pub struct Args {
    /// Study file (default: `studies/gyrowheel-2017.toml`, the paper's inputs).
    #[arg(long)]
    pub study: Option<std::path::PathBuf>,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// Monte Carlo turntables per box (default: the study's `monte_carlo.samples`).
    #[arg(long)]
    pub samples: Option<u64>,
    /// Seed (default: the study's `monte_carlo.seed`).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Target yield of the yield-based allocation, in (0, 1).
    #[arg(long, default_value_t = e2e_verify::DEFAULT_YIELD_FRACTION)]
    pub yield_fraction: f64,
    /// Reading of eq 13 as `outputs/estimate/form` (default: the study's).
    #[arg(long)]
    pub reading: Option<String>,
}

/// The library inputs for a study and the flags.
///
/// # Errors
/// [`InputError`] naming the file key or flag.
pub fn inputs(args: &Args) -> Result<EndToEndInputs, InputError> {
    let study = Study::load_or_paper(args.study.as_deref())?;
    let reading = match &args.reading {
        Some(r) => r
            .parse::<Reading>()
            .map_err(|e| InputError::new("--reading", e.to_string()))?,
        None => study.reading,
    };
    inputs_from_study(
        &study,
        reading,
        args.samples.unwrap_or(study.file.monte_carlo.samples),
        args.seed.unwrap_or(study.file.monte_carlo.seed),
        args.yield_fraction,
    )
}

/// The library inputs for a study with the given reading, Monte Carlo size, seed and target
/// yield (also used by `reproduce-paper`).
///
/// # Errors
/// [`InputError`] naming the key or flag.
pub fn inputs_from_study(
    study: &Study,
    reading: Reading,
    samples: u64,
    seed: u64,
    yield_fraction: f64,
) -> Result<EndToEndInputs, InputError> {
    let inputs = EndToEndInputs {
        coefficients: study.coefficients,
        site: study.site,
        schedule: study.schedule.clone(),
        reading,
        omega_m_rad_per_s: study.omega_m_rad_per_s,
        lower_bounds_rad: study.lower_bounds_rad,
        two_step_requirement_rad: study.requirement_rad,
        samples,
        seed,
        yield_fraction,
    };
    inputs.validate().map_err(|e| input_error(&e))?;
    Ok(inputs)
}

fn input_error(e: &E2eError) -> InputError {
    let location = match e {
        E2eError::ZeroSamples { .. } => "--samples",
        E2eError::FractionOutOfRange { .. } => "--yield-fraction",
        _ => "study",
    };
    InputError::new(location, e.to_string())
}

/// Solver trouble is ours (exit 1); everything else comes from the inputs (exit 2).
pub fn classify(e: E2eError) -> anyhow::Error {
    match e {
        E2eError::Alloc(AllocError::Solver { .. } | AllocError::NoConvergence { .. }) => {
            anyhow::Error::new(e)
        }
        other => input_error(&other).into(),
    }
}

/// Run the command.
///
/// # Errors
/// [`InputError`] for bad inputs; other errors if a solver fails.
pub fn run(args: &Args) -> Result<()> {
    let inputs = inputs(args)?;
    let t0 = Instant::now();
    let a = answer(&inputs).map_err(classify)?;
    let elapsed = t0.elapsed().as_secs_f64();
    let draws: u64 = a
        .readings
        .iter()
        .map(|r| {
            [&r.table4, &r.ours, &r.direct_box, &r.yield_box]
                .iter()
                .map(|b| b.distribution.samples)
                .sum::<u64>()
                + 2 * r.yield_based.samples
        })
        .sum();
    let speed = throughput(&inputs).map_err(classify)?;
    let value = to_json(&a, elapsed, draws, &speed);
    if args.json {
        println!("{}", serde_json::to_string_pretty(&value)?);
    } else {
        print_text(&a, elapsed, draws, &speed);
    }
    Ok(())
}

/// Single-thread turntables per second of the fast path and of the reference path on the
/// same draws, and of the whole answer.
struct Throughput {
    draws: usize,
    fast_per_s: f64,
    reference_per_s: f64,
}

/// Same-run baseline: the reference path (tt-kinematics' chain per position, calib-lsq's
/// eq 7-14 analysis with both estimates, i.e. a QR of A' per draw) against the fast path
/// (factored chain, precomputed pseudo-inverse), one thread, the same 400 draws of Table 4's
/// box under the user's reading.
fn throughput(inputs: &EndToEndInputs) -> Result<Throughput, E2eError> {
    const N: u64 = 400;
    let e2e = EndToEnd::new(
        &inputs.coefficients,
        &inputs.site,
        &inputs.schedule,
        Reading::USER,
    )?;
    let bounds = ErrorBox::from_upper_rad(alloc_opt::paper_table4_rad())?;
    let draws = e2e.sample_rates(&bounds, &McSettings::new(N, inputs.seed))?;
    let t = Instant::now();
    let mut sink = 0.0;
    for d in &draws {
        sink += e2e.delta_omega(&d.chi_rad)?[0];
    }
    let fast = t.elapsed().as_secs_f64();
    let t = Instant::now();
    for d in &draws {
        sink -= e2e.run(&d.chi_rad)?.delta_omega_rad_per_s()[0];
    }
    let reference = t.elapsed().as_secs_f64();
    std::hint::black_box(sink);
    Ok(Throughput {
        draws: draws.len(),
        fast_per_s: N as f64 / fast,
        reference_per_s: N as f64 / reference,
    })
}

fn arcmin_map(ub_rad: &[f64; CHI_LEN]) -> Value {
    let mut m = Map::new();
    for c in ErrorComponent::ALL {
        m.insert(
            c.name().to_string(),
            json!(ub_rad[c.index()] / RAD_PER_ARCMIN),
        );
    }
    Value::Object(m)
}

fn xy(v: [f64; 2]) -> Value {
    json!({"x": v[0], "y": v[1]})
}

fn box_entries(
    name: &str,
    b: &BoxAnswer,
    e2e_positions: &[(f64, f64)],
    out: &mut Map<String, Value>,
) {
    let get = |key: &str, out: &mut Map<String, Value>| -> Map<String, Value> {
        match out.remove(key) {
            Some(Value::Object(m)) => m,
            _ => Map::new(),
        }
    };
    let wc = &b.worst_case;
    let d = &b.distribution;
    let (lo, hi) = d.yield_interval_95();
    let entries: Vec<(&str, Value)> = vec![
        ("worst_case_deg_per_h", xy(wc.exact_deg_per_h())),
        ("worst_case_linear_deg_per_h", xy(wc.linear_deg_per_h())),
        (
            "second_order_bound_deg_per_h",
            xy(wc.axes.clone().map(|a| {
                a.second_order_bound_rad_per_s
                    .map_or(f64::NAN, rad_per_s_to_deg_per_h)
            })),
        ),
        (
            "worst_position",
            json!({
                "x": position_json(wc.axes[0].position, e2e_positions),
                "y": position_json(wc.axes[1].position, e2e_positions),
            }),
        ),
        (
            "worst_chi_arcmin",
            json!({"x": arcmin_map(&wc.axes[0].worst_chi_rad), "y": arcmin_map(&wc.axes[1].worst_chi_rad)}),
        ),
        ("yield", json!(d.yield_fraction())),
        ("yield_interval_95", json!([lo, hi])),
        ("mc_max_deg_per_h", xy(d.max_deg_per_h())),
        (
            "mc_quantiles_deg_per_h",
            Value::Array(
                d.quantiles
                    .iter()
                    .map(|q| {
                        json!({"p": q.p, "x": rad_per_s_to_deg_per_h(q.rad_per_s[0]),
                               "y": rad_per_s_to_deg_per_h(q.rad_per_s[1]),
                               "max": rad_per_s_to_deg_per_h(q.rad_per_s[2])})
                    })
                    .collect(),
            ),
        ),
        (
            "mc_histogram",
            json!({
                "edges_deg_per_h": d.histogram_edges_rad_per_s.iter().map(|v| rad_per_s_to_deg_per_h(*v)).collect::<Vec<_>>(),
                "x": d.histogram_counts[0], "y": d.histogram_counts[1], "max": d.histogram_counts[2],
            }),
        ),
        (
            "per_position_worst_case_deg_per_h",
            json!({
                "x": wc.axes[0].per_position_rad_per_s.iter().map(|v| rad_per_s_to_deg_per_h(*v)).collect::<Vec<_>>(),
                "y": wc.axes[1].per_position_rad_per_s.iter().map(|v| rad_per_s_to_deg_per_h(*v)).collect::<Vec<_>>(),
            }),
        ),
        ("bounds_arcmin", arcmin_map(&b.upper_bounds_rad)),
        ("objective", json!(objective_to_arcmin(b.objective))),
    ];
    for (key, v) in entries {
        let mut m = get(key, out);
        m.insert(name.to_string(), v);
        out.insert(key.to_string(), Value::Object(m));
    }
}

fn position_json(i: usize, positions: &[(f64, f64)]) -> Value {
    let (p1, p2) = positions.get(i).copied().unwrap_or((f64::NAN, f64::NAN));
    json!({"index": i, "phi1_deg": p1, "phi2_deg": p2})
}

fn reading_json(r: &ReadingAnswer, positions: &[(f64, f64)]) -> Map<String, Value> {
    let mut out = Map::new();
    out.insert("reading".into(), json!(r.reading.to_string()));
    box_entries("table4", &r.table4, positions, &mut out);
    box_entries("ours", &r.ours, positions, &mut out);
    box_entries("direct", &r.direct_box, positions, &mut out);
    box_entries("yield_based", &r.yield_box, positions, &mut out);
    out.insert(
        "direct_allocation_arcmin".into(),
        arcmin_map(&r.direct.upper_bounds_rad),
    );
    out.insert(
        "direct_objective".into(),
        json!(r.direct.objective_arcmin()),
    );
    out.insert(
        "direct_active_rows".into(),
        Value::Array(
            r.direct
                .active_rows()
                .iter()
                .map(|l| {
                    let mut p = position_json(l.position, positions);
                    if let Value::Object(m) = &mut p {
                        m.insert("axis".into(), json!(l.axis.name()));
                    }
                    p
                })
                .collect(),
        ),
    );
    if let Some((d, wc)) = &r.direct_certified {
        out.insert(
            "direct_certified".into(),
            json!({
                "allocation_arcmin": arcmin_map(&d.upper_bounds_rad),
                "objective": d.objective_arcmin(),
                "second_order_margin_deg_per_h": rad_per_s_to_deg_per_h(d.second_order_margin_rad_per_s),
                "worst_case_deg_per_h": xy(wc.exact_deg_per_h()),
            }),
        );
    }
    out.insert(
        "yield_allocation_arcmin".into(),
        arcmin_map(&r.yield_based.upper_bounds_rad),
    );
    out.insert(
        "yield_objective".into(),
        json!(r.yield_based.objective_arcmin()),
    );
    out.insert(
        "yield_design".into(),
        json!({
            "target": r.yield_based.target,
            "scale": r.yield_based.scale,
            "samples": r.yield_based.samples,
            "seed": r.yield_based.seed,
            "yield": r.yield_based.yield_fraction(),
            "interval_95": [r.yield_based.interval_95.0, r.yield_based.interval_95.1],
        }),
    );
    out
}

fn to_json(a: &BuyersAnswer, elapsed: f64, draws: u64, speed: &Throughput) -> Value {
    let positions: Vec<(f64, f64)> = a
        .inputs
        .schedule
        .positions()
        .iter()
        .map(|p| (p.phi_1_deg(), p.phi_2_deg()))
        .collect();
    let mut top = reading_json(&a.readings[0], &positions);
    top.insert(
        "omega_m_deg_per_h".into(),
        json!(rad_per_s_to_deg_per_h(a.inputs.omega_m_rad_per_s)),
    );
    top.insert("samples".into(), json!(a.inputs.samples));
    top.insert("seed".into(), json!(a.inputs.seed));
    top.insert("yield_target".into(), json!(a.inputs.yield_fraction));
    top.insert(
        "lower_bounds_arcmin".into(),
        arcmin_map(&a.inputs.lower_bounds_rad),
    );
    top.insert(
        "two_step_objective".into(),
        json!(objective_to_arcmin(a.two_step_objective)),
    );
    top.insert(
        "table4_objective".into(),
        json!(objective_to_arcmin(a.table4_objective)),
    );
    top.insert("objective_unit".into(), json!("arcmin^-2"));
    top.insert(
        "positions_deg".into(),
        json!(positions.iter().map(|(a, b)| [*a, *b]).collect::<Vec<_>>()),
    );
    if let Some(user) = a.readings.get(1) {
        top.insert(
            "user_reading".into(),
            Value::Object(reading_json(user, &positions)),
        );
    }
    top.insert(
        "throughput".into(),
        json!({
            "answer_seconds": elapsed,
            "answer_turntables": draws,
            "answer_turntables_per_s": draws as f64 / elapsed,
            "single_thread_fast_per_s": speed.fast_per_s,
            "single_thread_reference_per_s": speed.reference_per_s,
            "fast_over_reference": speed.fast_per_s / speed.reference_per_s,
            "baseline_draws": speed.draws,
        }),
    );
    Value::Object(top)
}

fn print_text(a: &BuyersAnswer, elapsed: f64, draws: u64, speed: &Throughput) {
    let om = rad_per_s_to_deg_per_h(a.inputs.omega_m_rad_per_s);
    println!(
        "End-to-end check (issue 7): omega_m = {om} deg/h, {} turntables per box, seed {}, LB = {:?} arcmin",
        a.inputs.samples,
        a.inputs.seed,
        a.inputs.lower_bounds_rad.map(|v| v / RAD_PER_ARCMIN)
    );
    println!(
        "Objective J (arcmin^-2, paper weights): Table 4 {:.3}, two-step optimum {:.3}",
        objective_to_arcmin(a.table4_objective),
        objective_to_arcmin(a.two_step_objective)
    );
    for r in &a.readings {
        println!("\nReading {}:", r.reading);
        println!(
            "  {:<12} {:>11} {:>11} {:>9}  {:<19} {:>9}",
            "bounds", "worst x", "worst y", "yield", "95% interval", "J"
        );
        for (name, b) in [
            ("Table 4", &r.table4),
            ("two-step", &r.ours),
            ("direct", &r.direct_box),
            ("yield-based", &r.yield_box),
        ] {
            let [x, y] = b.worst_case.exact_deg_per_h();
            let (lo, hi) = b.distribution.yield_interval_95();
            let lin = b.worst_case.linear_deg_per_h();
            let flag = if x <= om && y <= om {
                "worst case meets omega_m"
            } else if lin[0] <= om * (1.0 + 1e-9) && lin[1] <= om * (1.0 + 1e-9) {
                "meets to first order (exact chain: second-order excess)"
            } else {
                "worst case exceeds omega_m"
            };
            println!(
                "  {name:<12} {x:>11.6} {y:>11.6} {:>9.5}  [{lo:.5}, {hi:.5}] {:>9.3}  {flag}",
                b.distribution.yield_fraction(),
                objective_to_arcmin(b.objective)
            );
        }
        println!("  (worst cases in deg/h: linearised vertex confirmed on the exact chain)");
        let names = ErrorComponent::ALL.map(|c| c.name());
        println!(
            "  {:<12} {}",
            "arcmin",
            names.map(|n| format!("{n:>10}")).join("")
        );
        for (name, ub) in [
            ("Table 4", r.table4.upper_bounds_rad),
            ("two-step", r.ours.upper_bounds_rad),
            ("direct", r.direct.upper_bounds_rad),
            ("yield-based", r.yield_based.upper_bounds_rad),
        ]
        .into_iter()
        .chain(
            r.direct_certified
                .as_ref()
                .map(|(d, _)| ("certified", d.upper_bounds_rad)),
        ) {
            println!(
                "  {name:<12} {}",
                ub.map(|v| format!("{:>10.4}", v / RAD_PER_ARCMIN)).join("")
            );
        }
        println!(
            "  direct: J {:.3} = {:.3} x two-step; yield-based ({:.2}%, scale {:.4}, design yield {:.5} [{:.5}, {:.5}]): J {:.3} = {:.3} x two-step",
            r.direct.objective_arcmin(),
            r.direct.objective / a.two_step_objective,
            100.0 * r.yield_based.target,
            r.yield_based.scale,
            r.yield_based.yield_fraction(),
            r.yield_based.interval_95.0,
            r.yield_based.interval_95.1,
            r.yield_based.objective_arcmin(),
            r.yield_based.objective / a.two_step_objective,
        );
        if let Some((d, wc)) = &r.direct_certified {
            let [x, y] = wc.exact_deg_per_h();
            println!(
                "  certified direct (rows held to omega_m - {:.2e} deg/h for the exact chain's second-order terms): worst {x:.6} {y:.6} deg/h, J {:.3} = {:.3} x two-step",
                rad_per_s_to_deg_per_h(d.second_order_margin_rad_per_s),
                d.objective_arcmin(),
                d.objective / a.two_step_objective
            );
        }
    }
    println!(
        "\nThroughput: {draws} turntables in {elapsed:.2} s ({:.0}/s, all threads, allocations included); one thread, {} draws: fast path {:.0}/s, reference path {:.0}/s (ratio {:.1})",
        draws as f64 / elapsed,
        speed.draws,
        speed.fast_per_s,
        speed.reference_per_s,
        speed.fast_per_s / speed.reference_per_s
    );
}
