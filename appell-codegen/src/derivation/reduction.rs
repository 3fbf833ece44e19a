//! Stage 12: the reduced state (Sec. III C, eq. 42).
//!
//! Coordinates that occur in the equations but on which they do not depend
//! (an axisymmetric wheel's angle, a bicycle's heading after the
//! elimination) are found numerically at pseudo-random points and set to
//! zero in M, f and the numeric elimination, so they drop out. The retained
//! coordinates are then those M and f need, those a scene integrates by
//! quadrature, and those the retained coordinates' rates need; the others
//! are ignorable, and the ignorable dependent ones are cyclic.
//!
//! A numeric elimination can hide such a coordinate: when the constraints
//! are written in the ground frame (a snakeboard's wheels, which may not
//! slide sideways), the heading enters S and R, and so the dependent rates
//! X, yet M and f computed through X do not depend on it. Those
//! coordinates are found by evaluating M, f and the retained rates through
//! the solve, and fixed in M, f and a copy of the elimination that only the
//! reduced equations use; the coordinate rates keep the model's own.

use std::collections::BTreeSet;

use appell_symbolic::{Graph, Id, Substitution, Symbol, SymbolSet, SymbolicError, Tape};

use super::numeric::{Elimination, NumericElimination};
use crate::probe::{numerically_independent, pseudo_value, switches_on};

/// The output of stage 12.
#[derive(Clone)]
pub struct Reduction {
    /// Coordinates kept in the reduced state.
    pub retained: Vec<usize>,
    /// Cyclic (dependent, absent) coordinates.
    pub cyclic: Vec<usize>,
    /// All coordinates left out of the reduced state.
    pub ignorable: Vec<usize>,
    /// Ignorable coordinates that the numeric elimination reads but M, f
    /// and the retained rates do not depend on through it: fixed in the
    /// elimination M and f use, so functions that need the dependent
    /// rates themselves solve the model's own elimination.
    pub through_solve: Vec<usize>,
}

/// What [`reduce_state`] reads and rewrites.
pub struct ReductionInputs<'a> {
    /// The coordinates.
    pub coords: &'a [(syn::Ident, appell_symbolic::Coordinate)],
    /// Coordinates forced into the state (a scene's quadrature outputs).
    pub quadrature: &'a [usize],
    /// q̇ = C ẏ + c.
    pub qdot: &'a [Id],
    /// The unknowns' coordinates.
    pub dependent: &'a [usize],
}

/// Stage 12: fixes the coordinates the equations do not depend on in
/// `mass`, `forcing` and `elimination`, and sorts the coordinates.
pub fn reduce_state(
    g: &mut Graph,
    inputs: ReductionInputs<'_>,
    mass: &mut [Id],
    forcing: &mut [Id],
    elimination: &mut Elimination,
) -> Result<Reduction, SymbolicError> {
    let (coords, dependent) = (inputs.coords, inputs.dependent);
    let n = coords.len();
    fix_independent_coordinates(g, coords, mass, forcing, elimination)?;
    let through_solve = fix_through_solve(g, &inputs, mass, forcing, elimination)?;
    let retained = retained_coordinates(g, &inputs, mass, forcing, elimination);
    let ignorable: Vec<usize> = (0..n).filter(|i| !retained.contains(i)).collect();
    let cyclic: Vec<usize> = ignorable
        .iter()
        .copied()
        .filter(|i| dependent.contains(i))
        .collect();
    Ok(Reduction {
        retained,
        cyclic,
        ignorable,
        through_solve,
    })
}

/// The coordinates M and f read, those forced into the state, and those
/// the retained coordinates' rates read, closed under the last; a value
/// read through the numeric solve reads everything the solve reads.
fn retained_coordinates(
    g: &Graph,
    inputs: &ReductionInputs<'_>,
    mass: &[Id],
    forcing: &[Id],
    elimination: &Elimination,
) -> Vec<usize> {
    let aux_deps = match elimination {
        Elimination::Symbolic => Vec::new(),
        Elimination::Numeric(ne) => {
            let mut all = SymbolSet::new();
            for &e in ne.expressions() {
                all.union_with(g.dependencies(e));
            }
            ne.x.iter()
                .chain(&ne.w)
                .map(|&s| (s, all.clone()))
                .collect::<Vec<_>>()
        }
    };
    let deps_of = |e: Id| -> SymbolSet {
        let mut set = g.dependencies(e).clone();
        for (s, d) in &aux_deps {
            if set.contains(*s) {
                set.union_with(d);
            }
        }
        set
    };
    let coord_of = |set: &SymbolSet| -> BTreeSet<usize> {
        inputs
            .coords
            .iter()
            .enumerate()
            .filter(|(_, (_, c))| set.contains(c.q))
            .map(|(i, _)| i)
            .collect()
    };
    let mut retained: BTreeSet<usize> = inputs.quadrature.iter().copied().collect();
    for &e in mass.iter().chain(forcing.iter()) {
        retained.extend(coord_of(&deps_of(e)));
    }
    loop {
        let before = retained.len();
        for r in retained.clone() {
            retained.extend(coord_of(&deps_of(inputs.qdot[r])));
        }
        if retained.len() == before {
            break;
        }
    }
    retained.into_iter().collect()
}

