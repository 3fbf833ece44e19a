//! The readable form of the derived equations: what the generated
//! `equations()` returns, and what a user reads to see which speeds are
//! dependent, what was folded and which coordinates are ignorable.

use std::fmt::Write;

use appell_symbolic::{Graph, Id};

use super::{Derivation, Elimination};
use crate::model::Model;

/// The longest expression written out in full, in characters (a spatial
/// chain's mass matrix entries reach megabytes otherwise).
const MAX_TEXT: usize = 8192;

/// The length of the listing of M and f past which entries are counted,
/// not printed.
const MAX_LISTING: usize = 16384;

/// The nodes `e` has written out as a tree, its shared parts counted each
/// time they occur, up to `cap`: a few hundred shared nodes (a recursion's)
/// can write out as millions.
fn written_size(g: &appell_symbolic::Graph, e: Id, cap: usize) -> usize {
    // Children are made before their parents: ascending ids visit them first.
    let nodes = g.reachable(&[e]);
    let mut size = std::collections::HashMap::with_capacity(nodes.len());
    for id in nodes {
        let below = g.node(id).children().iter().fold(1usize, |s, c| {
            s.saturating_add(size.get(c).copied().unwrap_or(cap))
        });
        size.insert(id, below.min(cap));
    }
    size.get(&e).copied().unwrap_or(cap)
}

/// The readable form of the derived equations.
pub fn equations_text(model: &Model, d: &Derivation) -> String {
    let g = &model.g;
    let name = |i: usize| model.coords[i].0.to_string();
    let show = |e: Id| printed(g, e).unwrap_or_else(too_long);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{}: Appell's equations (Wang & Pao 2003, eq. 56), reduced (eq. 42)",
        model.name
    );
    let _ = writeln!(
        s,
        "coordinates q: {}",
        (0..d.n).map(name).collect::<Vec<_>>().join(", ")
    );
    let speeds: Vec<String> = d
        .constraint_set
        .speed_specs
        .iter()
        .map(|sp| g.symbol_name(sp.symbol).to_string())
        .collect();
    let _ = writeln!(s, "privileged speeds: {}", speeds.join(", "));
    for (k, sp) in d.constraint_set.speed_specs.iter().enumerate() {
        if let Some(def) = sp.definition {
            let _ = writeln!(s, "  {} = {} (quasi-velocity)", speeds[k], show(def));
        }
    }
    dependent_speeds(&mut s, model, d, &speeds);
    let list = |v: &[usize]| {
        if v.is_empty() {
            "none".to_string()
        } else {
            v.iter().map(|&i| name(i)).collect::<Vec<_>>().join(", ")
        }
    };
    for line in &d.folded {
        let _ = writeln!(s, "{line}");
    }
    let _ = writeln!(s, "cyclic coordinates: {}", list(&d.reduction.cyclic));
    let _ = writeln!(
        s,
        "ignorable coordinates (not integrated): {}",
        list(&d.reduction.ignorable)
    );
    let mut state: Vec<String> = d.reduction.retained.iter().map(|&i| name(i)).collect();
    state.extend(speeds.iter().cloned());
    let _ = writeln!(s, "reduced state: ({})", state.join(", "));
    mass_and_forcing(&mut s, model, d, &speeds);
    s
}

/// An expression's text, or its node count where it is too long to print.
/// A small graph can still print as a long tree (its shared parts written
/// out each time they occur): an expression whose text passes MAX_TEXT
/// characters is named by its size too.
fn printed(g: &Graph, e: Id) -> Result<String, usize> {
    let nodes = g.dag_size(&[e]);
    let small = nodes <= 400 && written_size(g, e, MAX_TEXT) < MAX_TEXT;
    let text = small.then(|| g.display(e).to_string());
    match text {
        Some(text) if text.len() <= MAX_TEXT => Ok(text),
        _ => Err(nodes),
    }
}

