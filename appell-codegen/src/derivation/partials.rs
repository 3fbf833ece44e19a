//! Stage 6: partial velocities β̄_k and partial angular velocities γ̄_k
//! (eq. 54), the coefficients of ẏ_k in the velocities with ż eliminated.
//!
//! A mass centre's β̄_k = Σ_r C_rk J_r and β̄ = J_t + Σ_r c_r J_r are built
//! from its partial velocities J_r = ∂v/∂q̇_r, each a function of q alone
//! and kept as differentiated: C (with the numeric elimination's X) is not
//! multiplied into them, so each β̄_k is one short sum per component.
//!
//! A rigid body's γ̄_k are taken in its own frame. When its frame is an
//! earlier body's frame turned by a simple rotation (every direction cosine
//! between the two a single term) with a relative angular velocity of
//! constant components (a steer, a wheel's spin), γ̄ is the earlier body's
//! turned, plus the relative part: the chain of rotations is not expanded
//! again.
//!
//! Loads keep the expanded form, which is shorter for a constant force's
//! few components.

use appell_symbolic::{Graph, Node, RateRules, Substitution, Symbol, SymbolicError};

use super::speed_map::SpeedMap;
use crate::algebra::{
    combine, dot, expanded, expanded3, mat_t_vec, split_linear, turned, Mat3, Vec3,
};
use crate::model::{Body, Frame, Model};

/// Per body: velocity pieces and, for rigid bodies, body-frame angular ones.
pub struct BodyTerms {
    /// β̄_k.
    pub beta: Vec<Vec3>,
    /// β̄ (the part of the velocity free of ẏ).
    pub beta0: Vec3,
    /// γ̄_k in body components.
    pub gamma_b: Vec<Vec3>,
    /// ω in body components.
    pub omega_b: Vec3,
}

/// A body whose γ̄ were built from an earlier body's (see the module docs).
pub struct RelativeFrame {
    /// The earlier body.
    pub body: usize,
    /// The direction cosines between the two frames (v_this = rel · v_that).
    pub rel: Mat3,
    /// The relative angular velocity, in this body's frame.
    pub omega: Vec3,
}

/// The coefficients of ẏ in a velocity, and the rest.
pub struct SpeedParts {
    /// Per speed.
    pub parts: Vec<Vec3>,
    /// The part free of ẏ.
    pub rest: Vec3,
}

/// The output of stage 6.
pub struct PartialVelocities {
    /// Per body.
    pub bodies: Vec<BodyTerms>,
    /// Per body: the earlier body its γ̄ were turned from.
    pub relative: Vec<Option<RelativeFrame>>,
    /// Per body: its frame's rotation matrix (None for a particle).
    pub rotations: Vec<Option<Mat3>>,
    /// Per body: ∂v/∂q̇_r of its mass centre.
    pub center_parts: Vec<Vec<Vec3>>,
    /// Per force: β̄ of its point.
    pub forces: Vec<SpeedParts>,
    /// Per torque: γ̄ of its frame (N components).
    pub torques: Vec<SpeedParts>,
}

