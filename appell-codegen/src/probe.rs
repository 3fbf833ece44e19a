//! Numeric probes: questions about expressions answered by evaluating them
//! at pseudo-random points.
//!
//! The kinematics and the derivation ask questions the engine's canonical
//! forms cannot settle: are two expressions the same function (an identity
//! like sin² + cos² = 1 hidden in a product), is a row of D a combination of
//! the others, and does a value depend on a coordinate. Each is answered in
//! f64 at a few points fixed by the symbol and the trial number: parameters
//! in [0.5, 1.5] (the physical sign of a mass or a length), everything else
//! in [−1, 1]. The engine's exact test (`share_equal_values`, residues
//! modulo 2⁶¹ − 1) works on lowered instructions, not on graph nodes, and
//! does not see functions other than sine and cosine as it needs to here
//! (square roots of sums are independent residues there); these probes
//! evaluate the expressions themselves, square roots included, and report
//! an evaluation that fails (a square root of a negative number at a test
//! point) as "unknown" rather than guess.

use appell_symbolic::{Func, Graph, Id, Node, Symbol, SymbolKind, Tape};

/// A value in [0.5, 1.5] for parameters and [−1, 1] for everything else,
/// fixed by the symbol and the trial number (the numeric rank and
/// independence checks evaluate at such points).
///
/// ```
/// use appell_codegen::probe::pseudo_value;
/// let mut g = appell_symbolic::Graph::new();
/// let m = g.parameter("m").unwrap();
/// let q = g.coordinate("q").unwrap().q;
/// assert!((0.5..=1.5).contains(&pseudo_value(&g, m, 0)));
/// assert!((-1.0..=1.0).contains(&pseudo_value(&g, q, 0)));
/// assert_eq!(pseudo_value(&g, q, 3), pseudo_value(&g, q, 3));
/// ```
pub fn pseudo_value(g: &Graph, s: Symbol, trial: u64) -> f64 {
    let mut h = (s.index() as u64 + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15)
        ^ (trial + 1).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    h ^= h >> 31;
    h = h.wrapping_mul(0x94d0_49bb_1331_11eb);
    h ^= h >> 29;
    let u = (h >> 11) as f64 / (1u64 << 53) as f64;
    match g.symbol_kind(s) {
        SymbolKind::Parameter => 0.5 + u,
        _ => 2.0 * u - 1.0,
    }
}

/// Whether `a` and `b` are the same function: equal to 1e-10, relative, at
/// three pseudo-random points (see [`pseudo_value`]). A point where `a` is
/// below 1e-6 answers `false`, since a relative comparison says nothing
/// there: two expressions that vanish together are not called equal.
/// `None` when some evaluation fails.
pub fn same_function(g: &Graph, a: Id, b: Id) -> Option<bool> {
    let tape = Tape::new(g, &[a, b]);
    for trial in 0..3u64 {
        let v = tape.eval(&|s| Some(pseudo_value(g, s, trial))).ok()?;
        let (x, y) = (v[0], v[1]);
        if !(x.is_finite() && y.is_finite()) {
            return None;
        }
        if x.abs() < 1e-6 || (x - y).abs() > 1e-10 * x.abs().max(y.abs()) {
            return Some(false);
        }
    }
    Some(true)
}

/// A row of D that is numerically a combination of the rows before it,
/// when at each of three pseudo-random configurations (parameters in
/// [0.5, 1.5], coordinates and rates in [−1, 1]; up to six tried, those
/// that fail to evaluate skipped) some row is: the earliest such row found
/// at any of them. Rows independent at one configuration are independent,
/// so a dependence that holds only at special configurations is not
/// reported.
pub fn dependent_row(g: &Graph, d: &[Id], n: usize, m: usize) -> Option<usize> {
    if m < 2 {
        return None;
    }
    let tape = Tape::new(g, d);
    let mut first_dependent: Option<usize> = None;
    let mut trials = 0;
    for trial in 0..6u64 {
        let value = |s: Symbol| Some(pseudo_value(g, s, trial));
        let Ok(vals) = tape.eval(&value) else {
            continue;
        };
        trials += 1;
        // Incremental Gram–Schmidt rank test, row by row.
        let mut basis = Basis::default();
        let dep = (0..m).find(|&r| !basis.extends(&vals[r * n..(r + 1) * n]));
        match dep {
            None => return None,
            Some(r) => first_dependent = Some(first_dependent.map_or(r, |f: usize| f.min(r))),
        }
        if trials == 3 {
            break;
        }
    }
    first_dependent
}

