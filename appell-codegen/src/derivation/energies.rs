//! Stage 11: the energies the generated code reports.
//!
//! T = ½ Σ (m v·v + ω·I ω), from the partial velocities (v = Σ β̄_k ẏ_k + β̄);
//! V = −Σ F·r over the `gravity` effect's constant forces; and the power of
//! the loads that depend on an input, F·v_P + L·ω, whose integral closes the
//! energy balance of a driven system.

use appell_symbolic::{Id, Number, Substitution, SymbolSet, SymbolicError};

use super::partials::PartialVelocities;
use super::speed_map::SpeedMap;
use crate::algebra::{combine, dot, expanded, mat_vec};
use crate::model::Model;

/// The output of stage 11.
pub struct Energies {
    /// Kinetic energy T.
    pub kinetic: Id,
    /// Potential energy V of the gravity effect's loads.
    pub potential: Id,
    /// Power of the loads that depend on inputs.
    pub input_power: Id,
    /// The power of each input-dependent load, with its effect (for scenes).
    pub power_terms: Vec<(String, Id)>,
}

/// Stage 11.
pub fn energies(
    model: &mut Model,
    partials: &PartialVelocities,
    map: &SpeedMap,
    fixed: &mut Substitution,
) -> Result<Energies, SymbolicError> {
    let g = &mut model.g;
    let speed_rates = &map.speed_rates;
    let mut ke_terms = Vec::new();
    for (bi, b) in model.bodies.iter().enumerate() {
        let t = &partials.bodies[bi];
        let v = combine(g, &t.beta, t.beta0, speed_rates)?;
        let vv = dot(g, v, v)?;
        ke_terms.push(g.mul(b.mass, vv)?);
        if b.frame.is_some() {
            let iw = mat_vec(g, &b.inertia, t.omega_b)?;
            ke_terms.push(dot(g, t.omega_b, iw)?);
        }
    }
    let ke = g.sum(&ke_terms)?;
    let kinetic = g.scale(ke, Number::ratio(1, 2).expect("1/2"))?;
    let kinetic = expanded(g, kinetic)?;
    let mut v_terms = Vec::new();
    for f in model.forces.iter().filter(|f| f.effect == "gravity") {
        let w = dot(g, f.vector, f.point)?;
        v_terms.push(g.neg(w)?);
    }
    let potential = g.sum(&v_terms)?;
    let potential = expanded(g, potential)?;
    let inputs_set = SymbolSet::from_symbols(model.inputs.iter().map(|(_, s)| *s));
    let mut p_terms = Vec::new();
    let mut power_terms: Vec<(String, Id)> = Vec::new();
    for (fi, f) in model.forces.iter().enumerate() {
        if f.vector.iter().any(|&c| g.depends_on_any(c, &inputs_set)) {
            let at = &partials.forces[fi];
            let v = combine(g, &at.parts, at.rest, speed_rates)?;
            let p = dot(g, f.vector, v)?;
            let p = fixed.apply(g, p)?;
            p_terms.push(p);
            power_terms.push((f.effect.clone(), p));
        }
    }
    for (ti, t) in model.torques.iter().enumerate() {
        if t.vector.iter().any(|&c| g.depends_on_any(c, &inputs_set)) {
            let at = &partials.torques[ti];
            let w = combine(g, &at.parts, at.rest, speed_rates)?;
            let p = dot(g, t.vector, w)?;
            let p = fixed.apply(g, p)?;
            p_terms.push(p);
            power_terms.push((t.effect.clone(), p));
        }
    }
    let input_power = g.sum(&p_terms)?;
    let input_power = expanded(g, input_power)?;
    Ok(Energies {
        kinetic,
        potential,
        input_power,
        power_terms,
    })
}

#[cfg(test)]
mod tests {
    use super::super::testing::{self, assert_agrees};
    use super::super::Options;

    #[test]
    fn the_pendulums_energies() {
        let mut run = testing::run(testing::PENDULUM);
        let later = run.later(&Options::default());
        let g = &mut run.model.g;
        assert_agrees(g, later.energies.kinetic, "m*l^2*q_dot^2/2");
        assert_agrees(g, later.energies.potential, "-m*g*l*cos(q)");
        assert!(g.is_zero(later.energies.input_power));
    }

    #[test]
    fn an_input_forces_power_is_kept_with_its_effect() {
        // T = ½ (m r² + j) φ̇², P = f ẋ = −r f φ̇.
        let mut run = testing::run(testing::DISC_ON_A_LINE);
        let later = run.later(&Options::default());
        let g = &mut run.model.g;
        assert_agrees(g, later.energies.kinetic, "(m*r^2 + j)*phi_dot^2/2");
        assert_agrees(g, later.energies.input_power, "-r*f*phi_dot");
        assert_eq!(later.energies.power_terms[0].0, "push");
    }
}