/// Fixes, in M, f and the numeric elimination, the coordinates that M, f
/// and the retained rates do not depend on through the solve although its
/// rows read them (see the module docs). Starts from every coordinate the
/// rows read and drops those the composite depends on, or that the
/// reduced state would keep, until the set is stable.
fn fix_through_solve(
    g: &mut Graph,
    inputs: &ReductionInputs<'_>,
    mass: &mut [Id],
    forcing: &mut [Id],
    elimination: &mut Elimination,
) -> Result<Vec<usize>, SymbolicError> {
    let Elimination::Numeric(ne) = &*elimination else {
        return Ok(Vec::new());
    };
    let mut core: Vec<Id> = mass.iter().chain(forcing.iter()).copied().collect();
    core.extend(ne.expressions());
    let mut read = SymbolSet::new();
    for &e in ne.expressions() {
        read.union_with(g.dependencies(e));
    }
    let mut candidates: Vec<usize> = (0..inputs.coords.len())
        .filter(|&i| {
            let q = inputs.coords[i].1.q;
            read.contains(q) && !switches_on(g, &core, q)
        })
        .collect();
    while !candidates.is_empty() {
        // Held at 0 where S stays regular there, else at 1 or 2 (Euler
        // angles at gimbal lock make S singular at 0).
        let held: Vec<Symbol> = candidates.iter().map(|&i| inputs.coords[i].1.q).collect();
        let system = ThroughSolve::new(g, ne, &[]);
        let Some(at) = [0, 1, 2]
            .into_iter()
            .find(|&v| system.regular(g, &held, v as f64))
        else {
            return Ok(Vec::new());
        };
        let value = g.int(at)?;
        let mut fix = Substitution::new();
        for &q in &held {
            fix.insert(q, value);
        }
        let fixed_mass = fix.apply_all(g, mass)?;
        let fixed_forcing = fix.apply_all(g, forcing)?;
        let mut fixed_ne = ne.clone();
        for e in fixed_ne.expressions_mut() {
            *e = fix.apply(g, *e)?;
        }
        let fixed = Elimination::Numeric(fixed_ne);
        let retained = retained_coordinates(g, inputs, &fixed_mass, &fixed_forcing, &fixed);
        let mut roots: Vec<Id> = mass.iter().chain(forcing.iter()).copied().collect();
        roots.extend(retained.iter().map(|&r| inputs.qdot[r]));
        let probe = ThroughSolve::new(g, ne, &roots);
        let kept: Vec<usize> = candidates
            .iter()
            .copied()
            .filter(|i| !retained.contains(i) && probe.independent_of(g, inputs.coords[*i].1.q))
            .collect();
        if kept.len() == candidates.len() {
            mass.copy_from_slice(&fixed_mass);
            forcing.copy_from_slice(&fixed_forcing);
            *elimination = fixed;
            return Ok(kept);
        }
        candidates = kept;
    }
    Ok(Vec::new())
}

/// Values computed through the numeric elimination, in f64: S X = R and
/// S w = (Ṙ − Ṡ X)[ẏ; 1] solved by Gaussian elimination with partial
/// pivoting, then the roots evaluated with X and w bound.
struct ThroughSolve<'a> {
    ne: &'a NumericElimination,
    /// S (k×k) row-major, then R's columns `ne.columns` (k of each).
    system: Tape,
    rate: Tape,
    roots: Tape,
}

impl<'a> ThroughSolve<'a> {
    fn new(g: &Graph, ne: &'a NumericElimination, roots: &[Id]) -> Self {
        let width = ne.x.len() / ne.k.max(1);
        let mut system = ne.s.clone();
        for &j in &ne.columns {
            system.extend((0..ne.k).map(|i| ne.r[i * width + j]));
        }
        ThroughSolve {
            ne,
            system: Tape::new(g, &system),
            rate: Tape::new(g, &ne.rhs_rate),
            roots: Tape::new(g, roots),
        }
    }

