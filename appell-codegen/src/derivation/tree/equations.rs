//! Stages 6 to 11 for a large tree of joints, from the structured form
//! instead of Appell's closed form, whose cost grows like n³ with the
//! links: M from the composite-rigid-body algorithm, f = τ − h from
//! recursive Newton–Euler, T = ½ Σ vᵢ · Iᵢ vᵢ over the links, V from the weights' points, the
//! input power Σ τ u. The expressions are the recursions' shared nodes:
//! nothing is expanded.

use appell_symbolic::{Id, SymbolicError};

use super::Structured;
use crate::derivation::{Energies, Equations};
use crate::model::{ConstraintSet, Model};

/// The tree's M, f and energies.
pub fn equations(
    model: &mut Model,
    set: &ConstraintSet,
    s: &Structured,
) -> Result<(Equations, Energies), SymbolicError> {
    let l = set.speed_specs.len();
    let g = &mut model.g;
    let speeds: Vec<Id> = set
        .speed_specs
        .iter()
        .map(|sp| g.sym(sp.symbol))
        .collect::<Result<_, _>>()?;
    let torques = &s.inputs;
    let mut forcing = Vec::with_capacity(l);
    for k in 0..l {
        forcing.push(g.sub(torques[k], s.bias[k])?);
    }
    let kinetic = s.kinetic;
    let potential = potential(model)?;
    let g = &mut model.g;
    let mut p_terms = Vec::with_capacity(l);
    for k in 0..l {
        p_terms.push(g.mul(torques[k], speeds[k])?);
    }
    let input_power = g.sum(&p_terms)?;
    let actuated = !g.is_zero(input_power);
    Ok(assembled(
        s.mass.clone(),
        forcing,
        kinetic,
        potential,
        (input_power, actuated),
    ))
}

/// M, f and the energies of a tree projected onto a scene's speeds
/// ([`super::projected::in_speeds`]).
pub fn projected(
    model: &mut Model,
    p: super::projected::InSpeeds,
) -> Result<(Equations, Energies), SymbolicError> {
    let potential = potential(model)?;
    let super::projected::InSpeeds {
        projected,
        kinetic,
        input_power,
    } = p;
    let actuated = !model.g.is_zero(input_power);
    Ok(assembled(
        projected.mass,
        projected.forcing,
        kinetic,
        potential,
        (input_power, actuated),
    ))
}

/// The equations and energies of a tree's M, f, T, V and input power.
fn assembled(
    mass: Vec<Id>,
    forcing: Vec<Id>,
    kinetic: Id,
    potential: Id,
    (input_power, actuated): (Id, bool),
) -> (Equations, Energies) {
    let power_terms = if actuated {
        vec![("actuation".to_string(), input_power)]
    } else {
        Vec::new()
    };
    let equations = Equations {
        mass,
        inertial_terms: forcing.iter().map(|&f| vec![f]).collect(),
        forcing,
        load_terms: Vec::new(),
    };
    let energies = Energies {
        kinetic,
        potential,
        input_power,
        power_terms,
    };
    (equations, energies)
}

/// V = −Σ m g · r over the weights' points.
fn potential(model: &mut Model) -> Result<Id, SymbolicError> {
    let g = &mut model.g;
    let mut v_terms = Vec::new();
    for f in model.forces.iter().filter(|f| f.effect == "gravity") {
        let mut w = Vec::with_capacity(3);
        for c in 0..3 {
            w.push(g.mul(f.vector[c], f.point[c])?);
        }
        let work = g.sum(&w)?;
        v_terms.push(g.neg(work)?);
    }
    g.sum(&v_terms)
}