/// An orthonormal basis grown vector by vector (Gram–Schmidt): the
/// numeric rank tests of [`dependent_row`] and of a contact's joints.
#[derive(Default)]
pub struct Basis(Vec<Vec<f64>>);

impl Basis {
    /// Adds `v` when it is independent of the basis (its part outside the
    /// span above 1e-9 of its length) and says whether it was.
    ///
    /// ```
    /// use appell_codegen::probe::Basis;
    /// let mut b = Basis::default();
    /// assert!(b.extends(&[1.0, 0.0]));
    /// assert!(!b.extends(&[2.0, 0.0]));
    /// assert!(b.extends(&[1.0, 1.0]));
    /// assert!(!b.extends(&[0.0, 0.0]));
    /// ```
    pub fn extends(&mut self, v: &[f64]) -> bool {
        let mut v = v.to_vec();
        let norm0 = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        for b in &self.0 {
            let p: f64 = v.iter().zip(b).map(|(x, y)| x * y).sum();
            for (x, y) in v.iter_mut().zip(b) {
                *x -= p * y;
            }
        }
        let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        if norm <= 1e-9 * norm0.max(1e-300) {
            return false;
        }
        self.0.push(v.iter().map(|x| x / norm).collect());
        true
    }
}

/// Whether a piecewise function reachable from `roots` switches on `q`:
/// a `select` (a conditional, `min`, `max`) whose condition or a `sign`
/// whose argument depends on it. Such expressions can be flat in `q` at
/// every probe (a one-sided spring probed where it does not touch) and
/// still depend on it, so probes cannot show them independent.
pub fn switches_on(g: &Graph, roots: &[Id], q: Symbol) -> bool {
    let mut seen = std::collections::HashSet::new();
    let mut stack: Vec<Id> = roots
        .iter()
        .copied()
        .filter(|&r| g.depends_on(r, q))
        .collect();
    while let Some(id) = stack.pop() {
        if !seen.insert(id) {
            continue;
        }
        match g.node(id) {
            Node::Select(c, _, _) if g.depends_on(*c, q) => return true,
            Node::Fun(Func::Sign, a) if g.depends_on(*a, q) => return true,
            node => stack.extend(node.children().into_iter().filter(|&c| g.depends_on(c, q))),
        }
    }
    false
}

/// Whether the values of `tape` stay the same (to 1e-9 of 1 + the larger magnitude) when the
/// symbol `q` alone changes, at three pseudo-random points and two shifts.
/// Any evaluation failure counts as a dependence.
/// Piecewise laws can fool it: see [`switches_on`].
pub fn numerically_independent(g: &Graph, tape: &Tape, q: Symbol) -> bool {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_one_sided_law_is_not_taken_for_independent() {
        let mut g = Graph::new();
        let e = g.parse("select(-x, -k*x, 0) + y").unwrap();
        let x = g.symbol_named("x").unwrap();
        let y = g.symbol_named("y").unwrap();
        assert!(switches_on(&g, &[e], x));
        assert!(!switches_on(&g, &[e], y));
        let s = g.parse("z*sign(w)").unwrap();
        let w = g.symbol_named("w").unwrap();
        assert!(switches_on(&g, &[s], w));
    }

    #[test]
    fn same_function_sees_identities_the_expansion_does_not() {
        let mut g = Graph::new();
        g.coordinate("q").unwrap();
        g.parameter("r").unwrap();
        let a = g.parse("r*sin(q)^2 + r*cos(q)^2").unwrap();
        let b = g.parse("r").unwrap();
        let c = g.parse("r*sin(q)").unwrap();
        assert_eq!(same_function(&g, a, b), Some(true));
        assert_eq!(same_function(&g, a, c), Some(false));
        let nan = g.parse("sqrt(-r)").unwrap();
        assert_eq!(same_function(&g, nan, nan), None);
    }
}

#[cfg(test)]
mod rank_tests {
    use super::*;

    #[test]
    fn a_row_that_combines_earlier_rows_is_found() {
        let mut g = Graph::new();
        g.coordinate("q").unwrap();
        g.parameter("r").unwrap();
        // Rows of D (m = 3, n = 2): the third is r times the first plus the
        // second, at every configuration.
        let d: Vec<Id> = ["cos(q)", "sin(q)", "1", "r", "r*cos(q) + 1", "r*sin(q) + r"]
            .iter()
            .map(|t| g.parse(t).unwrap())
            .collect();
        assert_eq!(dependent_row(&g, &d, 2, 3), Some(2));
        assert_eq!(dependent_row(&g, &d[..4], 2, 2), None);
    }
}
