//! Stage 8: Appell's equations M ÿ = f (eq. 56), body by body.
//!
//! M_kl = Σ m β̄_k·β̄_l + γ̄_k·I γ̄_l and
//! f_k = Σ F·β̄_k + L·γ̄_k − m a_rem·β̄_k − γ̄_k·(I α_rem + ω × I ω), the
//! rotational terms in each body's frame, where I is constant. This stage
//! builds the inertial part (the loads come in stage 10), for a given
//! folding of composites and rotors (stage 9 chooses which).

use appell_symbolic::{Graph, Id, Symbol, SymbolicError};

use super::partials::{raw_parts, through_c, PartialVelocities};
use super::remainders::Remainders;
use super::speed_map::{Rates, SpeedMap};
use super::Calculus;
use crate::algebra::{cross, dot, mat_vec, Mat3, Vec3};
use crate::model::Body;

/// An axisymmetric body turning about its symmetry axis, which is fixed in
/// another body's frame (a wheel on its axle; see [`super::folding::rotors`]).
#[derive(Clone, Copy)]
pub struct Rotor {
    /// The body whose frame carries the axis.
    pub carrier: usize,
    /// The axis: 0, 1 or 2 of the carrier's (and the rotor's) frame.
    pub axis: usize,
    /// The coordinate whose rate is the spin rate.
    pub coordinate: usize,
    /// The moment of inertia about the axis.
    pub axial: Id,
    /// Its terms written with its axial partial angular velocities whole
    /// (λ o_k o_j), or split against the carrier's (see [`super::folding::rotors`]).
    pub whole: bool,
}

/// A body's part in a composite (see [`super::folding::composite_bodies`]).
pub enum Composite {
    /// Its translational terms are its own.
    Alone,
    /// It carries the group's translational terms: the total mass, the
    /// composite mass centre (N components) and the members' parallel-axis
    /// inertia about it (in its frame).
    Leader {
        /// The total mass.
        mass: Id,
        /// The composite mass centre, N components.
        center: Vec3,
        /// The composite mass centre less the leader's, in its frame.
        shift: Vec3,
        /// The members' parallel-axis inertia about the composite centre.
        extra_inertia: Mat3,
    },
    /// Its translational terms are carried by its group's leader (the
    /// index).
    Member(usize),
}

/// M's entries and f's terms per speed.
#[derive(Clone)]
pub struct Assembled {
    /// M (l×l), row-major; the upper triangle is filled.
    pub mass: Vec<Id>,
    /// The terms of each f_k, not yet summed.
    pub forcing_terms: Vec<Vec<Id>>,
}

/// Everything the assembly reads.
pub struct Assembler<'a> {
    /// The bodies.
    pub bodies: &'a [Body],
    /// Stage 6.
    pub partials: &'a PartialVelocities,
    /// Stage 7.
    pub remainders: &'a mut Remainders,
    /// Stage 4.
    pub map: &'a SpeedMap,
    /// Stage 4's rate rules.
    pub rates: &'a mut Rates,
    /// The derivatives and the twin.
    pub calculus: &'a mut Calculus,
    /// Every coordinate rate q̇_r.
    pub coordinate_rates: Vec<Symbol>,
}

/// A body's translational term: its mass, β̄_k, its centre (the twin's
/// when there is one) and ∂v/∂q̇_r of that centre.
struct Translational {
    mass: Id,
    beta: Vec<Vec3>,
    center: Vec3,
    parts: Vec<Vec3>,
}