    /// The roots at the point `value` gives the model's symbols; `None`
    /// when an evaluation fails or S is singular there.
    fn eval(&self, value: &dyn Fn(Symbol) -> f64) -> Option<Vec<f64>> {
        let ne = self.ne;
        let k = ne.k;
        let width = ne.x.len() / k.max(1);
        let v = self.system.eval(&|s| Some(value(s))).ok()?;
        let s = &v[..k * k];
        let mut x = vec![0.0; k * width];
        for (c, &j) in ne.columns.iter().enumerate() {
            let col = solve_dense(s, &v[k * k + c * k..k * k + (c + 1) * k])?;
            for i in 0..k {
                x[i * width + j] = col[i];
            }
        }
        let bound = |sym: Symbol| -> f64 {
            match ne.x.iter().position(|&t| t == sym) {
                Some(p) => x[p],
                None => value(sym),
            }
        };
        let rate = self.rate.eval(&|sym| Some(bound(sym))).ok()?;
        let w = solve_dense(s, &rate)?;
        self.roots
            .eval(&|sym| match ne.w.iter().position(|&t| t == sym) {
                Some(p) => Some(w[p]),
                None => Some(bound(sym)),
            })
            .ok()
    }

    /// Whether S is regular, at three pseudo-random points, with the
    /// symbols `held` at `value`.
    fn regular(&self, g: &Graph, held: &[Symbol], value: f64) -> bool {
        let k = self.ne.k;
        if k == 0 {
            return true;
        }
        (0..3u64).all(|trial| {
            let at = |s: Symbol| {
                Some(if held.contains(&s) {
                    value
                } else {
                    pseudo_value(g, s, trial)
                })
            };
            self.system
                .eval(&at)
                .is_ok_and(|v| solve_dense(&v[..k * k], &vec![1.0; k]).is_some())
        })
    }

    /// Whether the roots keep their values when `q` alone moves, at three
    /// pseudo-random points (as [`numerically_independent`]); `false` when
    /// an evaluation fails.
    fn independent_of(&self, g: &Graph, q: Symbol) -> bool {
        (0..3u64).all(|trial| {
            let base = |s: Symbol| pseudo_value(g, s, trial);
            let Some(v0) = self.eval(&base) else {
                return false;
            };
            [0.7, 1.9].iter().all(|&shift| {
                let moved = |s: Symbol| base(s) + if s == q { shift } else { 0.0 };
                self.eval(&moved).is_some_and(|v1| {
                    v0.iter()
                        .zip(&v1)
                        .all(|(a, b)| (a - b).abs() <= 1e-9 * (1.0 + a.abs().max(b.abs())))
                })
            })
        })
    }
}

/// The solution of the k×k system `a` (row-major) x = `b`, by Gaussian
/// elimination with partial pivoting; `None` when a pivot falls below
/// 1e-10 of the largest entry (or the entries are not finite).
fn solve_dense(a: &[f64], b: &[f64]) -> Option<Vec<f64>> {
    let k = b.len();
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if !scale.is_finite() || scale == 0.0 {
        return None;
    }
    let mut m: Vec<Vec<f64>> = (0..k)
        .map(|i| {
            let mut row = a[i * k..(i + 1) * k].to_vec();
            row.push(b[i]);
            row
        })
        .collect();
    for c in 0..k {
        let pivot = (c..k).max_by(|&i, &j| m[i][c].abs().total_cmp(&m[j][c].abs()))?;
        if m[pivot][c].abs() < 1e-10 * scale {
            return None;
        }
        m.swap(c, pivot);
        for i in c + 1..k {
            let factor = m[i][c] / m[c][c];
            for j in c..=k {
                m[i][j] -= factor * m[c][j];
            }
        }
    }
    let mut x = vec![0.0; k];
    for i in (0..k).rev() {
        let tail: f64 = (i + 1..k).map(|j| m[i][j] * x[j]).sum();
        x[i] = (m[i][k] - tail) / m[i][i];
    }
    Some(x)
}

