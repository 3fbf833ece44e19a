//! Substitution of symbols by expressions, and expansion of products of sums.
//!
//! Both are DAG maps: each node is rebuilt at most once per call (memoized),
//! children first, and any node that does not depend on a substituted symbol
//! is kept as it is without being visited.

use std::collections::BTreeMap;

use crate::deps::SymbolSet;
use crate::error::{Result, SymbolicError};
use crate::graph::{FxHashMap, Graph, Id, Node, Symbol};
use crate::number::Number;

/// A reusable substitution `symbol → expression`. Reusing one value for many
/// roots shares the rebuilt nodes between them.
///
/// ```
/// use appell_symbolic::{Graph, Substitution};
/// let mut g = Graph::new();
/// let e = g.parse("x^2 + sin(x)*y").unwrap();
/// let x = g.symbol_named("x").unwrap();
/// let rep = g.parse("2*t").unwrap();
/// let mut sub = Substitution::new();
/// sub.insert(x, rep);
/// let r = sub.apply(&mut g, e).unwrap();
/// assert_eq!(r, g.parse("4*t^2 + y*sin(2*t)").unwrap());
/// ```
#[derive(Clone, Debug, Default)]
pub struct Substitution {
    map: BTreeMap<Symbol, Id>,
    symbols: SymbolSet,
    memo: FxHashMap<Id, Id>,
}

impl Substitution {
    /// An empty substitution.
    pub fn new() -> Substitution {
        Substitution::default()
    }

    /// Replaces `s` by `e` (clears what was memoized so far).
    pub fn insert(&mut self, s: Symbol, e: Id) {
        self.map.insert(s, e);
        self.symbols.insert(s);
        self.memo.clear();
    }

    /// Applies the substitution to one expression.
    pub fn apply(&mut self, g: &mut Graph, root: Id) -> Result<Id> {
        let mut stack = vec![(root, false)];
        while let Some((id, expanded)) = stack.pop() {
            if self.memo.contains_key(&id) {
                continue;
            }
            if !g.depends_on_any(id, &self.symbols) {
                self.memo.insert(id, id);
                continue;
            }
            if let Node::Sym(s) = g.node(id) {
                let r = self.map[s];
                self.memo.insert(id, r);
                continue;
            }
            if !expanded {
                stack.push((id, true));
                g.node(id).for_each_child(|c| stack.push((c, false)));
                continue;
            }
            let node = g.node(id).clone();
            let memo = &self.memo;
            let r = g.rebuild(&node, |c| memo[&c])?;
            self.memo.insert(id, r);
        }
        Ok(self.memo[&root])
    }

    /// Applies the substitution to several expressions.
    pub fn apply_all(&mut self, g: &mut Graph, roots: &[Id]) -> Result<Vec<Id>> {
        roots.iter().map(|&r| self.apply(g, r)).collect()
    }
}

impl Graph {
    /// Rebuilds `node` through the canonical constructors with its children
    /// replaced by `map(child)`.
    pub(crate) fn rebuild(&mut self, node: &Node, map: impl Fn(Id) -> Id) -> Result<Id> {
        match node {
            Node::Num(_) | Node::Sym(_) => self.intern(node.clone()),
            Node::Add { constant, terms } => {
                let parts: Vec<(Id, Number)> = terms.iter().map(|&(b, k)| (map(b), k)).collect();
                self.linear_combination(*constant, parts)
            }
            Node::Mul { coeff, factors } => {
                let parts: Vec<(Id, i64)> =
                    factors.iter().map(|&(b, e)| (map(b), e as i64)).collect();
                if parts.iter().any(|&(b, e)| e < 0 && self.is_zero(b)) {
                    return Err(SymbolicError::DivisionByZero {
                        expr: "a substituted expression".to_string(),
                    });
                }
                self.power_product(*coeff, parts)
            }
            Node::Fun(f, a) => self.func(*f, map(*a)),
            Node::Atan2(y, x) => self.atan2(map(*y), map(*x)),
            Node::Powf(x, y) => self.powf(map(*x), map(*y)),
            Node::Select(c, a, b) => self.select(map(*c), map(*a), map(*b)),
        }
    }

    /// Substitutes symbols in one expression (see [`Substitution`] to reuse
    /// work across many).
    pub fn substitute(&mut self, e: Id, pairs: &[(Symbol, Id)]) -> Result<Id> {
        let mut sub = Substitution::new();
        for &(s, r) in pairs {
            sub.insert(s, r);
        }
        sub.apply(self, e)
    }

