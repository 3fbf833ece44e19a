//! Stage 7: acceleration remainders, the accelerations with ÿ = 0 (eq. 37,
//! which reads, with the OCR slip of the printed text mended,
//! r̈ = Σ_k (β̄_k ÿ_k + β̄̇_k ẏ_k) + β̄̇: the remainder is its last two terms).
//!
//! For a velocity v(q, q̇, t) linear in q̇ the remainder is
//! Σ_s ∂v/∂q_s q̇_s + ∂v/∂t (the directional derivative along q̇, rates held
//! fixed, then replaced by C ẏ + c) plus Σ_d ∂v/∂q̇_d r_d, with r_d the
//! dependent rates' own remainders (w for a numeric elimination).
//! Differentiating each β̄_k through C instead would multiply every partial
//! derivative by q̇ = C ẏ + c once per speed. The directional derivative is
//! taken on the twin, whose direction cosines are symbols, and the values
//! are put back afterwards.
//!
//! Angular acceleration remainders α are kept in each body's frame; a body
//! whose γ̄ were turned from an earlier body's takes that body's α, turned,
//! plus ω × ω_rel and the relative rates' own remainders.

use appell_symbolic::{Id, Substitution, Symbol, SymbolicError};

use super::partials::PartialVelocities;
use super::speed_map::{Rates, SpeedMap};
use super::Calculus;
use crate::algebra::{cross, expanded3, mat_t_vec, turned, Vec3};
use crate::model::Model;

/// The output of stage 7.
pub struct Remainders {
    /// ÿ_k → 0.
    pub zero_accels: Substitution,
    /// Each dependent rate's symbol and its own remainder r_d.
    pub dependent: Vec<(Symbol, Id)>,
    /// The coordinates of `dependent`, in order.
    pub coordinates: Vec<usize>,
    /// Which of `coordinates` are a quaternion's components: their terms
    /// take ∂v/∂q̇_d from the velocity as given (see [`Self::of_velocity`]).
    pub quaternion: Vec<bool>,
    /// Per body: α with ÿ = 0 in its frame (None for a particle).
    pub alphas: Vec<Option<Vec3>>,
}

impl Remainders {
    /// The remainder of a velocity `v` (the twin's, when there is one).
    /// `parts`, when given, are the partial velocities ∂v/∂q̇_r already
    /// built for β̄ (the same values): the dependent rates' terms reuse
    /// them, except a quaternion's. The twin writes a quaternion frame's
    /// direction cosines turning at ω = 2 G(e) ė, which equals the rate of
    /// R(e) only where e · ė = 0; its ∂v/∂ė is that of the twin's own v
    /// (G(e) e = 0), while R(e)'s is not, and the dependent rates' own
    /// remainders r_d have a part along e (e · ë = −|ė|²). Mixing the two
    /// would add a term along the body's offset times |ω|². Left factored:
    /// a remainder enters f only through dot products with the partial
    /// velocities.
    pub fn of_velocity(
        &self,
        g: &mut appell_symbolic::Graph,
        rates: &mut Rates,
        uncut: &mut Substitution,
        v: Vec3,
        parts: Option<&[Vec3]>,
    ) -> Result<Vec3, SymbolicError> {
        let zero = g.int(0)?;
        let mut out = [zero; 3];
        for i in 0..3 {
            let along = g.time_derivative(v[i], &rates.along)?;
            let along = uncut.apply(g, along)?;
            let mut terms = vec![rates.fixed.apply(g, along)?];
            let dependent = self.dependent.iter().zip(&self.coordinates);
            for ((&(rate, r), &d), &quaternion) in dependent.zip(&self.quaternion) {
                let c = match parts {
                    Some(p) if !quaternion => p[d][i],
                    _ => {
                        let c = g.diff(v[i], rate)?;
                        let c = uncut.apply(g, c)?;
                        rates.fixed.apply(g, c)?
                    }
                };
                if g.is_zero(c) {
                    continue;
                }
                terms.push(g.mul(c, r)?);
            }
            out[i] = g.sum(&terms)?;
        }
        Ok(out)
    }
}

