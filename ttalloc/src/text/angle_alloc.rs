//! The text of the angle-dependent model's direct allocations (`allocate`, `end-to-end`). The
//! results and their JSON views: [`tt_lab::allocation::angle`].

use e2e_verify::{DirectAllocation, EndToEnd};
use tt_core::human::sig;
pub(crate) use tt_lab::allocation::angle::*;

/// Each error's bound, arcmin, 4 significant digits (`none` for an unbounded one).
pub(crate) fn bounds_text(names: &[&str], d: &DirectAllocation) -> String {
    names
        .iter()
        .zip(d.upper_bounds_rad())
        .map(|(n, u)| {
            if u.is_finite() {
                format!("{n} {}", sig(tt_core::units::rad_to_arcmin(*u), 4))
            } else {
                format!("{n} none")
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}

fn j_text(d: &DirectAllocation) -> String {
    objective(d).map_or("no bound needed".into(), |j| {
        format!("J = {} arcmin^-2", sig(j, 5))
    })
}

/// The text block (empty lines excluded) for the terminal.
#[must_use]
pub(crate) fn to_text(e2e: &EndToEnd, a: &AngleAllocations) -> String {
    let names = e2e.turntable().rotation_error_names();
    let mut t = String::new();
    if a.varies {
        t.push_str(
            "\nerrors that vary with the shaft angle (the study's model; each bound holds over the whole revolution): ",
        );
        t.push_str(
            &names
                .iter()
                .zip(&a.variations)
                .map(|(n, v)| format!("{n} {}", model_name(v)))
                .collect::<Vec<_>>()
                .join(", "),
        );
        t.push('\n');
    } else {
        t.push_str("\nwith the study's measured errors compensated:\n");
    }
    for r in &a.readings {
        t.push_str(&format!(
            "reading {}: direct allocation {} (constant model: {})\n  bounds (arcmin): {}\n",
            r.reading,
            j_text(&r.direct),
            j_text(&r.constant_direct),
            bounds_text(&names, &r.direct)
        ));
        match &r.certified {
            Ok(d) => t.push_str(&format!(
                "  certified on the exact chain: {}; bounds (arcmin): {}\n",
                j_text(d),
                bounds_text(&names, d)
            )),
            Err(why) => t.push_str(&format!("  not certified: {why}\n")),
        }
        match &r.compensated {
            Some(Ok(d)) => t.push_str(&format!(
                "  compensated (measured errors held at their uncertainty, first order): {} for the unmeasured errors (before: J = {}); bounds (arcmin): {}\n",
                j_text(d),
                r.unmeasured_before_arcmin.map_or("-".into(), |j| sig(j, 5)),
                bounds_text(&names, d)
            )),
            Some(Err(why)) => t.push_str(&format!("  compensated: {why}\n")),
            None => {}
        }
    }
    t
}