/// The dependent speeds' lines, q̇_r = C ẏ + c.
fn dependent_speeds(s: &mut String, model: &Model, d: &Derivation, speeds: &[String]) {
    if d.speeds.dependent.is_empty() {
        return;
    }
    let g = &model.g;
    let show = |e: Id| printed(g, e).unwrap_or_else(too_long);
    let how = match d.elimination {
        Elimination::Symbolic => "solved symbolically",
        Elimination::Numeric(_) => "solved numerically at run time (no provably non-zero pivot)",
    };
    let _ = writeln!(s, "dependent speeds (q_dot = C y_dot + c, {how}):");
    for &r in &d.speeds.dependent {
        let mut terms = Vec::new();
        for k in 0..d.l {
            let c = d.map.c[r * d.l + k];
            if !g.is_zero(c) {
                terms.push(format!("({}) * {}", show(c), speeds[k]));
            }
        }
        if !g.is_zero(d.map.c0[r]) {
            terms.push(show(d.map.c0[r]));
        }
        if terms.is_empty() {
            terms.push("0".into());
        }
        let _ = writeln!(s, "  {}_dot = {}", model.coords[r].0, terms.join(" + "));
    }
}

/// M's upper triangle and f, entry by entry. Entries too long to print are
/// counted on one line, not listed: a large tree's M has hundreds of them.
fn mass_and_forcing(s: &mut String, model: &Model, d: &Derivation, speeds: &[String]) {
    let g = &model.g;
    let accels: Vec<String> = d
        .constraint_set
        .speed_specs
        .iter()
        .map(|sp| g.symbol_name(sp.accel).to_string())
        .collect();
    let _ = writeln!(
        s,
        "M(q) y_ddot = f(q, y_dot, t) with y_ddot = ({}):",
        accels.join(", ")
    );
    let mut entries = Vec::new();
    for k in 0..d.l {
        for j in k..d.l {
            let e = d.equations.mass[k * d.l + j];
            entries.push((format!("M[{}, {}]", speeds[k], speeds[j]), e));
        }
    }
    for k in 0..d.l {
        entries.push((format!("f[{}]", speeds[k]), d.equations.forcing[k]));
    }
    let mut long: Vec<(String, usize)> = Vec::new();
    let budget = s.len() + MAX_LISTING;
    for (label, e) in entries {
        let fits = s.len() < budget;
        match printed(g, e) {
            Ok(text) if fits => {
                let _ = writeln!(s, "  {label} = {text}");
            }
            Ok(_) => long.push((label, g.dag_size(&[e]))),
            Err(nodes) => long.push((label, nodes)),
        }
    }
    match long.as_slice() {
        [] => {}
        [(label, nodes)] => {
            let _ = writeln!(s, "  {label} = {}", too_long(*nodes));
        }
        [(first, _), .., (last, _)] => {
            let most = long.iter().map(|(_, n)| *n).max().unwrap_or(0);
            let _ = writeln!(
                s,
                "  {} entries from {first} to {last} are not printed (too long, or past the listing's length; up to {most} nodes each): see the generated code",
                long.len()
            );
        }
    }
}

/// The placeholder for an expression too long to print.
fn too_long(nodes: usize) -> String {
    format!("<expression of {nodes} nodes; see the generated code>")
}

#[cfg(test)]
mod tests {
    use super::super::{derive, testing};
    use crate::ctxt::Ctxt;

    #[test]
    fn the_text_names_the_dependent_speeds_and_the_reduced_state() {
        let cx = Ctxt::new();
        let d = derive(&cx, testing::kinematics(testing::DISC_ON_A_LINE))
            .expect("derivation")
            .full;
        cx.check().expect("no errors");
        assert!(
            d.text
                .contains("dependent speeds (q_dot = C y_dot + c, solved symbolically):"),
            "{}",
            d.text
        );
        assert!(d.text.contains("x_dot = "), "{}", d.text);
        assert!(d.text.contains("cyclic coordinates: x"), "{}", d.text);
        assert!(d.text.contains("reduced state: (phi_dot)"), "{}", d.text);
    }
}