/// Sets to zero, in M, f and the numeric elimination, every coordinate
/// they read but do not depend on.
fn fix_independent_coordinates(
    g: &mut Graph,
    coords: &[(syn::Ident, appell_symbolic::Coordinate)],
    mass: &mut [Id],
    forcing: &mut [Id],
    elimination: &mut Elimination,
) -> Result<(), SymbolicError> {
    let zero = g.int(0)?;
    let mut core: Vec<Id> = mass.iter().chain(forcing.iter()).copied().collect();
    if let Elimination::Numeric(ne) = &*elimination {
        core.extend(ne.expressions());
    }
    let mut deps = SymbolSet::new();
    for &e in &core {
        deps.union_with(g.dependencies(e));
    }
    let tape = Tape::new(g, &core);
    let independent: Vec<Symbol> = coords
        .iter()
        .map(|(_, c)| c.q)
        .filter(|&q| {
            deps.contains(q)
                && !crate::probe::switches_on(g, &core, q)
                && numerically_independent(g, &tape, q)
        })
        .collect();
    if independent.is_empty() {
        return Ok(());
    }
    let mut fix = Substitution::new();
    for &q in &independent {
        fix.insert(q, zero);
    }
    for e in mass.iter_mut().chain(forcing.iter_mut()) {
        *e = fix.apply(g, *e)?;
    }
    if let Elimination::Numeric(ne) = elimination {
        for e in ne.expressions_mut() {
            *e = fix.apply(g, *e)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::testing;
    use super::super::{derive, Derivation};
    use crate::ctxt::Ctxt;

    fn derived(src: &str) -> Derivation {
        let cx = Ctxt::new();
        let d = derive(&cx, testing::kinematics(src));
        cx.check().expect("no errors");
        d.expect("a derivation").full
    }

    #[test]
    fn the_pendulum_keeps_its_angle() {
        let d = derived(testing::PENDULUM);
        assert_eq!(d.reduction.retained, vec![0]);
        assert!(d.reduction.ignorable.is_empty() && d.reduction.cyclic.is_empty());
    }

    #[test]
    fn a_dependent_coordinate_nothing_reads_is_cyclic() {
        // The disc on a line: M and f read neither x nor φ; x is dependent.
        let d = derived(testing::DISC_ON_A_LINE);
        assert!(d.reduction.retained.is_empty());
        assert_eq!(d.reduction.ignorable, vec![0, 1]);
        assert_eq!(d.reduction.cyclic, vec![0]);
    }

    #[test]
    fn the_sleigh_keeps_its_heading_only() {
        // Through X = tan θ the equations read θ; x and y are ignorable, and
        // y, dependent, is cyclic.
        let d = derived(testing::SLEIGH);
        assert_eq!(d.reduction.retained, vec![2]);
        assert_eq!(d.reduction.ignorable, vec![0, 1]);
        assert_eq!(d.reduction.cyclic, vec![1]);
    }

    /// The snakeboard as a user writes it from the docs: a board with a
    /// rotor at its centre P and two steered wheel axles a distance r
    /// ahead and behind, neither of which may slide sideways; the forward
    /// speed along the board is a quasi-velocity.
    const SNAKEBOARD: &str = r#"
        #[appell(coordinates(x, y, theta, psi, phi_b, phi_f))]
        #[appell(speeds(v = dot(velocity(P), B.x), psi, phi_b, phi_f))]
        #[appell(frame(B = N.rotate_z(theta)), frame(R = B.rotate_z(psi)))]
        #[appell(frame(Wb = B.rotate_z(phi_b)), frame(Wf = B.rotate_z(phi_f)))]
        #[appell(point(P = O + x * N.x + y * N.y))]
        #[appell(point(Pb = P - r * B.x), point(Pf = P + r * B.x))]
        #[appell(body(board, center = P, frame = B, mass = m, inertia = principal(j, j, j)))]
        #[appell(body(rotor, center = P, frame = R, mass = mr, inertia = principal(jr, jr, jr)))]
        #[appell(body(back, center = Pb, frame = Wb, mass = mw, inertia = principal(jw, jw, jw)))]
        #[appell(body(front, center = Pf, frame = Wf, mass = mw, inertia = principal(jw, jw, jw)))]
        #[appell(nonholonomic(dot(velocity(Pb), Wb.y) == 0))]
        #[appell(nonholonomic(dot(velocity(Pf), Wf.y) == 0))]
        struct Snakeboard { m: f64, j: f64, mr: f64, jr: f64, mw: f64, jw: f64, r: f64 }
    "#;

    #[test]
    fn the_snakeboard_drops_its_heading() {
        // Nothing the board does depends on where it is or which way it
        // points: x, y, θ and the rotor angle ψ are all ignorable.
        let d = derived(SNAKEBOARD);
        assert_eq!(d.reduction.retained, vec![4, 5]);
        assert_eq!(d.reduction.ignorable, vec![0, 1, 2, 3]);
    }
}
