//! The text of the rate parts (`check-turntable`, `allocate`, `end-to-end`, the report): the
//! check with the errors only rotation exposes, and the direct allocation with the rate
//! tolerances. The results and their JSON views: [`tt_lab::vendor::rate`].

use e2e_verify::{EndToEnd, RateTolerance};
use tt_core::human::num;
pub(crate) use tt_lab::vendor::rate::*;

/// The check as text.
#[must_use]
pub(crate) fn text(e2e: &EndToEnd, c: &RateCheck) -> String {
    let names = e2e.extra_names();
    let mut s = format!(
        "\nrate steps, reading {}: the angular box and the errors only rotation exposes together\n",
        e2e.reading()
    );
    let bounds: Vec<String> = e2e
        .extra_errors()
        .iter()
        .zip(&names)
        .zip(&c.bounds)
        .map(|((x, n), b)| {
            let (v, unit) = in_sheet_units(x, *b);
            format!("{n} {} {unit}", num(v))
        })
        .collect();
    s.push_str(&format!("  bounds: {}\n", bounds.join(", ")));
    let acc = e2e.accuracies();
    for o in &c.outputs {
        let out = &e2e.calibration().outputs()[o.output()].output();
        let top = o
            .extra_parts()
            .iter()
            .enumerate()
            .fold((0, 0.0), |b, (i, v)| if *v > b.1 { (i, *v) } else { b });
        let noise = c.noise.as_ref().map_or(String::new(), |n| {
            format!(
                ", noise {} ({} sigma of {}), table + noise {}",
                num(n.margin(o.output())),
                num(n.k_sigma),
                num(n.sigma[o.output()]),
                num(RateCheck::table_part(o) + n.margin(o.output()))
            )
        });
        s.push_str(&format!(
            "  {}: worst case {} {} (angles {}, rate errors and translations {}; largest {} {}) at entry {}, exact {}{noise} against {}: {}\n",
            out.name,
            num(o.linear_bound()),
            out.unit,
            num(o.angular_part()),
            num(o.extra_part()),
            names.get(top.0).map_or("-", String::as_str),
            num(top.1),
            o.position(),
            num(o.exact_at_vertex()),
            num(acc[o.output()]),
            if c.output_meets(o, acc[o.output()]) {
                "meets"
            } else {
                "does not meet"
            }
        ));
    }
    let (lo, hi) = c.count.interval_95();
    let verdict = |m: bool| {
        if m {
            "meets every accuracy"
        } else {
            "does not meet every accuracy"
        }
    };
    s.push_str(&format!(
        "  yield over both boxes {:.2}% [{:.2}%, {:.2}%] of {} turntables{}; verdict with the rate errors{}: {}\n",
        100.0 * c.count.meeting() as f64 / c.count.samples() as f64,
        100.0 * lo,
        100.0 * hi,
        c.count.samples(),
        if c.noise.is_some() {
            " (the table alone)"
        } else {
            ""
        },
        if c.noise.is_some() { " and the noise" } else { "" },
        verdict(c.meets_every_accuracy(e2e))
    ));
    if c.noise.is_some() {
        s.push_str(&format!(
            "  rule: {}; the table alone {}\n",
            c.rule(),
            verdict(c.table_meets_every_accuracy(e2e))
        ));
    }
    s
}

/// The allocation with the rate tolerances and the noise part kept free, as text.
#[must_use]
fn with_noise_text(e2e: &EndToEnd, w: &RateWithNoise) -> String {
    let mut s = format!(
        "direct allocation with the rate tolerances and the noise kept free ({})\n",
        with_noise_rule(w.noise.k_sigma)
    );
    let acc = e2e.accuracies();
    let name = |k: usize| e2e.calibration().outputs()[k].output();
    match &w.allocation {
        Err(blocked) => {
            for b in blocked {
                let out = name(b.output());
                s.push_str(&format!(
                    "  no table suffices at this dwell: {} noise part {} {} (with the lower bounds' {}) leaves no room in {}\n",
                    out.name,
                    num(b.noise_part()),
                    out.unit,
                    num(b.lower_bounds_part()),
                    num(acc[b.output()])
                ));
            }
        }
        Ok(a) => {
            s.push_str(&format!(
                "  J = {} arcmin^-2; rate tolerances: {}\n",
                num(a.combined().objective_arcmin()),
                tolerances_text(e2e, a.tolerances(), a.tolerance_bounds())
            ));
            for c in a.worst_cases() {
                let k = c.output();
                let out = name(k);
                s.push_str(&format!(
                    "  {}: table {} {} (exact at its worst vertex) + noise {} = {} against {}\n",
                    out.name,
                    num(c.exact_at_vertex()),
                    out.unit,
                    num(w.noise.margin(k)),
                    num(c.exact_at_vertex() + w.noise.margin(k)),
                    num(acc[k])
                ));
            }
            match &w.certified {
                Some(Ok(c)) => s.push_str(&format!(
                    "  certified with the noise kept free: J = {} arcmin^-2; rate tolerances: {}\n",
                    num(c.combined().objective_arcmin()),
                    tolerances_text(e2e, c.tolerances(), c.tolerance_bounds())
                )),
                Some(Err(why)) => {
                    s.push_str(&format!(
                        "  no certified allocation with the noise: {why}\n"
                    ));
                }
                None => {}
            }
        }
    }
    s
}

