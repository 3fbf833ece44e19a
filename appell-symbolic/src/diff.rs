//! Differentiation: partial derivatives with respect to a symbol (memoized in
//! the graph) and total time derivatives under rate rules.
//!
//! Both walk the DAG once, children first, with an explicit stack (no
//! recursion, so deep expressions cannot overflow the stack) and skip every
//! subexpression that does not depend on a differentiated symbol.

use std::collections::BTreeMap;

use crate::deps::SymbolSet;
use crate::error::{Result, SymbolicError};
use crate::graph::{Func, FxHashMap, Graph, Id, Node, Symbol, SymbolKind};
use crate::number::Number;

/// How the total time derivative treats each symbol.
///
/// The defaults ([`RateRules::coordinates`]): a coordinate q has rate q̇, q̇ has
/// rate q̈, time has rate 1, parameters are constant. Inputs, accelerations and
/// auxiliary symbols have no rate unless a rule gives one (an error names the
/// symbol otherwise). [`RateRules::with`] overrides a rate, e.g. to use
/// q̇ = Σ C u + c directly.
///
/// ```
/// use appell_symbolic::{Graph, RateRules};
/// let mut g = Graph::new();
/// let q = g.coordinate("q").unwrap();
/// let u = g.declare("u", appell_symbolic::SymbolKind::Auxiliary).unwrap();
/// let two_u = g.parse("2*u").unwrap();
/// let rules = RateRules::coordinates().with(q.q, two_u);
/// let e = g.parse("q^2").unwrap();
/// let de = g.time_derivative(e, &rules).unwrap();
/// assert_eq!(g.display(de).to_string(), "4*q*u");
/// ```
#[derive(Clone, Debug, Default)]
pub struct RateRules {
    explicit: BTreeMap<Symbol, Id>,
    constants: SymbolSet,
}

impl RateRules {
    /// The default rules for coordinates, their rates, time and parameters.
    pub fn coordinates() -> RateRules {
        RateRules::default()
    }

    /// Sets the rate of `s` to the expression `rate`.
    pub fn with(mut self, s: Symbol, rate: Id) -> RateRules {
        self.explicit.insert(s, rate);
        self
    }

    /// Declares `s` constant in time (rate 0), e.g. an input held over a step.
    pub fn constant(mut self, s: Symbol) -> RateRules {
        self.constants.insert(s);
        self
    }

    fn rate(&self, g: &mut Graph, s: Symbol) -> Result<Id> {
        if let Some(&r) = self.explicit.get(&s) {
            return Ok(r);
        }
        if self.constants.contains(s) {
            return g.int(0);
        }
        match g.symbol_kind(s) {
            SymbolKind::Parameter => g.int(0),
            SymbolKind::Time => g.int(1),
            SymbolKind::Coordinate | SymbolKind::Rate(_) => match g.derivative_symbol(s) {
                Some(d) => g.sym(d),
                None => Err(SymbolicError::NoRateRule {
                    symbol: g.symbol_name(s).to_string(),
                }),
            },
            _ => Err(SymbolicError::NoRateRule {
                symbol: g.symbol_name(s).to_string(),
            }),
        }
    }

    /// The symbols whose rate may be non-zero under these rules.
    fn moving(&self, g: &Graph) -> SymbolSet {
        let mut set = SymbolSet::new();
        for (s, info) in g.symbols() {
            let constant = self.constants.contains(s)
                || (info.kind == SymbolKind::Parameter && !self.explicit.contains_key(&s));
            if !constant {
                set.insert(s);
            }
        }
        set
    }
}

impl Graph {
    /// ∂e/∂s, memoized across calls.
    ///
    /// ```
    /// use appell_symbolic::Graph;
    /// let mut g = Graph::new();
    /// let e = g.parse("x^3*sin(y) + atan2(y, x)").unwrap();
    /// let x = g.symbol_named("x").unwrap();
    /// let d = g.diff(e, x).unwrap();
    /// let expected = g.parse("3*x^2*sin(y) - y/(x^2 + y^2)").unwrap();
    /// assert_eq!(d, expected);
    /// ```
    pub fn diff(&mut self, e: Id, s: Symbol) -> Result<Id> {
        if let Some(&d) = self.diff_memo.get(&(e, s)) {
            return Ok(d);
        }
        let relevant = SymbolSet::single(s);
        let mut memo = FxHashMap::default();
        let one = self.int(1)?;
        let result = self.derive(e, &relevant, &mut memo, &mut |_, _| Ok(one))?;
        for (k, v) in memo {
            self.diff_memo.insert((k, s), v);
        }
        Ok(result)
    }