/// Stage 6. `fixed` substitutes the dependent rates (stage 4).
pub fn partial_velocities(
    model: &mut Model,
    map: &SpeedMap,
    rules: &RateRules,
    fixed: &Substitution,
) -> Result<PartialVelocities, SymbolicError> {
    let rates = model.coordinate_rates();
    let l = map.speed_rates.len();
    let g = &mut model.g;
    let zero = g.int(0)?;
    let mut sub = fixed.clone();
    let mut out = PartialVelocities {
        bodies: Vec::new(),
        relative: Vec::new(),
        rotations: Vec::new(),
        center_parts: Vec::new(),
        forces: Vec::new(),
        torques: Vec::new(),
    };
    for b in &model.bodies {
        let mut v = [zero; 3];
        for i in 0..3 {
            v[i] = g.time_derivative(b.center[i], rules)?;
        }
        let (parts, rest) = raw_parts(g, &rates, v)?;
        let (beta, beta0) = through_c(g, map, &parts, rest)?;
        out.center_parts.push(parts);
        let (gamma_b, omega_b, rotation, relative) = match b.frame {
            Some(fi) => {
                let frame = &model.frames[fi];
                let turned_from = turned_from_earlier(
                    g,
                    (&model.bodies, &model.frames),
                    &out.bodies,
                    fi,
                    map,
                    &rates,
                )?;
                match turned_from {
                    Some((gamma_b, omega_b, relative)) => {
                        (gamma_b, omega_b, Some(frame.rot), Some(relative))
                    }
                    None => {
                        let rot = frame.rot;
                        let (parts, rest) = split_linear(g, frame.omega, &rates)?;
                        let parts = parts
                            .iter()
                            .map(|v| mat_t_vec(g, &rot, *v).and_then(|x| expanded3(g, x)))
                            .collect::<Result<Vec<_>, _>>()?;
                        let rest = mat_t_vec(g, &rot, rest)?;
                        let rest = expanded3(g, rest)?;
                        let (gamma_b, gamma0_b) = through_c(g, map, &parts, rest)?;
                        let omega_b = combine(g, &gamma_b, gamma0_b, &map.speed_rates)?;
                        (gamma_b, omega_b, Some(rot), None)
                    }
                }
            }
            None => (vec![[zero; 3]; l], [zero; 3], None, None),
        };
        out.relative.push(relative);
        out.bodies.push(BodyTerms {
            beta,
            beta0,
            gamma_b,
            omega_b,
        });
        out.rotations.push(rotation);
    }
    for f in &model.forces {
        let mut v = [zero; 3];
        for i in 0..3 {
            let d = g.time_derivative(f.point[i], rules)?;
            let d = sub.apply(g, d)?;
            v[i] = expanded(g, d)?;
        }
        let (parts, rest) = split_linear(g, v, &map.speed_rates)?;
        out.forces.push(SpeedParts { parts, rest });
    }
    for t in &model.torques {
        let mut w = model.frames[t.frame].omega;
        for x in w.iter_mut() {
            *x = sub.apply(g, *x)?;
        }
        let (parts, rest) = split_linear(g, w, &map.speed_rates)?;
        out.torques.push(SpeedParts { parts, rest });
    }
    Ok(out)
}

/// γ̄ and ω of the body with frame `fi` turned from the first earlier body
/// whose frame it is a simple turn of (see [`simple_turn`]).
#[allow(clippy::type_complexity)] // (γ̄_k, ω, the frame it was turned from)
fn turned_from_earlier(
    g: &mut Graph,
    (bodies, frames): (&[Body], &[Frame]),
    earlier: &[BodyTerms],
    fi: usize,
    map: &SpeedMap,
    rates: &[Symbol],
) -> Result<Option<(Vec<Vec3>, Vec3, RelativeFrame)>, SymbolicError> {
    let frame = &frames[fi];
    let l = map.speed_rates.len();
    for (pb, pt) in earlier.iter().enumerate() {
        let Some(pf) = bodies[pb].frame else {
            continue;
        };
        if pf == fi {
            continue;
        }
        let Some((rel, dw)) = simple_turn(g, frame, &frames[pf], rates)? else {
            continue;
        };
        let (dparts, drest) = split_linear(g, dw, rates)?;
        let (dgamma, dgamma0) = through_c(g, map, &dparts, drest)?;
        let gamma_b = (0..l)
            .map(|k| turned(g, &rel, pt.gamma_b[k], dgamma[k]))
            .collect::<Result<Vec<_>, _>>()?;
        let domega = combine(g, &dgamma, dgamma0, &map.speed_rates)?;
        let omega_b = turned(g, &rel, pt.omega_b, domega)?;
        let relative = RelativeFrame {
            body: pb,
            rel,
            omega: dw,
        };
        return Ok(Some((gamma_b, omega_b, relative)));
    }
    Ok(None)
}

