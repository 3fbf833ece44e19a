//! Stages 6 to 11 for a large tree of joints, from the structured form
//! instead of Appell's closed form, whose cost grows like n³ with the
//! links: M from the composite-rigid-body algorithm, f = τ − h from
//! recursive Newton–Euler, T = ½ Σ vᵢ · Iᵢ vᵢ over the links, V from the weights' points, the
//! input power Σ τ u. The expressions are the recursions' shared nodes:
//! nothing is expanded.

use appell_symbolic::{Id, SymbolicError};

use super::Structured;
use crate::derivation::{Energies, Equations};
use crate::model::Model;

/// The tree's M, f and energies.
pub fn equations(
    model: &mut Model,
    s: &Structured,
) -> Result<(Equations, Energies), SymbolicError> {
    let l = model.speed_specs.len();
    let g = &mut model.g;
    let speeds: Vec<Id> = model
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
    let mut v_terms = Vec::new();
    for f in model.forces.iter().filter(|f| f.effect == "gravity") {
        let mut w = Vec::with_capacity(3);
        for c in 0..3 {
            w.push(g.mul(f.vector[c], f.point[c])?);
        }
        let work = g.sum(&w)?;
        v_terms.push(g.neg(work)?);
    }
    let potential = g.sum(&v_terms)?;
    let mut p_terms = Vec::with_capacity(l);
    for k in 0..l {
        p_terms.push(g.mul(torques[k], speeds[k])?);
    }
    let input_power = g.sum(&p_terms)?;
    let power_terms = if g.is_zero(input_power) {
        Vec::new()
    } else {
        vec![("actuation".to_string(), input_power)]
    };
    let equations = Equations {
        mass: s.mass.clone(),
        forcing: forcing.clone(),
        inertial_terms: forcing.iter().map(|&f| vec![f]).collect(),
        load_terms: Vec::new(),
    };
    let energies = Energies {
        kinetic,
        potential,
        input_power,
        power_terms,
    };
    Ok((equations, energies))
}
