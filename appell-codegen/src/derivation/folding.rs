//! Stage 9: folding bodies together where that makes M and f cheaper.
//!
//! Two foldings change how M and f are computed, not what they are:
//!
//! - **Composites.** Bodies whose mass centres are fixed in one rigid
//!   body's frame (a wheel's centre in the frame that carries its axle)
//!   share one translational term at their composite mass centre, the
//!   members' parallel-axis inertia turning with the leader's frame.
//! - **Rotors.** An axisymmetric body spinning about its symmetry axis,
//!   fixed in a carrier body's frame, folds its rotational terms into the
//!   carrier's, written whole or split against the carrier's.
//!
//! Each is kept only when the assembled M and f count fewer operations
//! (composites pay off when the members' own translational terms are long,
//! and not in small models, whose fully expanded terms collect better body
//! by body), and listed in the equations text. [`super::Options`] can force
//! them for tests.

use appell_symbolic::{Assumptions, Graph, Id, Sign, SymbolicError};

use super::assembly::{Assembled, Assembler, Composite, Rotor};
use super::Options;
use crate::algebra::{dot, expanded, expanded3, mat_t_vec, Mat3, Vec3};
use crate::model::{Body, Frame};

/// The output of stage 9: M and f's inertial terms as folded.
pub struct Folded {
    /// M and f's terms.
    pub assembled: Assembled,
    /// Each body's part in a composite.
    pub composites: Vec<Composite>,
    /// The foldings kept, as readable lines.
    pub lines: Vec<String>,
}

/// Stage 9: assembles M and f (stage 8) unfolded, with composites and with
/// rotors, and keeps the cheapest.
pub fn fold(
    g: &mut Graph,
    model_parts: (
        &[Body],
        &[Frame],
        &[(syn::Ident, appell_symbolic::Coordinate)],
    ),
    assembler: &mut Assembler<'_>,
    rotations: &[Option<Mat3>],
    assume: &Assumptions,
    options: &Options,
) -> Result<Folded, SymbolicError> {
    let (bodies, frames, coords) = model_parts;
    let l = assembler.map.speed_rates.len();
    let no_rotors: Vec<Option<Rotor>> = vec![None; bodies.len()];
    let mut chosen: Vec<Composite> = (0..bodies.len()).map(|_| Composite::Alone).collect();
    let mut assembled = assembler.assemble(g, &chosen, &no_rotors)?;
    let composites = composite_bodies(g, bodies, rotations, assume)?;
    if composites.iter().any(|c| !matches!(c, Composite::Alone)) {
        let candidate = assembler.assemble(g, &composites, &no_rotors)?;
        if options.fold_always
            || assembled_ops(g, &candidate, l)? < assembled_ops(g, &assembled, l)?
        {
            assembled = candidate;
            chosen = composites;
        }
    }
    let mut lines = composite_lines(bodies, &chosen);
    // Each rotor's terms are written whole or split, whichever the
    // assembled M and f count fewer operations with; every combination is
    // tried for up to four rotors.
    let mut found = rotors(g, bodies, frames, coords)?;
    if found.iter().any(Option::is_some) {
        let indices: Vec<usize> = (0..found.len()).filter(|&i| found[i].is_some()).collect();
        let combinations = match options.rotor_form {
            None if indices.len() <= 4 => 1usize << indices.len(),
            _ => 1,
        };
        let mut best: Option<(usize, Vec<Option<Rotor>>, Assembled)> = None;
        for mask in 0..combinations {
            let mut forms = found.clone();
            for (bit, &i) in indices.iter().enumerate() {
                if let Some(r) = forms[i].as_mut() {
                    r.whole = options.rotor_form.unwrap_or(mask & (1 << bit) == 0);
                }
            }
            let candidate = assembler.assemble(g, &chosen, &forms)?;
            let ops = assembled_ops(g, &candidate, l)?;
            if best.as_ref().is_none_or(|(b, _, _)| ops < *b) {
                best = Some((ops, forms, candidate));
            }
        }
        let (ops, forms, candidate) = best.expect("at least one combination");
        found = forms;
        if options.fold_always || ops < assembled_ops(g, &assembled, l)? {
            assembled = candidate;
            for (bi, r) in found.iter().enumerate() {
                if let Some(r) = r {
                    lines.push(format!(
                        "rotor: `{}` spins about axis {} of `{}` (its rotational terms folded into the carrier's)",
                        bodies[bi].name,
                        ["x", "y", "z"][r.axis],
                        bodies[r.carrier].name
                    ));
                }
            }
        }
    }
    Ok(Folded {
        assembled,
        composites: chosen,
        lines,
    })
}

