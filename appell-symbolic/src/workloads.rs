//! Expression families of known size for benchmarks and scaling tests.
//!
//! [`spatial_chain`] builds the kinematics of an n-link spatial serial chain
//! the way the derivation will: rotation matrices by simple rotations, link
//! tip positions, and their velocities and accelerations by total time
//! derivatives. Its size grows with n the way a multibody model's does.

use crate::diff::RateRules;
use crate::error::Result;
use crate::graph::{Coordinate, Graph, Id};

/// The kinematics of an n-link spatial chain.
#[derive(Clone, Debug)]
pub struct ChainKinematics {
    /// Joint coordinates q1..qn (with rates and accelerations).
    pub joints: Vec<Coordinate>,
    /// Tip position of every link, in the base frame.
    pub positions: Vec<[Id; 3]>,
    /// Tip velocity of every link (first time derivative).
    pub velocities: Vec<[Id; 3]>,
    /// Tip acceleration of every link (second time derivative).
    pub accelerations: Vec<[Id; 3]>,
}

impl ChainKinematics {
    /// All accelerations, flattened: the usual roots to emit.
    pub fn acceleration_roots(&self) -> Vec<Id> {
        self.accelerations.iter().flatten().copied().collect()
    }
}

/// Joint `i` rotates about axis `i mod 3` (z, y, x, z, …) of the previous
/// link's frame; link `i` has length `l{i}` along its own x axis.
///
/// ```
/// use appell_symbolic::{workloads::spatial_chain, Graph};
/// let mut g = Graph::new();
/// let chain = spatial_chain(&mut g, 2).unwrap();
/// // The first tip moves on a circle of radius l1 in the base x-y plane.
/// let x = chain.positions[0][0];
/// assert_eq!(g.display(x).to_string(), "l1*cos(q1)");
/// ```
pub fn spatial_chain(g: &mut Graph, n: usize) -> Result<ChainKinematics> {
    let (joints, positions) = chain_positions(g, n)?;
    let rules = RateRules::coordinates();
    let flat: Vec<Id> = positions.iter().flatten().copied().collect();
    let vel = g.time_derivatives(&flat, &rules)?;
    let acc = g.time_derivatives(&vel, &rules)?;
    let triples = |v: &[Id]| v.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
    Ok(ChainKinematics {
        joints,
        positions,
        velocities: triples(&vel),
        accelerations: triples(&acc),
    })
}

/// The joint coordinates and link tip positions only (no derivatives), so
/// the phases of a derivation can be timed apart.
#[allow(clippy::type_complexity)] // (coordinates, positions) reads plainly here
pub fn chain_positions(g: &mut Graph, n: usize) -> Result<(Vec<Coordinate>, Vec<[Id; 3]>)> {
    let zero = g.int(0)?;
    let one = g.int(1)?;
    let mut rot = [[one, zero, zero], [zero, one, zero], [zero, zero, one]];
    let mut tip = [zero; 3];
    let mut joints = Vec::with_capacity(n);
    let mut positions = Vec::with_capacity(n);
    for i in 1..=n {
        let q = g.coordinate(&format!("q{i}"))?;
        let l = g.parameter(&format!("l{i}"))?;
        joints.push(q);
        let qs = g.sym(q.q)?;
        let (c, s) = (g.cos(qs)?, g.sin(qs)?);
        let ms = g.neg(s)?;
        // Simple rotation about axis (i−1) mod 3 in z, y, x order.
        let local = match (i - 1) % 3 {
            0 => [[c, ms, zero], [s, c, zero], [zero, zero, one]],
            1 => [[c, zero, s], [zero, one, zero], [ms, zero, c]],
            _ => [[one, zero, zero], [zero, c, ms], [zero, s, c]],
        };
        let mut next = [[zero; 3]; 3];
        for (r, row) in next.iter_mut().enumerate() {
            for (k, entry) in row.iter_mut().enumerate() {
                let mut terms = Vec::with_capacity(3);
                for (m, lrow) in local.iter().enumerate() {
                    terms.push(g.mul(rot[r][m], lrow[k])?);
                }
                *entry = g.sum(&terms)?;
            }
        }
        rot = next;
        let ls = g.sym(l)?;
        for (r, t) in tip.iter_mut().enumerate() {
            let step = g.mul(rot[r][0], ls)?;
            *t = g.add(*t, step)?;
        }
        positions.push(tip);
    }
    Ok((joints, positions))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::Tape;

    #[test]
    fn planar_two_link_tip_matches_closed_form() {
        // Joints 1 (z) and 2 (y): at q2 = 0 the chain is straight in the
        // base x-y plane, so the tip is (l1 + l2)(cos q1, sin q1, 0).
        let mut g = Graph::new();
        let chain = spatial_chain(&mut g, 2).unwrap();
        let tape = Tape::new(&g, &chain.positions[1]);
        let values = [("q1", 0.3), ("q2", 0.0), ("l1", 1.5), ("l2", 0.5)];
        let env = |s| {
            values
                .iter()
                .find(|(n, _)| g.symbol_name(s) == *n)
                .map(|(_, v)| *v)
        };
        let p = tape.eval(&env).unwrap();
        assert!((p[0] - 2.0 * 0.3f64.cos()).abs() < 1e-15);
        assert!((p[1] - 2.0 * 0.3f64.sin()).abs() < 1e-15);
        assert!(p[2].abs() < 1e-15);
    }

    #[test]
    fn velocity_is_linear_in_the_rates() {
        let mut g = Graph::new();
        let chain = spatial_chain(&mut g, 3).unwrap();
        let rates: Vec<_> = chain.joints.iter().map(|j| j.rate).collect();
        for v in chain.velocities.iter().flatten() {
            let form = g.linear_coefficients(*v, &rates).unwrap();
            assert!(g.is_zero(form.remainder));
        }
    }
}