impl Assembler<'_> {
    /// M and f's inertial terms with the given composites and rotors.
    pub fn assemble(
        &mut self,
        g: &mut Graph,
        composites: &[Composite],
        rotors: &[Option<Rotor>],
    ) -> Result<Assembled, SymbolicError> {
        let l = self.map.speed_rates.len();
        let zero = g.int(0)?;
        let mut out = Assembled {
            mass: vec![zero; l * l],
            forcing_terms: vec![Vec::new(); l],
        };
        for bi in 0..self.bodies.len() {
            self.body(g, bi, composites, rotors, &mut out)?;
        }
        Ok(out)
    }

    /// Body `bi`'s part of M and f.
    fn body(
        &mut self,
        g: &mut Graph,
        bi: usize,
        composites: &[Composite],
        rotors: &[Option<Rotor>],
        out: &mut Assembled,
    ) -> Result<(), SymbolicError> {
        let l = self.map.speed_rates.len();
        let zero = g.int(0)?;
        let b = &self.bodies[bi];
        let t = &self.partials.bodies[bi];
        let mut inertia = self.carried_inertia(g, bi, rotors)?;
        if let Some(r) = rotors[bi] {
            self.rotor(g, r, out)?;
        }
        let translational = self.translational(g, bi, &composites[bi], &mut inertia)?;
        if let Some(tr) = &translational {
            let center_rules = self
                .calculus
                .twin_rules
                .as_ref()
                .unwrap_or(&self.calculus.rules);
            let mut v = [zero; 3];
            for i in 0..3 {
                v[i] = g.time_derivative(tr.center[i], center_rules)?;
            }
            let a_rem = self.remainders.of_velocity(
                g,
                self.rates,
                &mut self.calculus.uncut,
                v,
                Some(&tr.parts),
            )?;
            for k in 0..l {
                let ab = dot(g, a_rem, tr.beta[k])?;
                let inertial = g.mul(tr.mass, ab)?;
                out.forcing_terms[k].push(g.neg(inertial)?);
            }
        }
        for k in 0..l {
            for j in k..l {
                let mut e = zero;
                if let Some(tr) = &translational {
                    let bb = dot(g, tr.beta[k], tr.beta[j])?;
                    e = g.mul(tr.mass, bb)?;
                }
                if b.frame.is_some() && rotors[bi].is_none() {
                    let ig = mat_vec(g, &inertia, t.gamma_b[j])?;
                    let rot = dot(g, t.gamma_b[k], ig)?;
                    e = g.add(e, rot)?;
                }
                out.mass[k * l + j] = g.add(out.mass[k * l + j], e)?;
            }
        }
        if let (Some(alpha_b), None) = (self.remainders.alphas[bi], rotors[bi]) {
            let i_alpha = mat_vec(g, &inertia, alpha_b)?;
            let i_omega = mat_vec(g, &inertia, t.omega_b)?;
            let gyro = cross(g, t.omega_b, i_omega)?;
            let mut total = [zero; 3];
            for i in 0..3 {
                total[i] = g.add(i_alpha[i], gyro[i])?;
            }
            for k in 0..l {
                let e = dot(g, t.gamma_b[k], total)?;
                out.forcing_terms[k].push(g.neg(e)?);
            }
        }
        Ok(())
    }

    /// Body `bi`'s inertia, with its rotors' added but for the axial moment
    /// of a rotor written whole (the rotor's own terms carry it).
    fn carried_inertia(
        &self,
        g: &mut Graph,
        bi: usize,
        rotors: &[Option<Rotor>],
    ) -> Result<Mat3, SymbolicError> {
        let mut inertia = self.bodies[bi].inertia;
        for (ri, r) in rotors.iter().enumerate() {
            if let Some(r) = r.filter(|r| r.carrier == bi) {
                let rotor_inertia = &self.bodies[ri].inertia;
                for (i, (row, rotor_row)) in inertia.iter_mut().zip(rotor_inertia).enumerate() {
                    for (j, (e, x)) in row.iter_mut().zip(rotor_row).enumerate() {
                        if r.whole && i == r.axis && j == r.axis {
                            continue;
                        }
                        *e = g.add(*e, *x)?;
                    }
                }
            }
        }
        Ok(inertia)
    }

    /// A rotor's terms, folded into its carrier's (see
    /// [`super::folding`]): written whole, λ o_k o_j and
    /// λ (ν o_k + Ω γ̄ᶜ_k·(ωᶜ × a)), a product of two sums the expansion keeps
    /// whole; or split, λ (s_k γ̄ᶜ_j·a + s_j γ̄ᶜ_k·a + s_k s_j) beside the
    /// carrier's λ γ̄ᶜ_k·a γ̄ᶜ_j·a, and
    /// λ (θ̈ γ̄ᶜ_k·a + θ̇ γ̄ᶜ_k·(ωᶜ × a) + s_k (αᶜ·a + θ̈)).
    fn rotor(&mut self, g: &mut Graph, r: Rotor, out: &mut Assembled) -> Result<(), SymbolicError> {
        let l = self.map.speed_rates.len();
        let zero = g.int(0)?;
        let c_t = &self.partials.bodies[r.carrier];
        let a = r.axis;
        let s: Vec<Id> = (0..l).map(|k| self.map.c[r.coordinate * l + k]).collect();
        let spin = self.map.qdot[r.coordinate];
        let spin_rate = g.time_derivative(spin, &self.rates.reduced)?;
        let spin_rate = self.remainders.zero_accels.apply(g, spin_rate)?;
        let alpha = self.remainders.alphas[r.carrier].expect("rigid");
        let mut axis = [zero; 3];
        axis[a] = g.int(1)?;
        let w_cross_a = cross(g, c_t.omega_b, axis)?;
        let (mass, forcing_terms) = (&mut out.mass, &mut out.forcing_terms);
        if r.whole {
            let o: Vec<Id> = (0..l)
                .map(|k| g.add(s[k], c_t.gamma_b[k][a]))
                .collect::<Result<_, _>>()?;
            let axial_rate = g.add(c_t.omega_b[a], spin)?;
            let axial_accel = g.add(alpha[a], spin_rate)?;
            for k in 0..l {
                for j in k..l {
                    let e = g.mul(o[k], o[j])?;
                    let e = g.mul(r.axial, e)?;
                    mass[k * l + j] = g.add(mass[k * l + j], e)?;
                }
                let x = g.mul(axial_accel, o[k])?;
                let y = dot(g, c_t.gamma_b[k], w_cross_a)?;
                let y = g.mul(axial_rate, y)?;
                let sum = g.add(x, y)?;
                let e = g.mul(r.axial, sum)?;
                forcing_terms[k].push(g.neg(e)?);
            }
        } else {
            for k in 0..l {
                for j in k..l {
                    let x = g.mul(s[k], c_t.gamma_b[j][a])?;
                    let y = g.mul(s[j], c_t.gamma_b[k][a])?;
                    let z = g.mul(s[k], s[j])?;
                    let sum = g.sum(&[x, y, z])?;
                    let e = g.mul(r.axial, sum)?;
                    mass[k * l + j] = g.add(mass[k * l + j], e)?;
                }
                let x = g.mul(spin_rate, c_t.gamma_b[k][a])?;
                let y = dot(g, c_t.gamma_b[k], w_cross_a)?;
                let y = g.mul(spin, y)?;
                let z = g.add(alpha[a], spin_rate)?;
                let z = g.mul(s[k], z)?;
                let sum = g.sum(&[x, y, z])?;
                let e = g.mul(r.axial, sum)?;
                forcing_terms[k].push(g.neg(e)?);
            }
        }
        Ok(())
    }

    /// Body `bi`'s translational term: its own, none for a composite's
    /// member, or its composite's for a leader (whose inertia then gains
    /// the members' parallel-axis terms).
    fn translational(
        &mut self,
        g: &mut Graph,
        bi: usize,
        composite: &Composite,
        inertia: &mut Mat3,
    ) -> Result<Option<Translational>, SymbolicError> {
        let b = &self.bodies[bi];
        let twin = &self.calculus.twin;
        Ok(match composite {
            Composite::Member(_) => None,
            Composite::Alone => Some(Translational {
                mass: b.mass,
                beta: self.partials.bodies[bi].beta.clone(),
                center: twin.as_ref().map_or(b.center, |t| t.bodies[bi].center),
                parts: self.partials.center_parts[bi].clone(),
            }),
            Composite::Leader {
                mass: total,
                center,
                shift,
                extra_inertia,
            } => {
                for (r, row) in inertia.iter_mut().enumerate() {
                    for (c, e) in row.iter_mut().enumerate() {
                        *e = g.add(*e, extra_inertia[r][c])?;
                    }
                }
                let zero = g.int(0)?;
                let mut v = [zero; 3];
                for i in 0..3 {
                    v[i] = g.time_derivative(center[i], &self.calculus.rules)?;
                }
                let (parts, rest) = raw_parts(g, &self.coordinate_rates, v)?;
                let (beta, _) = through_c(g, self.map, &parts, rest)?;
                let twin_center = match twin {
                    Some(t) => {
                        let rot = t.frames[b.frame.expect("rigid")].rot;
                        let mut c = t.bodies[bi].center;
                        for (i, c) in c.iter_mut().enumerate() {
                            let mut terms = vec![*c];
                            for (j, sh) in shift.iter().enumerate() {
                                terms.push(g.mul(rot[i][j], *sh)?);
                            }
                            *c = g.sum(&terms)?;
                        }
                        c
                    }
                    None => *center,
                };
                Some(Translational {
                    mass: *total,
                    beta,
                    center: twin_center,
                    parts,
                })
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::testing::{self, assert_agrees};
    use super::super::Options;

    #[test]
    fn the_pendulums_mass_is_m_l_squared_and_its_inertial_forcing_vanishes() {
        // M = m β̄·β̄ = m l²; −m a_rem·β̄ = −m l² q̇² (−sin q cos q + cos q sin q) = 0.
        let mut run = testing::run(testing::PENDULUM);
        let later = run.later(&Options::default());
        let g = &mut run.model.g;
        assert_agrees(g, later.equations.mass[0], "m*l^2");
        let inertial = g.sum(&later.equations.inertial_terms[0]).unwrap();
        assert_agrees(g, inertial, "0");
    }

    #[test]
    fn a_rigid_body_adds_its_rotational_inertia() {
        // The disc: m β̄·β̄ + γ̄·I γ̄ = m r² + j.
        let mut run = testing::run(testing::DISC_ON_A_LINE);
        let later = run.later(&Options::default());
        let g = &mut run.model.g;
        assert_agrees(g, later.equations.mass[0], "m*r^2 + j");
    }
}