/// The equations text's line for each composite kept.
fn composite_lines(bodies: &[Body], chosen: &[Composite]) -> Vec<String> {
    let mut lines = Vec::new();
    for (bi, c) in chosen.iter().enumerate() {
        if matches!(c, Composite::Leader { .. }) {
            let members: Vec<String> = chosen
                .iter()
                .enumerate()
                .filter(|(_, m)| matches!(m, Composite::Member(leader) if *leader == bi))
                .map(|(i, _)| format!("`{}`", bodies[i].name))
                .collect();
            lines.push(format!(
                "composite: `{}` with {} (one translational term at their mass centre)",
                bodies[bi].name,
                members.join(", ")
            ));
        }
    }
    lines
}

/// Finds rotors: a rigid body whose frame is a carrier body's frame turned
/// about one of its axes by a coordinate, with an inertia symmetric about
/// that axis. Its inertia is then the same matrix in the carrier's frame,
/// so its rotational terms fold into the carrier's. With a the axis, λ the
/// axial and μ the transverse moment, θ the spin angle, s_k = ∂θ̇/∂ẏ_k,
/// o_k = s_k + γ̄ᶜ_k·a the rotor's axial partial angular velocity,
/// Ω = ωᶜ·a + θ̇ its axial angular velocity and ν = αᶜ·a + θ̈ the remainder
/// of its axial angular acceleration: the carrier's inertia gains μ (1 − a aᵀ),
/// γ̄_k·I γ̄_j adds λ o_k o_j, and γ̄_k·(I α + ω × I ω) adds
/// λ (ν o_k + Ω γ̄ᶜ_k·(ωᶜ × a)).
pub fn rotors(
    g: &mut Graph,
    bodies: &[Body],
    frames: &[Frame],
    coords: &[(syn::Ident, appell_symbolic::Coordinate)],
) -> Result<Vec<Option<Rotor>>, SymbolicError> {
    let nb = bodies.len();
    let mut out: Vec<Option<Rotor>> = vec![None; nb];
    for b in 0..nb {
        let Some(fb) = bodies[b].frame else { continue };
        let inertia = bodies[b].inertia;
        for p in 0..nb {
            let Some(fp) = bodies[p].frame else { continue };
            if p == b || fp == fb || out[p].is_some() {
                continue;
            }
            if out.iter().flatten().any(|r| r.carrier == b) {
                break;
            }
            let (rb, rp) = (frames[fb].rot, frames[fp].rot);
            // The relative rotation, carrier to rotor, and the relative
            // angular velocity in the carrier's frame.
            let mut rel = [[g.int(0)?; 3]; 3];
            for (i, row) in rel.iter_mut().enumerate() {
                for (j, e) in row.iter_mut().enumerate() {
                    let d = dot(
                        g,
                        [rp[0][i], rp[1][i], rp[2][i]],
                        [rb[0][j], rb[1][j], rb[2][j]],
                    )?;
                    *e = expanded(g, d)?;
                }
            }
            let mut dw = [g.int(0)?; 3];
            for i in 0..3 {
                dw[i] = g.sub(frames[fb].omega[i], frames[fp].omega[i])?;
            }
            let dw = mat_t_vec(g, &rp, dw)?;
            let dw = expanded3(g, dw)?;
            let one = g.int(1)?;
            for k in 0..3 {
                let others = [(k + 1) % 3, (k + 2) % 3];
                let axis_fixed = rel[k][k] == one
                    && others
                        .iter()
                        .all(|&i| g.is_zero(rel[i][k]) && g.is_zero(rel[k][i]));
                let symmetric = (0..3).all(|i| (0..3).all(|j| i == j || g.is_zero(inertia[i][j])))
                    && inertia[others[0]][others[0]] == inertia[others[1]][others[1]];
                let spin = coords
                    .iter()
                    .position(|(_, c)| g.sym(c.rate).is_ok_and(|r| r == dw[k]));
                if axis_fixed && symmetric && others.iter().all(|&i| g.is_zero(dw[i])) {
                    if let Some(coordinate) = spin {
                        out[b] = Some(Rotor {
                            carrier: p,
                            axis: k,
                            coordinate,
                            axial: inertia[k][k],
                            whole: true,
                        });
                        break;
                    }
                }
            }
            if out[b].is_some() {
                break;
            }
        }
    }
    Ok(out)
}

