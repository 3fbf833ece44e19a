//! Free joints' speeds. A free joint's privileged speeds are the child's
//! angular velocity ω in its own axes and the rates ṗ of its slides, in the
//! joint frame's axes; the recursions run in the child's velocity in its
//! own axes, (ω, v) with v = Rᵀ ṗ (R: the child's axes in the joint
//! frame's), where the joint's motion subspace is the identity and its
//! articulated inertia is solved once, as Featherstone's floating base is.
//! This stage converts at the recursions' boundary, for each free link:
//!
//! - speeds in: v = Rᵀ ṗ;
//! - accelerations in: v̇ = Rᵀ p̈ − ω × v;
//! - accelerations out: p̈ = R (v̇ + ω × v);
//! - generalized forces out: the force's component along ṗ is R f;
//! - M out: Tᵀ M T for ẏ-to-(ω, v) map T, i.e. R on the rows and the
//!   columns of the slides.
//!
//! Every other link's speeds pass through unchanged.

use appell_symbolic::{Id, SymbolicError};

use super::links::Link;
use super::spatial::{Algebra, M3, V3};

type R<T> = Result<T, SymbolicError>;

/// A free link's rotation and the indices of its ω and ṗ speeds.
struct Free {
    turn: M3,
    angular: [usize; 3],
    linear: [usize; 3],
}

fn free_links(links: &[Link]) -> Vec<Free> {
    links
        .iter()
        .filter_map(|l| {
            let turn = l.free?;
            let s = &l.speeds;
            Some(Free {
                turn,
                angular: [s[0], s[1], s[2]],
                linear: [s[3], s[4], s[5]],
            })
        })
        .collect()
}

fn pick(x: &[Id], at: [usize; 3]) -> V3 {
    [x[at[0]], x[at[1]], x[at[2]]]
}

fn put(x: &mut [Id], at: [usize; 3], v: V3) {
    for k in 0..3 {
        x[at[k]] = v[k];
    }
}

/// The recursions' speeds from the model's: v = Rᵀ ṗ.
pub fn speeds_in(a: &mut Algebra, links: &[Link], speeds: &[Id]) -> R<Vec<Id>> {
    let mut out = speeds.to_vec();
    for f in free_links(links) {
        let v = a.mat_t_vec(&f.turn, pick(speeds, f.linear))?;
        put(&mut out, f.linear, v);
    }
    Ok(out)
}

/// The recursions' accelerations from the model's: v̇ = Rᵀ p̈ − ω × v,
/// with `body` the recursions' speeds.
pub fn accelerations_in(a: &mut Algebra, links: &[Link], body: &[Id], accels: &[Id]) -> R<Vec<Id>> {
    let mut out = accels.to_vec();
    for f in free_links(links) {
        let turned = a.mat_t_vec(&f.turn, pick(accels, f.linear))?;
        let spin = a.cross(pick(body, f.angular), pick(body, f.linear))?;
        let v_dot = a.sub(turned, spin)?;
        put(&mut out, f.linear, v_dot);
    }
    Ok(out)
}

/// The model's accelerations from the recursions': p̈ = R (v̇ + ω × v).
pub fn accelerations_out(
    a: &mut Algebra,
    links: &[Link],
    body: &[Id],
    body_accels: &[Id],
) -> R<Vec<Id>> {
    let mut out = body_accels.to_vec();
    for f in free_links(links) {
        let spin = a.cross(pick(body, f.angular), pick(body, f.linear))?;
        let classical = a.add(pick(body_accels, f.linear), spin)?;
        let p_ddot = a.mat_vec(&f.turn, classical)?;
        put(&mut out, f.linear, p_ddot);
    }
    Ok(out)
}

/// The model's generalized forces from the recursions': R f along ṗ.
pub fn forces_out(a: &mut Algebra, links: &[Link], forces: &[Id]) -> R<Vec<Id>> {
    let mut out = forces.to_vec();
    for f in free_links(links) {
        let turned = a.mat_vec(&f.turn, pick(forces, f.linear))?;
        put(&mut out, f.linear, turned);
    }
    Ok(out)
}

/// `links` with each free joint's rotation R replaced by R⁻ᵀ = R / c,
/// c = |R e₁|²: a quaternion's rotation is a homogeneous quadratic form
/// with RᵀR = |e|⁴ I, so R⁻¹ = Rᵀ / c off the unit sphere too. Through
/// [`accelerations_in`] it inverts [`accelerations_out`] exactly; through
/// [`forces_out`] and [`mass_out`] it writes the generalized forces and M
/// those accelerations imply.
pub fn exact_inverses(a: &mut Algebra, links: &[Link]) -> R<Vec<Link>> {
    let mut out = links.to_vec();
    for link in &mut out {
        let Some(turn) = link.free else { continue };
        let column = [turn[0][0], turn[1][0], turn[2][0]];
        let c = a.dot((0..3).map(|k| (column[k], column[k])))?;
        let over = a.g.recip(c)?;
        let mut scaled = turn;
        for row in &mut scaled {
            for entry in row.iter_mut() {
                *entry = a.g.mul(*entry, over)?;
            }
        }
        link.free = Some(scaled);
    }
    Ok(out)
}

/// The model's M (size × size, row-major) from the recursions': R on the
/// slides' rows and columns.
pub fn mass_out(a: &mut Algebra, links: &[Link], mass: &[Id], size: usize) -> R<Vec<Id>> {
    let mut out = mass.to_vec();
    for f in free_links(links) {
        for c in 0..size {
            let column = pick_strided(&out, f.linear, |r| r * size + c);
            let turned = a.mat_vec(&f.turn, column)?;
            (0..3).for_each(|k| out[f.linear[k] * size + c] = turned[k]);
        }
        for r in 0..size {
            let row = pick_strided(&out, f.linear, |c| r * size + c);
            let turned = a.mat_vec(&f.turn, row)?;
            (0..3).for_each(|k| out[r * size + f.linear[k]] = turned[k]);
        }
    }
    Ok(out)
}

fn pick_strided(x: &[Id], at: [usize; 3], index: impl Fn(usize) -> usize) -> V3 {
    [x[index(at[0])], x[index(at[1])], x[index(at[2])]]
}