/// The rate tolerances `bounds` as `name value unit` (or `no bound`), comma-separated.
fn tolerances_text(e2e: &EndToEnd, tolerances: &[RateTolerance], bounds: &[f64]) -> String {
    e2e.rates()
        .rate_tolerance_names()
        .iter()
        .zip(tolerances)
        .zip(bounds)
        .map(|((n, t), b)| {
            if b.is_finite() {
                let (v, unit) = tolerance_in_sheet_units(t, *b);
                format!("{n} {} {unit}", num(v))
            } else {
                format!("{n} no bound")
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// The allocation with the rate tolerances as text.
#[must_use]
pub(crate) fn allocation_text(e2e: &EndToEnd, r: &RateAllocated) -> String {
    let a = &r.allocation;
    let mut s = format!(
        "\ndirect allocation with the rate tolerances (reading {}): the angles, rate accuracy, ripple and translations allocated together, J = {} arcmin^-2\n",
        e2e.reading(),
        num(a.combined().objective_arcmin())
    );
    let names = e2e.turntable().rotation_error_names();
    let angles: Vec<String> = names
        .iter()
        .zip(a.angles_rad())
        .map(|(n, u)| {
            if u.is_finite() {
                format!("{n} {} arcmin", num(tt_core::units::rad_to_arcmin(*u)))
            } else {
                format!("{n} no bound")
            }
        })
        .collect();
    s.push_str(&format!("  angles: {}\n", angles.join(", ")));
    s.push_str(&format!(
        "  rate tolerances: {}\n",
        tolerances_text(e2e, a.tolerances(), a.tolerance_bounds())
    ));
    let acc = e2e.accuracies();
    for w in a.worst_cases() {
        let out = e2e.calibration().outputs()[w.output()].output();
        s.push_str(&format!(
            "  {}: worst case over both boxes {} {} (first order), exact chain at its worst vertex {} (entry {}), margin {} against {}\n",
            out.name,
            num(w.linear_bound()),
            out.unit,
            num(w.exact_at_vertex()),
            w.position(),
            num(acc[w.output()] - w.exact_at_vertex()),
            num(acc[w.output()])
        ));
    }
    let (lo, hi) = r.count.interval_95();
    s.push_str(&format!(
        "  yield over both allocated boxes {:.2}% [{:.2}%, {:.2}%] of {} turntables (exact chain at random points)\n",
        100.0 * r.count.meeting() as f64 / r.count.samples() as f64,
        100.0 * lo,
        100.0 * hi,
        r.count.samples()
    ));
    s.push_str(&format!(
        "  {}\n",
        e2e_verify::rate::NOT_CERTIFIED_AT_RATE_STEPS
    ));
    match &r.certified {
        Ok(c) => {
            s.push_str(&format!(
                "certified allocation with the rate tolerances (first-order worst case plus the derived second-order bound within every accuracy), J = {} arcmin^-2\n",
                num(c.combined().objective_arcmin())
            ));
            let tols: Vec<String> = e2e
                .rates()
                .rate_tolerance_names()
                .iter()
                .zip(c.tolerances())
                .zip(c.tolerance_bounds())
                .filter(|(_, b)| b.is_finite())
                .map(|((n, t), b)| {
                    let (v, unit) = tolerance_in_sheet_units(t, *b);
                    format!("{n} {} {unit}", num(v))
                })
                .collect();
            s.push_str(&format!("  rate tolerances: {}\n", tols.join(", ")));
            for (k, a_k) in acc.iter().enumerate() {
                let Some(cert) = c.certificate() else { break };
                let out = e2e.calibration().outputs()[k].output();
                s.push_str(&format!(
                    "  {}: certified {} {} = first order {} + second-order bound {}, against {}\n",
                    out.name,
                    num(cert.certified_bound(k)),
                    out.unit,
                    num(cert.linear_bounds()[k]),
                    num(cert.second_order_bounds()[k]),
                    num(*a_k)
                ));
            }
        }
        Err(why) => s.push_str(&format!("  no certified allocation: {why}\n")),
    }
    if let Some(w) = &r.with_noise {
        s.push_str(&with_noise_text(e2e, w));
    }
    s
}
