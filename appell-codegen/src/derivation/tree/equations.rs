//! Stages 6 to 11 for a large tree of joints, from the structured form
//! instead of Appell's closed form, whose cost grows like n³ with the
//! links: M from the composite-rigid-body algorithm, f = τ − h from
//! recursive Newton–Euler, T = ½ uᵀ M u, V from the weights' points, the
//! input power Σ τ u. The expressions are the recursions' shared nodes:
//! nothing is expanded.

use appell_symbolic::{Id, Number, SymbolicError};

use super::Structured;
use crate::derivation::{Energies, Equations};
use crate::model::tree::TreeSpec;
use crate::model::Model;

/// The tree's M, f and energies.
pub fn equations(
    model: &mut Model,
    spec: &TreeSpec,
    s: &Structured,
) -> Result<(Equations, Energies), SymbolicError> {
    let l = model.speed_specs.len();
    let g = &mut model.g;
    let speeds: Vec<Id> = model
        .speed_specs
        .iter()
        .map(|sp| g.sym(sp.symbol))
        .collect::<Result<_, _>>()?;
    // The joints' inputs in speed order (moving links are the speeds).
    let mut torques = Vec::with_capacity(l);
    for link in spec.links.iter().filter(|k| k.motion.is_some()) {
        let name = format!("tau_{}", link.joint);
        let input = model.inputs.iter().find(|(n, _)| *n == name);
        torques.push(match input {
            Some((_, sym)) if link.actuated => g.sym(*sym)?,
            _ => g.int(0)?,
        });
    }
    let mut forcing = Vec::with_capacity(l);
    for k in 0..l {
        forcing.push(g.sub(torques[k], s.bias[k])?);
    }
    let mut ke_terms = Vec::new();
    for i in 0..l {
        let mut row = Vec::with_capacity(l);
        for j in 0..l {
            row.push(g.mul(s.mass[i * l + j], speeds[j])?);
        }
        let mu = g.sum(&row)?;
        ke_terms.push(g.mul(speeds[i], mu)?);
    }
    let twice = g.sum(&ke_terms)?;
    let kinetic = g.scale(twice, Number::ratio(1, 2).expect("1/2"))?;
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
