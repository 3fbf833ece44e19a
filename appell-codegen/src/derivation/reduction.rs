//! Stage 12: the reduced state (Sec. III C, eq. 42).
//!
//! Coordinates that occur in the equations but on which they do not depend
//! (an axisymmetric wheel's angle, a bicycle's heading after the
//! elimination) are found numerically at pseudo-random points and set to
//! zero in M, f and the numeric elimination, so they drop out. The retained
//! coordinates are then those M and f need, those a scene integrates by
//! quadrature, and those the retained coordinates' rates need; the others
//! are ignorable, and the ignorable dependent ones are cyclic.

use std::collections::BTreeSet;

use appell_symbolic::{Graph, Id, Substitution, Symbol, SymbolSet, SymbolicError, Tape};

use super::energies::Energies;
use super::loads::Equations;
use super::numeric::Elimination;
use super::speed_map::SpeedMap;
use crate::probe::pseudo_value;

/// The output of stage 12.
#[derive(Clone)]
pub struct Reduction {
    /// Coordinates kept in the reduced state.
    pub retained: Vec<usize>,
    /// Cyclic (dependent, absent) coordinates.
    pub cyclic: Vec<usize>,
    /// All coordinates left out of the reduced state.
    pub ignorable: Vec<usize>,
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
    let ReductionInputs {
        coords,
        quadrature,
        qdot,
        dependent,
    } = inputs;
    let n = coords.len();
    fix_independent_coordinates(g, coords, mass, forcing, elimination)?;
    let aux_deps = match &*elimination {
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
    // A value's symbols, an auxiliary one standing for everything the
    // numeric solve reads.
    let deps_of = |g: &Graph, e: Id| -> SymbolSet {
        let mut set = g.dependencies(e).clone();
        for (s, d) in &aux_deps {
            if set.contains(*s) {
                set.union_with(d);
            }
        }
        set
    };
    let coord_of = |set: &SymbolSet| -> BTreeSet<usize> {
        coords
            .iter()
            .enumerate()
            .filter(|(_, (_, c))| set.contains(c.q))
            .map(|(i, _)| i)
            .collect()
    };
    let mut retained: BTreeSet<usize> = quadrature.iter().copied().collect();
    for &e in mass.iter().chain(forcing.iter()) {
        retained.extend(coord_of(&deps_of(g, e)));
    }
    loop {
        let before = retained.len();
        for r in retained.clone() {
            retained.extend(coord_of(&deps_of(g, qdot[r])));
        }
        if retained.len() == before {
            break;
        }
    }
    let retained: Vec<usize> = retained.into_iter().collect();
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
    })
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
        .filter(|&q| deps.contains(q) && numerically_independent(g, &tape, q))
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

/// Whether the values of `tape` stay the same (to 1e-9, relative) when the
/// symbol `q` alone changes, at three pseudo-random points and two shifts.
/// Any evaluation failure counts as a dependence.
fn numerically_independent(g: &Graph, tape: &Tape, q: Symbol) -> bool {
    for trial in 0..3u64 {
        let base = |s: Symbol| Some(pseudo_value(g, s, trial));
        let Ok(v0) = tape.eval(&base) else {
            return false;
        };
        for shift in [0.7, 1.9] {
            let moved =
                |s: Symbol| Some(pseudo_value(g, s, trial) + if s == q { shift } else { 0.0 });
            let Ok(v1) = tape.eval(&moved) else {
                return false;
            };
            let same = v0
                .iter()
                .zip(&v1)
                .all(|(a, b)| (a - b).abs() <= 1e-9 * (1.0 + a.abs().max(b.abs())));
            if !same {
                return false;
            }
        }
    }
    true
}

/// Sets the symbols of X's vanishing last column to zero everywhere: they
/// have done their work (carrying w into the accelerations).
pub fn drop_vanishing(
    g: &mut Graph,
    vanishing: &[Symbol],
    map: &mut SpeedMap,
    equations: &mut Equations,
    energies: &mut Energies,
    elimination: &mut Elimination,
) -> Result<(), SymbolicError> {
    if vanishing.is_empty() {
        return Ok(());
    }
    let zero = g.int(0)?;
    let mut zero_x = Substitution::new();
    for &s in vanishing {
        zero_x.insert(s, zero);
    }
    let mut fix = |g: &mut Graph, e: &mut Id| -> Result<(), SymbolicError> {
        *e = zero_x.apply(g, *e)?;
        Ok(())
    };
    for e in map
        .c
        .iter_mut()
        .chain(map.c0.iter_mut())
        .chain(map.qdot.iter_mut())
    {
        fix(g, e)?;
    }
    for e in equations
        .mass
        .iter_mut()
        .chain(equations.forcing.iter_mut())
    {
        fix(g, e)?;
    }
    for e in [
        &mut energies.kinetic,
        &mut energies.potential,
        &mut energies.input_power,
    ] {
        fix(g, e)?;
    }
    for e in equations.inertial_terms.iter_mut().flatten() {
        fix(g, e)?;
    }
    for (_, terms) in equations.load_terms.iter_mut() {
        for e in terms.iter_mut() {
            fix(g, e)?;
        }
    }
    for (_, e) in energies.power_terms.iter_mut() {
        fix(g, e)?;
    }
    if let Elimination::Numeric(ne) = elimination {
        for e in ne.expressions_mut() {
            fix(g, e)?;
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
}
