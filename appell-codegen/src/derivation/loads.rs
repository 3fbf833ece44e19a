//! Stage 10: the loads' part of f, F·β̄_k + L·γ̄_k (eq. 56), and M and f
//! in their final form.
//!
//! Loads are kept apart per effect so that scenes can pick them: one sum
//! per effect, expanded on its own, since the loads of one effect can
//! cancel in part (a torque and its reaction on two bodies leave only the
//! relative rotation's partial velocity). The weights of a composite's
//! members act as one at its mass centre: Σ mᵢ g·β̄ᵢ = M g·β̄_G.

use appell_symbolic::{Graph, Id, RateRules, Substitution, Symbol, SymbolicError};

use super::assembly::Assembled;
use super::assembly::Composite;
use super::partials::{raw_parts, through_c, PartialVelocities};
use super::speed_map::SpeedMap;
use crate::algebra::{dot, expanded, expanded3, mat_t_vec, Vec3};
use crate::model::Model;

/// The output of stage 10.
pub struct Equations {
    /// M (l×l), row-major, symmetric.
    pub mass: Vec<Id>,
    /// f (l).
    pub forcing: Vec<Id>,
    /// The inertial part of f, per speed, as terms (for scenes).
    pub inertial_terms: Vec<Vec<Id>>,
    /// Each effect's part of f, per speed (for scenes).
    pub load_terms: Vec<(String, Vec<Id>)>,
}

/// Stage 10. A load may depend on coordinate rates (a damper, friction):
/// `fixed` writes the dependent ones as C ẏ + c.
pub fn equations(
    model: &mut Model,
    assembled: Assembled,
    composites: &[Composite],
    partials: &PartialVelocities,
    map: &SpeedMap,
    rules: &RateRules,
    fixed: &mut Substitution,
) -> Result<Equations, SymbolicError> {
    let l = map.speed_rates.len();
    let Assembled {
        mut mass,
        mut forcing_terms,
    } = assembled;
    let inertial_terms = forcing_terms.clone();
    let mut load_terms = force_terms(model, composites, partials, map, rules)?;
    load_terms.extend(torque_terms(model, partials, l)?);
    let g = &mut model.g;
    let mut merged: Vec<(String, Vec<Id>)> = Vec::new();
    for (effect, per_k) in load_terms {
        match merged.iter_mut().find(|(e, _)| *e == effect) {
            Some((_, sum)) => {
                for (s, x) in sum.iter_mut().zip(per_k) {
                    *s = g.add(*s, x)?;
                }
            }
            None => merged.push((effect, per_k)),
        }
    }
    for (_, per_k) in merged.iter_mut() {
        for x in per_k.iter_mut() {
            let in_speeds = fixed.apply(g, *x)?;
            *x = expanded(g, in_speeds)?;
        }
        for k in 0..l {
            forcing_terms[k].push(per_k[k]);
        }
    }
    for k in 0..l {
        for j in k..l {
            mass[k * l + j] = expanded(g, mass[k * l + j])?;
        }
        for j in 0..k {
            mass[k * l + j] = mass[j * l + k];
        }
    }
    let forcing: Vec<Id> = forcing_terms
        .iter()
        .map(|t| g.sum(t).and_then(|e| expanded(g, e)))
        .collect::<Result<_, _>>()?;
    Ok(Equations {
        mass,
        forcing,
        inertial_terms,
        load_terms: merged,
    })
}

/// F·β̄_k per force, with its effect; a composite's weight at its centre.
fn force_terms(
    model: &mut Model,
    composites: &[Composite],
    partials: &PartialVelocities,
    map: &SpeedMap,
    rules: &RateRules,
) -> Result<Vec<(String, Vec<Id>)>, SymbolicError> {
    let l = map.speed_rates.len();
    let rates = model.coordinate_rates();
    let g = &mut model.g;
    let zero = g.int(0)?;
    let mut out = Vec::new();
    for (fi, f) in model.forces.iter().enumerate() {
        let weight = match (f.weight_of.map(|b| &composites[b]), model.gravity) {
            (Some(Composite::Member(_)), _) => Some(None),
            (
                Some(Composite::Leader {
                    mass: total,
                    center,
                    ..
                }),
                Some(gvec),
            ) => Some(Some(composite_weight(
                g, &rates, map, rules, *total, *center, gvec,
            )?)),
            _ => None,
        };
        let per_k: Vec<Id> = match weight {
            Some(None) => vec![zero; l],
            Some(Some((w, beta))) => (0..l)
                .map(|k| dot(g, w, beta[k]))
                .collect::<Result<_, _>>()?,
            None => (0..l)
                .map(|k| dot(g, f.vector, partials.forces[fi].parts[k]))
                .collect::<Result<_, _>>()?,
        };
        out.push((f.effect.clone(), per_k));
    }
    Ok(out)
}

/// A composite's weight M g and β̄_k of its mass centre.
fn composite_weight(
    g: &mut Graph,
    rates: &[Symbol],
    map: &SpeedMap,
    rules: &RateRules,
    total: Id,
    center: Vec3,
    gravity: Vec3,
) -> Result<(Vec3, Vec<Vec3>), SymbolicError> {
    let zero = g.int(0)?;
    let mut v = [zero; 3];
    for i in 0..3 {
        v[i] = g.time_derivative(center[i], rules)?;
    }
    let (parts, rest) = raw_parts(g, rates, v)?;
    let (beta, _) = through_c(g, map, &parts, rest)?;
    let mut w = gravity;
    for x in w.iter_mut() {
        *x = g.mul(*x, total)?;
    }
    Ok((w, beta))
}

/// L·γ̄_k per torque, in the frame it acts on, with its effect.
fn torque_terms(
    model: &mut Model,
    partials: &PartialVelocities,
    l: usize,
) -> Result<Vec<(String, Vec<Id>)>, SymbolicError> {
    let g = &mut model.g;
    let mut out = Vec::new();
    for (ti, t) in model.torques.iter().enumerate() {
        let rot = model.frames[t.frame].rot;
        let vector = mat_t_vec(g, &rot, t.vector)?;
        let vector = expanded3(g, vector)?;
        let mut per_k = Vec::with_capacity(l);
        for k in 0..l {
            let gamma = mat_t_vec(g, &rot, partials.torques[ti].parts[k])?;
            let gamma = expanded3(g, gamma)?;
            per_k.push(dot(g, vector, gamma)?);
        }
        out.push((t.effect.clone(), per_k));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::super::testing::{self, assert_agrees};
    use super::super::Options;

    #[test]
    fn gravity_gives_the_pendulums_restoring_force() {
        // f = (−m g N.y)·β̄ = −m g l sin q.
        let mut run = testing::run(testing::PENDULUM);
        let later = run.later(&Options::default());
        let g = &mut run.model.g;
        assert_agrees(g, later.equations.forcing[0], "-m*g*l*sin(q)");
        assert_eq!(later.equations.load_terms.len(), 1);
        assert_eq!(later.equations.load_terms[0].0, "gravity");
    }

    #[test]
    fn an_input_force_enters_through_the_dependent_rate() {
        // F = f N.x at the centre, β̄ = (−r, 0, 0): f_φ = −r f.
        let mut run = testing::run(testing::DISC_ON_A_LINE);
        let later = run.later(&Options::default());
        let g = &mut run.model.g;
        assert_agrees(g, later.equations.forcing[0], "-r*f");
        assert_eq!(later.equations.load_terms[0].0, "push");
    }
}