/// Groups bodies whose mass centres are fixed in a rigid body's frame (a
/// wheel's centre in the frame that carries its axle). For such a group,
/// Σ mᵢ β̄ᵢ·β̄ⱼ and Σ mᵢ aᵢ·β̄ are those of one particle of the total mass
/// at the composite mass centre G plus the parallel-axis inertia
/// Σ mᵢ (|dᵢ|² 1 − dᵢ dᵢᵀ), dᵢ = rᵢ − G, turning with the leader's frame:
/// one translational term instead of one per body. A group is formed only
/// when its total mass is provably positive (parameters declared
/// `positive`), since G divides by it.
pub fn composite_bodies(
    g: &mut Graph,
    bodies: &[Body],
    rotations: &[Option<Mat3>],
    assume: &Assumptions,
) -> Result<Vec<Composite>, SymbolicError> {
    let nb = bodies.len();
    let zero = g.int(0)?;
    let mut out: Vec<Composite> = (0..nb).map(|_| Composite::Alone).collect();
    let mut taken = vec![false; nb];
    for a in 0..nb {
        let Some(rot) = rotations[a] else { continue };
        if taken[a] {
            continue;
        }
        // Members and their offsets from the leader's centre, in its frame.
        let mut members: Vec<(usize, Vec3)> = vec![(a, [zero; 3])];
        for (b, body) in bodies.iter().enumerate().skip(a + 1) {
            if taken[b] {
                continue;
            }
            let mut diff = [zero; 3];
            for i in 0..3 {
                diff[i] = g.sub(body.center[i], bodies[a].center[i])?;
            }
            let offset = mat_t_vec(g, &rot, diff)?;
            let offset = expanded3(g, offset)?;
            if offset.iter().all(|&c| g.is_parameter_only(c)) {
                members.push((b, offset));
            }
        }
        if members.len() < 2 {
            continue;
        }
        let masses: Vec<Id> = members.iter().map(|(i, _)| bodies[*i].mass).collect();
        let total = g.sum(&masses)?;
        if g.sign(total, assume) != Sign::Positive {
            continue;
        }
        let inv = g.recip(total)?;
        // G − r_a = Σ mᵢ eᵢ / M, in the leader's frame.
        let mut shift = [zero; 3];
        for i in 0..3 {
            let mut terms = Vec::new();
            for (b, e) in &members {
                terms.push(g.mul(bodies[*b].mass, e[i])?);
            }
            let s = g.sum(&terms)?;
            shift[i] = g.mul(s, inv)?;
        }
        let mut center = bodies[a].center;
        for (i, c) in center.iter_mut().enumerate() {
            let mut terms = vec![*c];
            for (j, s) in shift.iter().enumerate() {
                terms.push(g.mul(rot[i][j], *s)?);
            }
            *c = g.sum(&terms)?;
        }
        let mut extra = [[zero; 3]; 3];
        for (b, e) in &members {
            let mut d = [zero; 3];
            for i in 0..3 {
                d[i] = g.sub(e[i], shift[i])?;
            }
            let dd = dot(g, d, d)?;
            for r in 0..3 {
                for c in 0..3 {
                    let outer = g.mul(d[r], d[c])?;
                    let term = if r == c {
                        g.sub(dd, outer)?
                    } else {
                        g.neg(outer)?
                    };
                    let term = g.mul(bodies[*b].mass, term)?;
                    extra[r][c] = g.add(extra[r][c], term)?;
                }
            }
        }
        for (b, _) in &members {
            taken[*b] = true;
            out[*b] = Composite::Member(a);
        }
        out[a] = Composite::Leader {
            mass: total,
            center,
            shift,
            extra_inertia: extra,
        };
    }
    Ok(out)
}