    /// Multiplies out products and positive integer powers of sums, keeping
    /// negative powers (denominators) as they are. Bounded by
    /// [`crate::Limits::max_terms`].
    ///
    /// ```
    /// use appell_symbolic::Graph;
    /// let mut g = Graph::new();
    /// let e = g.parse("(x + y)^2 - x*(x + 2*y)").unwrap();
    /// let x = g.expand(e).unwrap();
    /// assert_eq!(g.display(x).to_string(), "y^2");
    /// ```
    pub fn expand(&mut self, root: Id) -> Result<Id> {
        let limit = self.limits.max_terms;
        self.expand_within(root, limit)
    }

    /// [`Graph::expand`] with its own term limit: any intermediate product
    /// of sums with more than `max_terms` terms is a
    /// [`SymbolicError::TermLimit`] error, so an expansion that would blow
    /// up is abandoned early.
    ///
    /// ```
    /// use appell_symbolic::{Graph, SymbolicError};
    /// let mut g = Graph::new();
    /// let e = g.parse("(a + b + c)*(d + e + f)").unwrap();
    /// assert!(matches!(g.expand_within(e, 4), Err(SymbolicError::TermLimit { limit: 4 })));
    /// assert!(g.expand_within(e, 9).is_ok());
    /// ```
    pub fn expand_within(&mut self, root: Id, max_terms: usize) -> Result<Id> {
        let saved = self.limits.max_terms;
        self.limits.max_terms = max_terms.min(saved);
        let r = self.expand_inner(root, true);
        self.limits.max_terms = saved;
        r
    }

    /// [`Graph::expand_within`] at the top level only: function arguments
    /// (`sqrt(...)`, `sin(...)`, `atan2(...)`) are left as they are, so one
    /// argument keeps one form wherever it occurs and its function value is
    /// shared.
    ///
    /// ```
    /// use appell_symbolic::Graph;
    /// let mut g = Graph::new();
    /// let e = g.parse("(a + b)*c + sqrt((a + b)*c)").unwrap();
    /// let x = g.expand_outside_functions(e, 16).unwrap();
    /// let want = g.parse("a*c + b*c + sqrt((a + b)*c)").unwrap();
    /// assert_eq!(x, want);
    /// // `expand` multiplies out inside the square root too.
    /// let y = g.expand(e).unwrap();
    /// assert_ne!(y, want);
    /// ```
    pub fn expand_outside_functions(&mut self, root: Id, max_terms: usize) -> Result<Id> {
        let saved = self.limits.max_terms;
        self.limits.max_terms = max_terms.min(saved);
        let r = self.expand_inner(root, false);
        self.limits.max_terms = saved;
        r
    }

    fn expand_inner(&mut self, root: Id, inside_functions: bool) -> Result<Id> {
        let mut memo: FxHashMap<Id, Id> = FxHashMap::default();
        let mut stack = vec![(root, false)];
        while let Some((id, expanded)) = stack.pop() {
            if memo.contains_key(&id) {
                continue;
            }
            if !expanded {
                if !inside_functions
                    && matches!(
                        self.node(id),
                        Node::Fun(..) | Node::Atan2(..) | Node::Powf(..) | Node::Select(..)
                    )
                {
                    memo.insert(id, id);
                    continue;
                }
                stack.push((id, true));
                self.node(id).for_each_child(|c| stack.push((c, false)));
                continue;
            }
            let node = self.node(id).clone();
            let r = match &node {
                Node::Mul { coeff, factors } => {
                    // (sum of terms) for each positive factor, multiplied out.
                    let mut acc: Vec<(Id, Number)> = Vec::new();
                    let mut acc_const = *coeff;
                    let mut started = false;
                    let mut keep: Vec<(Id, i64)> = Vec::new();
                    for &(b, e) in factors.iter() {
                        let b = memo[&b];
                        match self.node(b).clone() {
                            Node::Add { constant, terms } if e > 0 => {
                                for _ in 0..e {
                                    let (c2, t2) = self.multiply_sums(
                                        (acc_const, &acc, started),
                                        (constant, &terms),
                                    )?;
                                    acc_const = c2;
                                    acc = t2;
                                    started = true;
                                }
                            }
                            _ => keep.push((b, e as i64)),
                        }
                    }
                    let rest = self.power_product(Number::ONE, keep)?;
                    if !started {
                        self.power_product(acc_const, [(rest, 1)])?
                    } else {
                        let mut parts = Vec::with_capacity(acc.len() + 1);
                        for (t, k) in acc {
                            parts.push((self.power_product(k, [(t, 1), (rest, 1)])?, Number::ONE));
                        }
                        parts.push((rest, acc_const));
                        self.linear_combination(Number::ZERO, parts)?
                    }
                }
                _ => self.rebuild(&node, |c| memo[&c])?,
            };
            memo.insert(id, r);
        }
        Ok(memo[&root])
    }