    /// ∂e/∂s as [`Graph::diff`], with the derivative of every held factor
    /// ([`Graph::hold`]) held too: a recursion's held quantities keep their
    /// derivatives single factors, as the quantities themselves are, where
    /// `diff` lets the canonical forms merge them into their users (fewer
    /// expressions for small models, more operations for long
    /// recursions). Memoized apart from `diff`.
    ///
    /// ```
    /// use appell_symbolic::{Func, Graph, Node};
    /// let mut g = Graph::new();
    /// let sum = g.parse("x^2 + x*y").unwrap();
    /// let held = g.hold(sum).unwrap();
    /// let x = g.symbol_named("x").unwrap();
    /// // ∂/∂x = 2x + y, held as one factor.
    /// let d = g.diff_held(held, x).unwrap();
    /// assert!(matches!(g.node(d), Node::Fun(Func::Hold, _)));
    /// let three = g.int(3).unwrap();
    /// let product = g.mul(three, d).unwrap();
    /// assert_eq!(g.display(product).to_string(), "3*(2*x + y)");
    /// // diff merges it into its users.
    /// let plain = g.diff(held, x).unwrap();
    /// assert_eq!(plain, g.parse("2*x + y").unwrap());
    /// ```
    pub fn diff_held(&mut self, e: Id, s: Symbol) -> Result<Id> {
        if let Some(&d) = self.held_diff_memo.get(&(e, s)) {
            return Ok(d);
        }
        let relevant = SymbolSet::single(s);
        let mut memo = FxHashMap::default();
        let one = self.int(1)?;
        self.hold_derivatives = true;
        let result = self.derive(e, &relevant, &mut memo, &mut |_, _| Ok(one));
        self.hold_derivatives = false;
        let result = result?;
        for (k, v) in memo {
            self.held_diff_memo.insert((k, s), v);
        }
        Ok(result)
    }

    /// The total time derivative d e / d t under `rules`.
    pub fn time_derivative(&mut self, e: Id, rules: &RateRules) -> Result<Id> {
        Ok(self.time_derivatives(&[e], rules)?[0])
    }

    /// Total time derivatives of several expressions, sharing work between them.
    pub fn time_derivatives(&mut self, roots: &[Id], rules: &RateRules) -> Result<Vec<Id>> {
        let relevant = rules.moving(self);
        let mut memo = FxHashMap::default();
        let mut leaf_cache: FxHashMap<Symbol, Id> = FxHashMap::default();
        let mut leaf = |g: &mut Graph, s: Symbol| -> Result<Id> {
            if let Some(&r) = leaf_cache.get(&s) {
                return Ok(r);
            }
            let r = rules.rate(g, s)?;
            leaf_cache.insert(s, r);
            Ok(r)
        };
        roots
            .iter()
            .map(|&r| self.derive(r, &relevant, &mut memo, &mut leaf))
            .collect()
    }

    /// The chain rule over the DAG. `leaf(s)` gives the derivative of symbol
    /// `s ∈ relevant`; every other symbol has derivative zero.
    fn derive(
        &mut self,
        root: Id,
        relevant: &SymbolSet,
        memo: &mut FxHashMap<Id, Id>,
        leaf: &mut dyn FnMut(&mut Graph, Symbol) -> Result<Id>,
    ) -> Result<Id> {
        let zero = self.int(0)?;
        let mut stack = vec![(root, false)];
        while let Some((id, expanded)) = stack.pop() {
            if memo.contains_key(&id) {
                continue;
            }
            if !self.depends_on_any(id, relevant) {
                memo.insert(id, zero);
                continue;
            }
            if !expanded {
                stack.push((id, true));
                self.node(id).for_each_child(|c| {
                    if !memo.contains_key(&c) {
                        stack.push((c, false));
                    }
                });
                continue;
            }
            let d = self.derive_node(id, memo, leaf)?;
            memo.insert(id, d);
        }
        Ok(memo[&root])
    }

