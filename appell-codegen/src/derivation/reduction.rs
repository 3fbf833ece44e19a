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

use super::numeric::Elimination;
use crate::probe::numerically_independent;

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
}