/// β̄_k = Σ_r C_rk J_r and β̄ = rest + Σ_r c_r J_r from the partial
/// velocities `parts` = J_r, skipping zero products.
pub(super) fn through_c(
    g: &mut Graph,
    map: &SpeedMap,
    parts: &[Vec3],
    rest: Vec3,
) -> Result<(Vec<Vec3>, Vec3), SymbolicError> {
    let l = map.speed_rates.len();
    let zero = g.int(0)?;
    let mut beta = vec![[zero; 3]; l];
    let mut beta0 = rest;
    for i in 0..3 {
        for (k, b) in beta.iter_mut().enumerate() {
            let mut terms = Vec::new();
            for (r, part) in parts.iter().enumerate() {
                let coef = map.c[r * l + k];
                if g.is_zero(coef) || g.is_zero(part[i]) {
                    continue;
                }
                terms.push(g.mul(coef, part[i])?);
            }
            b[i] = g.sum(&terms)?;
        }
        let mut terms = vec![rest[i]];
        for (r, part) in parts.iter().enumerate() {
            if g.is_zero(map.c0[r]) || g.is_zero(part[i]) {
                continue;
            }
            terms.push(g.mul(map.c0[r], part[i])?);
        }
        beta0[i] = g.sum(&terms)?;
    }
    Ok((beta, beta0))
}

/// J_r = ∂v/∂q̇_r as differentiated (multiplying them out costs more than
/// it cancels) and the rest of `v`, expanded.
pub(super) fn raw_parts(
    g: &mut Graph,
    rates: &[Symbol],
    v: Vec3,
) -> Result<(Vec<Vec3>, Vec3), SymbolicError> {
    let (parts, rest) = split_linear(g, v, rates)?;
    Ok((parts, expanded3(g, rest)?))
}

