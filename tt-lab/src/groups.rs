//! Errors that act only together ([`tt_kinematics::Turntable::proportional_groups`]: one
//! rotation to first order, so no output can tell them apart): the one sentence every command
//! and the report print per group (the JSON `groups` key: [`crate::json::GroupJson`]).

use tt_core::human::sig;
use tt_core::units::rad_to_arcmin;
use tt_kinematics::{ErrorGroup, Turntable};

/// "a, b and c".
fn and_list(items: &[&str]) -> String {
    match items {
        [] => String::new(),
        [one] => (*one).to_string(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}

/// The combination's bound under `ub` (rad) in arcmin for people, `none` when unbounded.
fn bound_text(g: &ErrorGroup, ub: &[f64]) -> String {
    let b = g.combined_bound(ub);
    if b.is_finite() {
        format!("{} arcmin", sig(rad_to_arcmin(b), 4))
    } else {
        "none".into()
    }
}

/// The group's sentence: which errors act as one rotation and that only their combination
/// matters; with `bounds` (label, upper bounds in rad), the combination's bound under each
/// (the sum of the members' bounds).
#[must_use]
pub(crate) fn sentence(t: &Turntable, g: &ErrorGroup, bounds: &[(&str, &[f64])]) -> String {
    let names = t.rotation_error_names();
    let mut s = format!(
        "{} act as one rotation (first order, every pose): only their combination {} matters",
        and_list(&g.names(&names)),
        g.combination(&names)
    );
    if !bounds.is_empty() {
        let parts: Vec<String> = bounds
            .iter()
            .map(|(label, ub)| format!("{} ({label})", bound_text(g, ub)))
            .collect();
        s.push_str("; its bound is the sum of theirs: ");
        s.push_str(&parts.join(", "));
    }
    s
}

/// One [`sentence`] per group of errors that act only together (none when every error acts
/// alone).
#[must_use]
pub fn lines(t: &Turntable, bounds: &[(&str, &[f64])]) -> Vec<String> {
    t.proportional_groups()
        .iter()
        .map(|g| sentence(t, g, bounds))
        .collect()
}

/// The text block of a command: a line per group, each indented by `indent`, or nothing.
#[must_use]
pub fn text(t: &Turntable, bounds: &[(&str, &[f64])], indent: &str) -> String {
    lines(t, bounds)
        .into_iter()
        .map(|l| format!("{indent}{l}\n"))
        .collect()
}

/// The name of a contribution in a share table: the error's, or its group's combination.
#[must_use]
pub fn contribution_name(t: &Turntable, g: &ErrorGroup) -> String {
    g.combination(&t.rotation_error_names())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sentence_names_every_member_and_the_combination() {
        let t = tt_kinematics::paper::table3();
        let g = &t.proportional_groups()[0];
        let ub = vec![tt_core::units::arcmin_to_rad(0.25); t.n_rotation_errors()];
        assert_eq!(
            sentence(&t, g, &[("direct", &ub)]),
            "dphi_y1 and deps_y act as one rotation (first order, every pose): only their combination dphi_y1 + deps_y matters; its bound is the sum of theirs: 0.5 arcmin (direct)"
        );
        let v = crate::json::GroupJson::all(&t, &[("direct", &ub)]);
        assert_eq!(v.len(), 3);
        assert_eq!(v[1].errors, ["dphi_z2", "dalpha_z1"]);
        assert_eq!(and_list(&["a", "b", "c"]), "a, b and c");
    }
}