    /// `(c1 + Σ a) · (c2 + Σ b)` as a constant and a list of terms. When
    /// `started` is false the left side is the bare coefficient `c1`.
    #[allow(clippy::type_complexity)] // a pair of (constant, terms) is the natural shape here
    fn multiply_sums(
        &mut self,
        left: (Number, &[(Id, Number)], bool),
        right: (Number, &[(Id, Number)]),
    ) -> Result<(Number, Vec<(Id, Number)>)> {
        let (c1, a, started) = left;
        let (c2, b) = right;
        let a: Vec<(Id, Number)> = if started { a.to_vec() } else { Vec::new() };
        if a.len().saturating_mul(b.len()) > self.limits.max_terms {
            return Err(SymbolicError::TermLimit {
                limit: self.limits.max_terms,
            });
        }
        let mut out = Vec::with_capacity(a.len() * b.len() + a.len() + b.len());
        for &(x, kx) in &a {
            for &(y, ky) in b {
                out.push((self.mul(x, y)?, kx.mul(ky)));
            }
            if !c2.is_zero() {
                out.push((x, kx.mul(c2)));
            }
        }
        if !c1.is_zero() {
            for &(y, ky) in b {
                out.push((y, c1.mul(ky)));
            }
        }
        // Collect like terms now so repeated multiplication stays small.
        let sum = self.linear_combination(c1.mul(c2), out)?;
        Ok(match self.node(sum).clone() {
            Node::Add { constant, terms } => (constant, terms.to_vec()),
            Node::Num(n) => (n, Vec::new()),
            Node::Mul { coeff, factors } if !coeff.is_one() => {
                let f: Vec<(Id, i64)> = factors.iter().map(|&(b, e)| (b, e as i64)).collect();
                (
                    Number::ZERO,
                    vec![(self.power_product(Number::ONE, f)?, coeff)],
                )
            }
            _ => (Number::ZERO, vec![(sum, Number::ONE)]),
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::Graph;

    fn expands_to(src: &str, expected: &str) {
        let mut g = Graph::new();
        let e = g.parse(src).unwrap();
        let x = g.expand(e).unwrap();
        let y = g.parse(expected).unwrap();
        assert_eq!(x, y, "{} vs {}", g.display(x), g.display(y));
    }

    #[test]
    fn binomial_square() {
        expands_to("(x + 1)^2", "x^2 + 2*x + 1");
    }
    #[test]
    fn difference_of_squares() {
        expands_to("(x - y)*(x + y)", "x^2 - y^2");
    }
    #[test]
    fn keeps_denominators() {
        expands_to("(x + 1)*y/(x + 2)", "x*y/(x + 2) + y/(x + 2)");
    }
    #[test]
    fn expands_inside_functions() {
        expands_to("sin((x + 1)^2)", "sin(x^2 + 2*x + 1)");
    }
    #[test]
    fn expansion_cancels_to_zero() {
        expands_to("(a + b)*(a - b) - a^2 + b^2", "0");
    }
    #[test]
    fn substitute_to_zero_divisor_is_an_error() {
        let mut g = Graph::new();
        let e = g.parse("1/x").unwrap();
        let x = g.symbol_named("x").unwrap();
        let z = g.int(0).unwrap();
        assert!(g.substitute(e, &[(x, z)]).is_err());
    }
    #[test]
    fn untouched_nodes_keep_identity() {
        let mut g = Graph::new();
        let e = g.parse("sin(y) + x").unwrap();
        let sy = g.parse("sin(y)").unwrap();
        let x = g.symbol_named("x").unwrap();
        let z = g.int(0).unwrap();
        assert_eq!(g.substitute(e, &[(x, z)]).unwrap(), sy);
    }
}