    fn derive_node(
        &mut self,
        id: Id,
        memo: &FxHashMap<Id, Id>,
        leaf: &mut dyn FnMut(&mut Graph, Symbol) -> Result<Id>,
    ) -> Result<Id> {
        let node = self.node(id).clone();
        match node {
            Node::Num(_) => self.int(0),
            Node::Sym(s) => leaf(self, s),
            Node::Add { terms, .. } => {
                let parts: Vec<(Id, Number)> = terms.iter().map(|&(b, k)| (memo[&b], k)).collect();
                self.linear_combination(Number::ZERO, parts)
            }
            Node::Mul { coeff, factors } => {
                // d(c Π fᵢ^eᵢ) = Σᵢ c eᵢ fᵢ^(eᵢ−1) f'ᵢ Π_{j≠i} fⱼ^eⱼ
                let mut parts = Vec::new();
                for (i, &(f, e)) in factors.iter().enumerate() {
                    let df = memo[&f];
                    if self.is_zero(df) {
                        continue;
                    }
                    let mut fs: Vec<(Id, i64)> =
                        factors.iter().map(|&(b, x)| (b, x as i64)).collect();
                    fs[i].1 -= 1;
                    fs.push((df, 1));
                    let term = self.power_product(coeff.mul(Number::int(e as i64)), fs)?;
                    parts.push((term, Number::ONE));
                }
                self.linear_combination(Number::ZERO, parts)
            }
            Node::Fun(func, a) => {
                let da = memo[&a];
                let outer = match func {
                    Func::Sin => self.cos(a)?,
                    Func::Cos => {
                        let s = self.sin(a)?;
                        self.neg(s)?
                    }
                    Func::Tan => {
                        let t = self.tan(a)?;
                        let t2 = self.powi(t, 2)?;
                        self.linear_combination(Number::ONE, [(t2, Number::ONE)])?
                    }
                    Func::Exp => id,
                    Func::Ln => self.recip(a)?,
                    Func::Abs => self.div(a, id)?,
                    Func::Sqrt => {
                        self.power_product(Number::ratio(1, 2).expect("1/2"), [(id, -1)])?
                    }
                    Func::Sinh => self.cosh(a)?,
                    Func::Cosh => self.sinh(a)?,
                    Func::Tanh => {
                        // 1 − tanh²
                        let t2 = self.powi(id, 2)?;
                        self.linear_combination(Number::ONE, [(t2, Number::int(-1))])?
                    }
                    Func::Asin | Func::Acos => {
                        // ±1/√(1 − a²)
                        let a2 = self.powi(a, 2)?;
                        let r = self.linear_combination(Number::ONE, [(a2, Number::int(-1))])?;
                        let root = self.sqrt(r)?;
                        let k = if func == Func::Asin { 1 } else { -1 };
                        self.power_product(Number::int(k), [(root, -1)])?
                    }
                    Func::Atan => {
                        let a2 = self.powi(a, 2)?;
                        let r = self.linear_combination(Number::ONE, [(a2, Number::ONE)])?;
                        self.recip(r)?
                    }
                    // Piecewise constant: zero away from 0.
                    Func::Sign => return self.int(0),
                    Func::Hold if self.hold_derivatives => return self.hold(da),
                    Func::Hold => return Ok(da),
                };
                self.mul(outer, da)
            }
            Node::Powf(x, y) => {
                // d x^y = x^y (y' ln x + y x'/x)
                let (dx, dy) = (memo[&x], memo[&y]);
                let mut inner = self.power_product(Number::ONE, [(y, 1), (dx, 1), (x, -1)])?;
                if !self.is_zero(dy) {
                    let ln = self.ln(x)?;
                    let a = self.mul(dy, ln)?;
                    inner = self.add(a, inner)?;
                }
                self.mul(id, inner)
            }
            Node::Select(c, a, b) => {
                // Differentiated branch by branch.
                let (da, db) = (memo[&a], memo[&b]);
                self.select(c, da, db)
            }
            Node::Atan2(y, x) => {
                // d atan2(y, x) = (x y' − y x') / (x² + y²)
                let (dy, dx) = (memo[&y], memo[&x]);
                let a = self.mul(x, dy)?;
                let b = self.mul(y, dx)?;
                let num = self.sub(a, b)?;
                let x2 = self.powi(x, 2)?;
                let y2 = self.powi(y, 2)?;
                let den = self.add(x2, y2)?;
                self.div(num, den)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::{Graph, RateRules};

    fn d(src: &str, var: &str) -> String {
        let mut g = Graph::new();
        let e = g.parse(src).unwrap();
        let s = g.symbol_named(var).unwrap();
        let r = g.diff(e, s).unwrap();
        g.display(r).to_string()
    }

    fn same(a: &str, var: &str, expected: &str) {
        let mut g = Graph::new();
        let e = g.parse(a).unwrap();
        let s = g.symbol_named(var).unwrap();
        let r = g.diff(e, s).unwrap();
        let x = g.parse(expected).unwrap();
        assert_eq!(
            r,
            x,
            "d/d{var} {a} = {} (expected {expected})",
            g.display(r)
        );
    }

    #[test]
    fn a_held_sum_differentiates_as_the_sum() {
        let mut g = Graph::new();
        let [s, x] = ["x*x + 3*x*y", "x"].map(|t| g.parse(t).unwrap());
        let held = g.hold(s).unwrap();
        let k = g.mul(held, x).unwrap();
        let (sx, kx) = (g.symbol_named("x").unwrap(), g.mul(s, x).unwrap());
        // The derivative is the unheld one's: (x² + 3xy)·x → 3x² + 6xy.
        let (dk, expected) = (g.diff(k, sx).unwrap(), g.diff(kx, sx).unwrap());
        let at = [("x", 0.7), ("y", -1.3)];
        let (a, b) = (
            g.eval_named(dk, &at).unwrap(),
            g.eval_named(expected, &at).unwrap(),
        );
        assert!((a - b).abs() < 1e-15, "{a} vs {b}");
        assert_eq!(d("x*y", "x"), "y");
    }

    #[test]
    fn hyperbolic_and_inverse_functions() {
        same("sinh(x)", "x", "cosh(x)");
        same("cosh(2*x)", "x", "2*sinh(2*x)");
        same("tanh(x)", "x", "1 - tanh(x)^2");
        same("asin(x)", "x", "1/sqrt(1 - x^2)");
        same("acos(x)", "x", "-1/sqrt(1 - x^2)");
        same("atan(x)", "x", "1/(1 + x^2)");
    }
    #[test]
    fn real_powers() {
        // d x^a = a x^a / x; d a^x = a^x ln a.
        same("powf(x, a)", "x", "a*powf(x, a)/x");
        same("powf(a, x)", "x", "powf(a, x)*ln(a)");
        same("powf(x, x)", "x", "powf(x, x)*(ln(x) + 1)");
    }
    #[test]
    fn piecewise_functions_are_differentiated_piecewise() {
        same("sign(x)", "x", "0");
        same("y*sign(x)", "x", "0");
        same("select(x - y, x^2, 3*x)", "x", "select(x - y, 2*x, 3)");
        // min(a, b) = select(b − a, a, b)
        same("min(x^2, y)", "x", "select(y - x^2, 2*x, 0)");
        same("max(x, 2*x)", "x", "select(-x, 1, 2)");
    }
    #[test]
    fn power_rule() {
        same("x^5", "x", "5*x^4");
    }
    #[test]
    fn negative_power() {
        same("1/x^2", "x", "-2/x^3");
    }
    #[test]
    fn product_rule() {
        same("x*sin(x)", "x", "sin(x) + x*cos(x)");
    }
    #[test]
    fn chain_sin() {
        same("sin(2*x)", "x", "2*cos(2*x)");
    }
    #[test]
    fn chain_cos() {
        same("cos(x^2)", "x", "-2*x*sin(x^2)");
    }
    #[test]
    fn tan_rule() {
        same("tan(x)", "x", "1 + tan(x)^2");
    }
    #[test]
    fn exp_rule() {
        same("exp(3*x)", "x", "3*exp(3*x)");
    }
    #[test]
    fn ln_rule() {
        same("ln(x^2 + 1)", "x", "2*x/(x^2 + 1)");
    }
    #[test]
    fn sqrt_rule() {
        same("sqrt(x)", "x", "1/2/sqrt(x)");
    }
    #[test]
    fn abs_rule() {
        same("abs(x)", "x", "x/abs(x)");
    }
    #[test]
    fn atan2_rule_in_x() {
        same("atan2(y, x)", "x", "-y/(x^2 + y^2)");
    }
    #[test]
    fn constant_in_other_symbol() {
        assert_eq!(d("sin(y)*y + 0*x", "x"), "0");
    }
    #[test]
    fn memo_returns_same_node() {
        let mut g = Graph::new();
        let e = g.parse("sin(x)^3").unwrap();
        let x = g.symbol_named("x").unwrap();
        assert_eq!(g.diff(e, x).unwrap(), g.diff(e, x).unwrap());
    }
    #[test]
    fn time_derivative_of_coordinate_chain() {
        let mut g = Graph::new();
        g.coordinate("q").unwrap();
        g.parameter("l").unwrap();
        let e = g.parse("l*q_dot*cos(q)").unwrap();
        let de = g.time_derivative(e, &RateRules::coordinates()).unwrap();
        let expected = g.parse("l*q_ddot*cos(q) - l*q_dot^2*sin(q)").unwrap();
        assert_eq!(de, expected);
    }
    #[test]
    fn time_derivative_of_time() {
        let mut g = Graph::new();
        g.time().unwrap();
        let e = g.parse("t^2").unwrap();
        let de = g.time_derivative(e, &RateRules::coordinates()).unwrap();
        assert_eq!(g.display(de).to_string(), "2*t");
    }
    #[test]
    fn time_derivative_without_rule_is_an_error() {
        let mut g = Graph::new();
        g.input("tau").unwrap();
        let e = g.parse("tau^2").unwrap();
        let err = g.time_derivative(e, &RateRules::coordinates()).unwrap_err();
        assert_eq!(
            err.to_string(),
            "the time derivative needs the rate of `tau`, and no rule gives it"
        );
    }
    #[test]
    fn constant_rule_silences_an_input() {
        let mut g = Graph::new();
        let tau = g.input("tau").unwrap();
        let e = g.parse("tau^2").unwrap();
        let de = g
            .time_derivative(e, &RateRules::coordinates().constant(tau))
            .unwrap();
        assert!(g.is_zero(de));
    }
}