/// Operations of M (upper triangle) and f, expanded as they will be.
fn assembled_ops(g: &mut Graph, a: &Assembled, l: usize) -> Result<usize, SymbolicError> {
    let (mass, forcing_terms) = (&a.mass, &a.forcing_terms);
    let mut roots = Vec::new();
    for k in 0..l {
        for j in k..l {
            roots.push(expanded(g, mass[k * l + j])?);
        }
    }
    for terms in forcing_terms {
        let f = g.sum(terms)?;
        roots.push(expanded(g, f)?);
    }
    Ok(g.op_count(&roots)?.total())
}

#[cfg(test)]
mod tests {
    use super::super::testing::{self, assert_agrees};
    use super::*;

    /// A gimbal B (yaw, then pitch) carrying a rotor D that spins about B.y,
    /// with its centre fixed in B.
    const GYROSCOPE: &str = r#"
        #[appell(coordinates(yaw, pitch, spin), speeds(yaw, pitch, spin), positive(mb, md))]
        #[appell(frame(A = N.rotate_z(yaw)), frame(B = A.rotate_x(pitch)), frame(D = B.rotate_y(spin)))]
        #[appell(point(Bo = O + a * B.z), point(Do = O + h * B.z))]
        #[appell(body(gimbal, center = Bo, frame = B, mass = mb, inertia = principal(i1, i2, i3)))]
        #[appell(body(rotor, center = Do, frame = D, mass = md, inertia = principal(j1, j2, j1)))]
        #[appell(gravity(-g * N.z))]
        struct Gyro { a: f64, h: f64, mb: f64, md: f64, i1: f64, i2: f64, i3: f64, j1: f64, j2: f64, g: f64 }
    "#;

    #[test]
    fn a_symmetric_body_spinning_about_a_carrier_axis_is_a_rotor() {
        let mut m = testing::model(GYROSCOPE);
        let found = rotors(&mut m.g, &m.bodies, &m.frames, &m.coords).unwrap();
        assert!(found[0].is_none());
        let r = found[1].expect("the rotor");
        assert_eq!((r.carrier, r.axis, r.coordinate), (0, 1, 2));
        assert_agrees(&mut m.g, r.axial, "j2");
    }

    #[test]
    fn centres_fixed_in_one_frame_form_a_composite_at_their_mass_centre() {
        let mut m = testing::model(GYROSCOPE);
        let rotations: Vec<Option<Mat3>> = m
            .bodies
            .iter()
            .map(|b| b.frame.map(|f| m.frames[f].rot))
            .collect();
        let assume = m.assumptions();
        let found = composite_bodies(&mut m.g, &m.bodies, &rotations, &assume).unwrap();
        assert!(matches!(found[1], Composite::Member(0)));
        let Composite::Leader { mass, shift, .. } = &found[0] else {
            panic!("the gimbal leads");
        };
        // G − r_gimbal = md (h − a) / (mb + md) along B.z.
        assert_agrees(&mut m.g, *mass, "mb + md");
        assert_agrees(&mut m.g, shift[2], "md*(h - a)/(mb + md)");
    }

    #[test]
    fn forced_folding_keeps_the_same_equations_and_says_so() {
        let forced = Options {
            fold_always: true,
            rotor_form: None,
            closed_form_only: false,
        };
        let mut plain = testing::run(GYROSCOPE);
        let a = plain.later(&Options::default());
        let mut folded = testing::run(GYROSCOPE);
        let b = folded.later(&forced);
        assert!(b
            .folded_lines
            .iter()
            .any(|l| l.starts_with("composite: `gimbal`")));
        assert!(b
            .folded_lines
            .iter()
            .any(|l| l.starts_with("rotor: `rotor`")));
        // Both graphs were built the same way up to here: compare by value.
        let g = &mut folded.model.g;
        for k in 0..9 {
            let text = plain.model.g.display(a.equations.mass[k]).to_string();
            assert_agrees(g, b.equations.mass[k], &text);
        }
    }
}
