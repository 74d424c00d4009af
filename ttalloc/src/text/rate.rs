//! The text of the rate parts (`check-turntable`, `allocate`, `end-to-end`, the report): the
//! check with the errors only rotation exposes, and the direct allocation with the rate
//! tolerances. The results and their JSON views: [`tt_lab::vendor::rate`].

use e2e_verify::EndToEnd;
use study::fmt::num;
pub use tt_lab::vendor::rate::*;

/// The check as text.
#[must_use]
pub fn text(e2e: &EndToEnd, c: &RateCheck) -> String {
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
        s.push_str(&format!(
            "  {}: worst case {} {} (angles {}, rate errors and translations {}; largest {} {}) at entry {}, exact {} against {}: {}\n",
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
            if o.linear_bound() <= acc[o.output()] && o.exact_at_vertex() <= acc[o.output()] {
                "meets"
            } else {
                "does not meet"
            }
        ));
    }
    let (lo, hi) = e2e_verify::wilson_interval_95(c.meets, c.samples);
    s.push_str(&format!(
        "  yield over both boxes {:.2}% [{:.2}%, {:.2}%] of {} turntables; verdict with the rate errors: {}\n",
        100.0 * c.meets as f64 / c.samples as f64,
        100.0 * lo,
        100.0 * hi,
        c.samples,
        if c.meets_every_accuracy(e2e) {
            "meets every accuracy"
        } else {
            "does not meet every accuracy"
        }
    ));
    s
}

/// The allocation with the rate tolerances as text.
#[must_use]
pub fn allocation_text(e2e: &EndToEnd, r: &RateAllocated) -> String {
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
    let tols: Vec<String> = e2e
        .rate_tolerance_names()
        .iter()
        .zip(a.tolerances())
        .zip(a.tolerance_bounds())
        .map(|((n, t), b)| {
            if b.is_finite() {
                let (v, unit) = tolerance_in_sheet_units(t, *b);
                format!("{n} {} {unit}", num(v))
            } else {
                format!("{n} no bound")
            }
        })
        .collect();
    s.push_str(&format!("  rate tolerances: {}\n", tols.join(", ")));
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
    let (lo, hi) = e2e_verify::wilson_interval_95(r.meets, r.samples);
    s.push_str(&format!(
        "  yield over both allocated boxes {:.2}% [{:.2}%, {:.2}%] of {} turntables (exact chain at random points)\n",
        100.0 * r.meets as f64 / r.samples as f64,
        100.0 * lo,
        100.0 * hi,
        r.samples
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
                let out = e2e.calibration().outputs()[k].output();
                s.push_str(&format!(
                    "  {}: certified {} {} = first order {} + second-order bound {}, against {}\n",
                    out.name,
                    num(c.certified_bound(k)),
                    out.unit,
                    num(c.linear_bounds()[k]),
                    num(c.second_order_bounds()[k]),
                    num(*a_k)
                ));
            }
        }
        Err(why) => s.push_str(&format!("  no certified allocation: {why}\n")),
    }
    s
}