/// When `frame` is `parent` turned by a simple rotation: every direction
/// cosine between the two is a single term (no sum), and the relative
/// angular velocity, in `frame`'s components, is a combination of the
/// coordinate rates with constant coefficients (the steer, a wheel's spin).
/// Returns the direction cosines (`rel[i][j]` = frame axis i · parent axis
/// j, so v_frame = rel · v_parent) and that relative angular velocity.
pub(super) fn simple_turn(
    g: &mut Graph,
    frame: &Frame,
    parent: &Frame,
    rates: &[Symbol],
) -> Result<Option<(Mat3, Vec3)>, SymbolicError> {
    let (rot, prot) = (frame.rot, parent.rot);
    let zero = g.int(0)?;
    let mut rel = [[zero; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            let d = dot(
                g,
                [rot[0][i], rot[1][i], rot[2][i]],
                [prot[0][j], prot[1][j], prot[2][j]],
            )?;
            rel[i][j] = expanded(g, d)?;
            if matches!(g.node(rel[i][j]), Node::Add { .. }) {
                return Ok(None);
            }
        }
    }
    let mut dw = [zero; 3];
    for i in 0..3 {
        dw[i] = g.sub(frame.omega[i], parent.omega[i])?;
    }
    let dw = mat_t_vec(g, &rot, dw)?;
    let dw = expanded3(g, dw)?;
    let (parts, rest) = split_linear(g, dw, rates)?;
    if !parts
        .iter()
        .flatten()
        .chain(&rest)
        .all(|&c| g.is_parameter_only(c))
    {
        return Ok(None);
    }
    Ok(Some((rel, dw)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn simple_turn_finds_a_rotation_about_a_parent_axis() {
        let mut g = Graph::new();
        let a = g.coordinate("a").unwrap();
        let b = g.coordinate("b").unwrap();
        let rates = [a.rate, b.rate];
        let frame = |g: &mut Graph, rot: [[&str; 3]; 3], omega: [&str; 3]| Frame {
            name: String::new(),
            rot: rot.map(|row| row.map(|e| g.parse(e).unwrap())),
            omega: omega.map(|e| g.parse(e).unwrap()),
        };
        // P turns about N.z by a; F turns about P.z by b.
        let p = frame(
            &mut g,
            [
                ["cos(a)", "-sin(a)", "0"],
                ["sin(a)", "cos(a)", "0"],
                ["0", "0", "1"],
            ],
            ["0", "0", "a_dot"],
        );
        let f = frame(
            &mut g,
            [
                [
                    "cos(a)*cos(b) - sin(a)*sin(b)",
                    "-cos(a)*sin(b) - sin(a)*cos(b)",
                    "0",
                ],
                [
                    "sin(a)*cos(b) + cos(a)*sin(b)",
                    "cos(a)*cos(b) - sin(a)*sin(b)",
                    "0",
                ],
                ["0", "0", "1"],
            ],
            ["0", "0", "a_dot + b_dot"],
        );
        let (rel, dw) = simple_turn(&mut g, &f, &p, &rates).unwrap().unwrap();
        let expect = |g: &mut Graph, t: &str| g.parse(t).unwrap();
        assert_eq!(rel[0][0], expect(&mut g, "cos(b)"));
        assert_eq!(rel[0][1], expect(&mut g, "sin(b)"));
        assert_eq!(rel[2][2], expect(&mut g, "1"));
        let (zero, b_dot) = (g.int(0).unwrap(), g.sym(b.rate).unwrap());
        assert_eq!(dw, [zero, zero, b_dot]);
        // G turns about P.x by b: simple from P, not from F.
        let h = frame(
            &mut g,
            [
                ["cos(a)", "-sin(a)*cos(b)", "sin(a)*sin(b)"],
                ["sin(a)", "cos(a)*cos(b)", "-cos(a)*sin(b)"],
                ["0", "sin(b)", "cos(b)"],
            ],
            ["b_dot*cos(a)", "b_dot*sin(a)", "a_dot"],
        );
        assert!(simple_turn(&mut g, &h, &p, &rates).unwrap().is_some());
        assert!(simple_turn(&mut g, &h, &f, &rates).unwrap().is_none());
    }
}

#[cfg(test)]
mod stage_tests {
    use super::super::testing::{self, assert_agrees};

    #[test]
    fn the_pendulums_partial_velocity_is_tangent_to_its_circle() {
        // v = l q̇ (cos q, sin q, 0).
        let mut run = testing::run(testing::PENDULUM);
        let p = run.partials();
        let g = &mut run.model.g;
        let b = &p.bodies[0];
        assert_agrees(g, b.beta[0][0], "l*cos(q)");
        assert_agrees(g, b.beta[0][1], "l*sin(q)");
        assert!(g.is_zero(b.beta[0][2]));
        assert!(b.beta0.iter().all(|e| g.is_zero(*e)));
        assert!(p.rotations[0].is_none());
    }

    #[test]
    fn a_rolling_discs_partials_go_through_c() {
        // ẋ = −r φ̇: β̄ = (−r, 0, 0); γ̄ = B.z, in B's components (0, 0, 1);
        // the force at the centre has the centre's β̄.
        let mut run = testing::run(testing::DISC_ON_A_LINE);
        let p = run.partials();
        let g = &mut run.model.g;
        let b = &p.bodies[0];
        assert_agrees(g, b.beta[0][0], "-r");
        assert!(g.is_zero(b.beta[0][1]));
        assert_agrees(g, b.gamma_b[0][2], "1");
        assert!(g.is_zero(b.gamma_b[0][0]) && g.is_zero(b.gamma_b[0][1]));
        assert_agrees(g, b.omega_b[2], "phi_dot");
        assert_agrees(g, p.forces[0].parts[0][0], "-r");
        assert_agrees(g, p.center_parts[0][0][0], "1");
    }
}