/// Stage 7: the dependent rates' remainders and each body's α.
pub fn remainders(
    model: &mut Model,
    dependent: &[usize],
    map: &SpeedMap,
    partials: &PartialVelocities,
    rates: &mut Rates,
    calculus: &mut Calculus,
) -> Result<Remainders, SymbolicError> {
    let quaternion = dependent
        .iter()
        .map(|d| model.quaternions.iter().any(|block| block.contains(d)))
        .collect();
    let g = &mut model.g;
    let zero = g.int(0)?;
    let mut zero_accels = Substitution::new();
    for &accel in &map.accels {
        zero_accels.insert(accel, zero);
    }
    let mut dependent_remainders = Vec::new();
    for &d in dependent {
        let e = g.time_derivative(map.qdot[d], &rates.reduced)?;
        let e = zero_accels.apply(g, e)?;
        dependent_remainders.push((model.coords[d].1.rate, e));
    }
    let mut out = Remainders {
        zero_accels,
        dependent: dependent_remainders,
        coordinates: dependent.to_vec(),
        quaternion,
        alphas: Vec::new(),
    };
    for (bi, b) in model.bodies.iter().enumerate() {
        let alpha = match &partials.rotations[bi] {
            Some(rot) => match &partials.relative[bi] {
                Some(relative) if out.alphas[relative.body].is_some() => {
                    let omega_b = partials.bodies[bi].omega_b;
                    Some(turned_alpha(g, &out, relative, omega_b, rates)?)
                }
                _ => {
                    let f = b.frame.expect("rigid");
                    let omega = calculus
                        .twin
                        .as_ref()
                        .map_or(model.frames[f].omega, |t| t.frames[f].omega);
                    let alpha_n = out.of_velocity(g, rates, &mut calculus.uncut, omega, None)?;
                    let alpha_b = mat_t_vec(g, rot, alpha_n)?;
                    Some(expanded3(g, alpha_b)?)
                }
            },
            None => None,
        };
        out.alphas.push(alpha);
    }
    Ok(out)
}

/// α = (the earlier body's α, turned) + ω × ω_rel + the relative rates'
/// own remainders (dependent ones).
fn turned_alpha(
    g: &mut appell_symbolic::Graph,
    done: &Remainders,
    relative: &super::partials::RelativeFrame,
    omega_b: Vec3,
    rates: &mut Rates,
) -> Result<Vec3, SymbolicError> {
    let zero = g.int(0)?;
    let parent = done.alphas[relative.body].expect("rigid");
    let dw = relative.omega;
    let mut w_rel = [zero; 3];
    for i in 0..3 {
        w_rel[i] = rates.fixed.apply(g, dw[i])?;
    }
    let spin = cross(g, omega_b, w_rel)?;
    let mut alpha = turned(g, &relative.rel, parent, spin)?;
    for i in 0..3 {
        let mut terms = vec![alpha[i]];
        for &(rate, r) in &done.dependent {
            let c = g.diff(dw[i], rate)?;
            if !g.is_zero(c) {
                terms.push(g.mul(c, r)?);
            }
        }
        alpha[i] = g.sum(&terms)?;
    }
    Ok(alpha)
}

#[cfg(test)]
mod tests {
    use super::super::testing::{self, assert_agrees};

    #[test]
    fn the_pendulums_remainder_is_its_centripetal_acceleration() {
        // a = l q̈ (cos q, sin q) + l q̇² (−sin q, cos q): the remainder is the
        // second part, l q̇² towards the pivot.
        let mut run = testing::run(testing::PENDULUM);
        let (p, r) = run.remainders();
        let g = &mut run.model.g;
        let zero = g.int(0).unwrap();
        let center = run.model.bodies[0].center;
        let mut v = [zero; 3];
        for i in 0..3 {
            v[i] = g.time_derivative(center[i], &run.calculus.rules).unwrap();
        }
        let a = r
            .of_velocity(
                g,
                &mut run.rates,
                &mut run.calculus.uncut,
                v,
                Some(&p.center_parts[0]),
            )
            .unwrap();
        assert_agrees(g, a[0], "-l*q_dot^2*sin(q)");
        assert_agrees(g, a[1], "l*q_dot^2*cos(q)");
        assert!(r.dependent.is_empty());
        assert_eq!(r.alphas, vec![None]);
    }

    #[test]
    fn a_numeric_dependent_rates_remainder_is_w() {
        // The knife edge: ÿ's remainder is w (the numeric solve's), and the
        // sleigh turning at a constant rate has no angular remainder.
        let mut run = testing::run(testing::SLEIGH);
        let (_, r) = run.remainders();
        let g = &mut run.model.g;
        assert_eq!(r.coordinates, vec![1]);
        assert_agrees(g, r.dependent[0].1, "__w_0");
        let alpha = r.alphas[0].expect("a rigid body");
        assert!(alpha.iter().all(|e| g.is_zero(*e)));
    }
}
