//! Canonicalizing constructors: the only way nodes enter the graph.
//!
//! Simplification happens on construction and is local and bounded:
//!
//! | rule | example |
//! | --- | --- |
//! | flatten sums and products | `(x + y) + z → x + y + z` |
//! | collect like terms (rational coefficients) | `x + 2x → 3x` |
//! | collect like factors (summed integer exponents) | `x·x³/x → x³` |
//! | fold constants exactly | `1/2 + 1/3 → 5/6` |
//! | identities | `x + 0 → x`, `x·1 → x`, `x·0 → 0`, `x⁰ → 1` |
//! | distribute a coefficient over a sum | `2(x + y) → 2x + 2y` |
//! | except over a held sum | `2·hold(x + y)` stays a product |
//! | sums as factors are primitive, leading term positive | `(4y − 2x)/z → −2(x − 2y)/z` |
//! | square roots and absolute values of powers | `√x² → x` (as `√x·√x`), `|x|² → x²` |
//! | parity | `sin(−x) → −sin x`, `cos(−x) → cos x`, `|−x| → |x|` |
//! | right angles as doubles | `cos(1.5707963267948966) → 0`, `sin(-1.5707963267948966) → -1` |
//! | inverse pairs | `exp(ln x) → x`, `ln(exp x) → x` |
//! | Pythagoras inside a sum | `c·R·sin²x + c·R·cos²x → c·R`, `c·R − c·R·sin²x → c·R·cos²x` |
//!
//! Sums and products are sorted by node id, so the result depends only on the
//! multiset of operands and the (deterministic) order in which nodes were first
//! built; no hash-map iteration order reaches a node.

use std::collections::BTreeMap;

use crate::error::{Result, SymbolicError};
use crate::graph::{Func, Graph, Id, Node, Symbol};
use crate::number::Number;

/// k mod 4 when `x` is the double nearest to kπ/2 (0 < |k| ≤ 8): such an
/// angle stands for the right angle it rounds (a URDF's
/// `1.5707963267948966`), so its sine and cosine fold to the exact 0 and
/// ±1. The float values differ from them by less than half an ulp of 1
/// (cos(fl(π/2)) = 6.1e-17), below the rounding of a direction cosine, and
/// an exact zero keeps a rotation by a right angle a permutation instead of
/// filling every entry of the frames below it with tiny products.
fn quarter_turns(x: f64) -> Option<usize> {
    let k = (x / std::f64::consts::FRAC_PI_2).round();
    if k == 0.0 || k.abs() > 8.0 {
        return None;
    }
    let nearest = k * std::f64::consts::FRAC_PI_2;
    ((nearest - x).abs() <= f64::EPSILON * x.abs()).then(|| (k as i64).rem_euclid(4) as usize)
}

/// What a coefficient-1 product of factors canonically is.
enum UnitProduct {
    One,
    Base(Id),
    Node(Node),
}

impl Graph {
    // ----- leaves ---------------------------------------------------------

    /// A constant.
    pub fn num(&mut self, n: Number) -> Result<Id> {
        self.intern(Node::Num(n))
    }

    /// An exact integer.
    pub fn int(&mut self, n: i64) -> Result<Id> {
        self.num(Number::int(n))
    }

    /// The exact fraction `num / den`.
    ///
    /// ```
    /// use appell_symbolic::Graph;
    /// let mut g = Graph::new();
    /// let a = g.rational(2, 4).unwrap();
    /// let b = g.rational(1, 2).unwrap();
    /// assert_eq!(a, b);
    /// assert!(g.rational(1, 0).is_err());
    /// ```
    pub fn rational(&mut self, num: i64, den: i64) -> Result<Id> {
        let n = Number::ratio(num as i128, den as i128).ok_or_else(|| {
            SymbolicError::DivisionByZero {
                expr: num.to_string(),
            }
        })?;
        self.num(n)
    }

    /// A float constant; NaN and infinities are rejected.
    pub fn float(&mut self, x: f64) -> Result<Id> {
        let n = Number::try_float(x).ok_or(SymbolicError::NonFiniteConstant)?;
        self.num(n)
    }

    /// The expression made of one symbol.
    pub fn sym(&mut self, s: Symbol) -> Result<Id> {
        self.intern(Node::Sym(s))
    }

    // ----- sums -------------------------------------------------------------

    /// `a + b`.
    pub fn add(&mut self, a: Id, b: Id) -> Result<Id> {
        self.linear_combination(Number::ZERO, [(a, Number::ONE), (b, Number::ONE)])
    }

    /// `a - b`.
    pub fn sub(&mut self, a: Id, b: Id) -> Result<Id> {
        self.linear_combination(Number::ZERO, [(a, Number::ONE), (b, Number::MINUS_ONE)])
    }

    /// `-a`.
    pub fn neg(&mut self, a: Id) -> Result<Id> {
        self.scale(a, Number::MINUS_ONE)
    }

    /// `k · a` for a constant `k`.
    pub fn scale(&mut self, a: Id, k: Number) -> Result<Id> {
        self.linear_combination(Number::ZERO, [(a, k)])
    }

    /// The sum of all `terms` (0 when empty).
    ///
    /// ```
    /// use appell_symbolic::Graph;
    /// let mut g = Graph::new();
    /// let parts = ["x", "2*y", "-x", "y"].map(|s| g.parse(s).unwrap());
    /// let s = g.sum(&parts).unwrap();
    /// assert_eq!(g.display(s).to_string(), "3*y");
    /// ```
    pub fn sum(&mut self, terms: &[Id]) -> Result<Id> {
        self.linear_combination(Number::ZERO, terms.iter().map(|&t| (t, Number::ONE)))
    }

    /// `constant + Σ k · e` over `parts`, in canonical form.
    pub fn linear_combination(
        &mut self,
        constant: Number,
        parts: impl IntoIterator<Item = (Id, Number)>,
    ) -> Result<Id> {
        let mut acc = BTreeMap::new();
        let mut c = constant;
        for (id, k) in parts {
            self.push_term(&mut acc, &mut c, id, k)?;
        }
        self.finish_sum(acc, c)
    }

    fn push_term(
        &mut self,
        acc: &mut BTreeMap<Id, Number>,
        constant: &mut Number,
        id: Id,
        k: Number,
    ) -> Result<()> {
        if k.is_zero() {
            return Ok(());
        }
        match self.node(id) {
            Node::Num(n) => *constant = constant.add(k.mul(*n)),
            Node::Add {
                constant: c0,
                terms,
            } => {
                *constant = constant.add(k.mul(*c0));
                for &(b, kk) in terms.iter() {
                    add_coefficient(acc, b, k.mul(kk));
                }
            }
            Node::Mul { coeff, factors } if !coeff.is_one() => {
                let coeff = *coeff;
                let factors: Vec<(Id, i64)> = factors.iter().map(|&(b, e)| (b, e as i64)).collect();
                let base = self.unit_product(factors)?;
                if let Some(n) = self.as_number(base) {
                    *constant = constant.add(k.mul(coeff).mul(n));
                } else {
                    add_coefficient(acc, base, k.mul(coeff));
                }
            }
            _ => add_coefficient(acc, id, k),
        }
        if acc.len() > self.limits.max_terms {
            return Err(SymbolicError::TermLimit {
                limit: self.limits.max_terms,
            });
        }
        Ok(())
    }

    fn finish_sum(&mut self, mut acc: BTreeMap<Id, Number>, mut constant: Number) -> Result<Id> {
        acc.retain(|_, k| !k.is_zero());
        self.collapse_pythagoras(&mut acc, &mut constant)?;
        acc.retain(|_, k| !k.is_zero());
        if acc.is_empty() {
            return self.num(constant);
        }
        if acc.len() == 1 && constant.is_zero() {
            let (&b, &k) = acc.iter().next().expect("one term");
            return self.scaled_base(b, k);
        }
        let terms: Box<[(Id, Number)]> = acc.into_iter().collect();
        self.intern(Node::Add { constant, terms })
    }

    /// `k · b` where `b` is a valid term base (not a number, sum, or product
    /// with a coefficient).
    fn scaled_base(&mut self, b: Id, k: Number) -> Result<Id> {
        if k.is_one() {
            return Ok(b);
        }
        let factors: Box<[(Id, i32)]> = match self.node(b) {
            Node::Mul { factors, .. } => factors.clone(),
            _ => Box::new([(b, 1)]),
        };
        self.intern(Node::Mul { coeff: k, factors })
    }

    /// The factors of a term base (a coefficient-1 product or a single base).
    fn unit_factors(&self, b: Id) -> Vec<(Id, i64)> {
        match self.node(b) {
            Node::Mul { coeff, factors } if coeff.is_one() => {
                factors.iter().map(|&(f, e)| (f, e as i64)).collect()
            }
            _ => vec![(b, 1)],
        }
    }

    /// The canonical form of a coefficient-1 product of already canonical,
    /// sorted-or-not factors whose bases are neither numbers nor products and
    /// that trigger no further reduction.
    fn unit_product_shape(&self, factors: Vec<(Id, i64)>) -> Result<UnitProduct> {
        let mut map: BTreeMap<Id, i64> = BTreeMap::new();
        for (b, e) in factors {
            let x = map.entry(b).or_insert(0);
            *x = x.checked_add(e).ok_or(SymbolicError::ExponentOverflow)?;
        }
        map.retain(|_, e| *e != 0);
        if map.is_empty() {
            return Ok(UnitProduct::One);
        }
        if map.len() == 1 {
            let (&b, &e) = map.iter().next().expect("one factor");
            if e == 1 {
                return Ok(UnitProduct::Base(b));
            }
        }
        let factors = map
            .into_iter()
            .map(|(b, e)| {
                Ok((
                    b,
                    i32::try_from(e).map_err(|_| SymbolicError::ExponentOverflow)?,
                ))
            })
            .collect::<Result<Box<[_]>>>()?;
        Ok(UnitProduct::Node(Node::Mul {
            coeff: Number::ONE,
            factors,
        }))
    }

    fn unit_product(&mut self, factors: Vec<(Id, i64)>) -> Result<Id> {
        match self.unit_product_shape(factors)? {
            UnitProduct::One => self.num(Number::ONE),
            UnitProduct::Base(b) => Ok(b),
            UnitProduct::Node(n) => self.intern(n),
        }
    }

    fn lookup_unit_product(&self, factors: Vec<(Id, i64)>) -> Result<Option<Id>> {
        Ok(match self.unit_product_shape(factors)? {
            UnitProduct::One => self.lookup(&Node::Num(Number::ONE)),
            UnitProduct::Base(b) => Some(b),
            UnitProduct::Node(n) => self.lookup(&n),
        })
    }

    /// `sin² + cos² = 1` in all the shapes it takes inside one sum, until no
    /// pair matches or the pass limit stops it.
    fn collapse_pythagoras(
        &mut self,
        acc: &mut BTreeMap<Id, Number>,
        constant: &mut Number,
    ) -> Result<()> {
        if acc.len() + usize::from(!constant.is_zero()) < 2 {
            return Ok(());
        }
        let mut passes = 0;
        'pass: loop {
            if passes >= self.limits.max_rewrite_passes {
                self.stats.rewrite_limit_stops += 1;
                return Ok(());
            }
            passes += 1;
            let snapshot: Vec<(Id, Number)> = acc.iter().map(|(b, k)| (*b, *k)).collect();
            for (b, k) in snapshot {
                let factors = self.unit_factors(b);
                for (i, &(f, e)) in factors.iter().enumerate() {
                    if e < 2 {
                        continue;
                    }
                    let (func, x) = match self.node(f) {
                        Node::Fun(func @ (Func::Sin | Func::Cos), x) => (*func, *x),
                        _ => continue,
                    };
                    let other_func = if func == Func::Sin {
                        Func::Cos
                    } else {
                        Func::Sin
                    };
                    let other = self.lookup(&Node::Fun(other_func, x));
                    let mut rest = factors.clone();
                    rest[i].1 -= 2;
                    // Rule A: k·R·f² + k·R·g² → k·R.
                    if let Some(other) = other {
                        let mut with_other = rest.clone();
                        with_other.push((other, 2));
                        if let Some(partner) = self.lookup_unit_product(with_other)? {
                            if partner != b && acc.get(&partner) == Some(&k) {
                                acc.remove(&b);
                                acc.remove(&partner);
                                let r = self.unit_product(rest)?;
                                self.push_term(acc, constant, r, k)?;
                                self.stats.trig_collapses += 1;
                                continue 'pass;
                            }
                        }
                    }
                    // Rule B: −k·R + k·R·f² → −k·R·g².
                    let minus_k = k.neg();
                    let r = self.lookup_unit_product(rest.clone())?;
                    let matched = match r {
                        Some(r) => match self.as_number(r) {
                            Some(n) => constant.mul(n.recip().unwrap_or(Number::ZERO)) == minus_k,
                            None => acc.get(&r) == Some(&minus_k),
                        },
                        None => false,
                    };
                    if matched {
                        let r = r.expect("matched");
                        acc.remove(&b);
                        match self.as_number(r) {
                            Some(_) => *constant = Number::ZERO,
                            None => {
                                acc.remove(&r);
                            }
                        }
                        let other = self.func(other_func, x)?;
                        let mut with_other = rest;
                        with_other.push((other, 2));
                        let t = self.unit_product(with_other)?;
                        self.push_term(acc, constant, t, minus_k)?;
                        self.stats.trig_collapses += 1;
                        continue 'pass;
                    }
                }
            }
            return Ok(());
        }
    }

    // ----- products --------------------------------------------------------

    /// `a · b`.
    pub fn mul(&mut self, a: Id, b: Id) -> Result<Id> {
        self.power_product(Number::ONE, [(a, 1), (b, 1)])
    }

    /// The product of all `factors` (1 when empty).
    pub fn product(&mut self, factors: &[Id]) -> Result<Id> {
        self.power_product(Number::ONE, factors.iter().map(|&f| (f, 1)))
    }

    /// `a / b`; an error when `b` is identically zero.
    ///
    /// ```
    /// use appell_symbolic::Graph;
    /// let mut g = Graph::new();
    /// let e = g.parse("x^3").unwrap();
    /// let x = g.parse("x").unwrap();
    /// let q = g.div(e, x).unwrap();
    /// assert_eq!(g.display(q).to_string(), "x^2");
    /// ```
    pub fn div(&mut self, a: Id, b: Id) -> Result<Id> {
        if self.is_zero(b) {
            return Err(SymbolicError::DivisionByZero {
                expr: self.display(a).to_string(),
            });
        }
        self.power_product(Number::ONE, [(a, 1), (b, -1)])
    }

    /// `1 / a`.
    pub fn recip(&mut self, a: Id) -> Result<Id> {
        self.powi(a, -1)
    }

    /// `a ^ n` for an integer `n` (negative powers divide; `0⁻¹` is an error).
    pub fn powi(&mut self, a: Id, n: i64) -> Result<Id> {
        self.power_product(Number::ONE, [(a, n)])
    }

    /// `coeff · Π base ^ exponent`, in canonical form.
    pub fn power_product(
        &mut self,
        coeff: Number,
        parts: impl IntoIterator<Item = (Id, i64)>,
    ) -> Result<Id> {
        let mut acc: BTreeMap<Id, i64> = BTreeMap::new();
        let mut c = coeff;
        for (id, e) in parts {
            self.push_factor(&mut acc, &mut c, id, e)?;
        }
        // √x^e → x^(e div 2)·√x^(e mod 2); |x|^(2k) → x^(2k). Repeat, since the
        // radicand may itself be a root or a product.
        loop {
            let mut changed = false;
            let snapshot: Vec<(Id, i64)> = acc.iter().map(|(b, e)| (*b, *e)).collect();
            for (b, e) in snapshot {
                match *self.node(b) {
                    Node::Fun(Func::Sqrt, x) if e.abs() >= 2 => {
                        acc.insert(b, e % 2);
                        self.push_factor(&mut acc, &mut c, x, e / 2)?;
                        changed = true;
                    }
                    Node::Fun(Func::Abs, x) if e % 2 == 0 && e != 0 => {
                        acc.insert(b, 0);
                        self.push_factor(&mut acc, &mut c, x, e)?;
                        changed = true;
                    }
                    _ => {}
                }
            }
            acc.retain(|_, e| *e != 0);
            if !changed {
                break;
            }
        }
        // Sums as factors are primitive and lead with a positive term:
        // (4y − 2x)·r → −2·(x − 2y)·r, so every spelling of a product meets
        // in one node. (Sums with float coefficients keep their scale.)
        let mut normalize = Vec::new();
        for (&b, &e) in acc.iter() {
            if let Node::Add { constant, terms } = self.node(b) {
                let mut coeffs: Vec<Number> = terms.iter().map(|t| t.1).collect();
                coeffs.push(*constant);
                let content = Number::content(&coeffs).unwrap_or(Number::ONE);
                let k = if terms[0].1.is_negative() {
                    content.neg()
                } else {
                    content
                };
                if k != Number::ONE {
                    normalize.push((b, e, k));
                }
            }
        }
        for (b, e, k) in normalize {
            acc.remove(&b);
            let inv = k.recip().expect("content is non-zero");
            let nb = self.scale(b, inv)?;
            let x = acc.entry(nb).or_insert(0);
            *x = x.checked_add(e).ok_or(SymbolicError::ExponentOverflow)?;
            c = c.mul(k.powi(e).ok_or(SymbolicError::ExponentOverflow)?);
        }
        acc.retain(|_, e| *e != 0);
        if c.is_zero() {
            return self.num(Number::ZERO);
        }
        if acc.is_empty() {
            return self.num(c);
        }
        if acc.len() == 1 {
            let (&b, &e) = acc.iter().next().expect("one factor");
            if e == 1 {
                if c.is_one() {
                    return Ok(b);
                }
                if matches!(self.node(b), Node::Add { .. }) {
                    return self.linear_combination(Number::ZERO, [(b, c)]);
                }
            }
        }
        let factors = acc
            .into_iter()
            .map(|(b, e)| {
                Ok((
                    b,
                    i32::try_from(e).map_err(|_| SymbolicError::ExponentOverflow)?,
                ))
            })
            .collect::<Result<Box<[_]>>>()?;
        self.intern(Node::Mul { coeff: c, factors })
    }

    fn push_factor(
        &mut self,
        acc: &mut BTreeMap<Id, i64>,
        coeff: &mut Number,
        id: Id,
        e: i64,
    ) -> Result<()> {
        if e == 0 {
            return Ok(());
        }
        match self.node(id) {
            Node::Num(n) => {
                let p = n.powi(e).ok_or_else(|| SymbolicError::DivisionByZero {
                    expr: "1".to_string(),
                })?;
                *coeff = coeff.mul(p);
            }
            Node::Mul { coeff: k, factors } => {
                let p = k.powi(e).ok_or(SymbolicError::ExponentOverflow)?;
                *coeff = coeff.mul(p);
                for &(b, fe) in factors.iter() {
                    let x = acc.entry(b).or_insert(0);
                    let add = (fe as i64)
                        .checked_mul(e)
                        .ok_or(SymbolicError::ExponentOverflow)?;
                    *x = x.checked_add(add).ok_or(SymbolicError::ExponentOverflow)?;
                }
            }
            _ => {
                let x = acc.entry(id).or_insert(0);
                *x = x.checked_add(e).ok_or(SymbolicError::ExponentOverflow)?;
            }
        }
        Ok(())
    }

    // ----- sign -------------------------------------------------------------

    /// When `a` reads as a negated expression (a negative constant, a product
    /// with a negative coefficient, a sum whose first term is negative),
    /// returns `-a`. Used by the parity rules so `sin(y - x)` and
    /// `-sin(x - y)` meet in one node.
    pub fn negated(&mut self, a: Id) -> Result<Option<Id>> {
        let negative = match self.node(a) {
            Node::Num(n) => n.is_negative(),
            Node::Mul { coeff, .. } => coeff.is_negative(),
            Node::Add { terms, .. } => terms[0].1.is_negative(),
            _ => false,
        };
        if negative {
            Ok(Some(self.neg(a)?))
        } else {
            Ok(None)
        }
    }

    // ----- functions --------------------------------------------------------

    /// `f(a)` for a unary function, simplified by its rules.
    pub fn func(&mut self, f: Func, a: Id) -> Result<Id> {
        if let Some(n) = self.as_number(a) {
            if let Some(v) = self.fold(f, n)? {
                return Ok(v);
            }
        }
        match f {
            Func::Sin | Func::Tan | Func::Sinh | Func::Tanh | Func::Asin | Func::Atan => {
                if let Some(p) = self.negated(a)? {
                    let inner = self.func(f, p)?;
                    return self.neg(inner);
                }
            }
            Func::Cos | Func::Cosh => {
                if let Some(p) = self.negated(a)? {
                    return self.func(f, p);
                }
            }
            Func::Acos => {}
            // Only a sum is held: anything else is already one factor.
            Func::Hold => {
                if !matches!(self.node(a), Node::Add { .. }) {
                    return Ok(a);
                }
            }
            Func::Sign => {
                if let Some(p) = self.negated(a)? {
                    let inner = self.func(f, p)?;
                    return self.neg(inner);
                }
                if let Node::Fun(Func::Sign, _) = self.node(a) {
                    return Ok(a);
                }
                match self.sign(a, &crate::Assumptions::new()) {
                    crate::Sign::Positive => return self.int(1),
                    crate::Sign::Negative => return self.int(-1),
                    _ => {}
                }
            }
            Func::Abs => {
                if let Some(p) = self.negated(a)? {
                    return self.func(f, p);
                }
                match self.node(a) {
                    Node::Fun(Func::Abs | Func::Exp | Func::Sqrt, _) => return Ok(a),
                    Node::Mul { coeff, factors }
                        if !coeff.is_negative() && factors.iter().all(|(_, e)| e % 2 == 0) =>
                    {
                        return Ok(a)
                    }
                    _ => {}
                }
            }
            Func::Exp => {
                if let Node::Fun(Func::Ln, x) = *self.node(a) {
                    return Ok(x);
                }
            }
            Func::Ln => {
                if let Node::Fun(Func::Exp, x) = *self.node(a) {
                    return Ok(x);
                }
            }
            Func::Sqrt => {
                if let Node::Mul { coeff, factors } = self.node(a) {
                    if let Some(root) = coeff.exact_sqrt() {
                        if factors.iter().all(|(_, e)| e % 2 == 0) {
                            let factors: Vec<(Id, i32)> = factors.to_vec();
                            let mut parts = Vec::with_capacity(factors.len());
                            for (b, e) in factors {
                                parts.push((self.func(Func::Abs, b)?, (e / 2) as i64));
                            }
                            return self.power_product(root, parts);
                        }
                    }
                }
            }
        }
        self.intern(Node::Fun(f, a))
    }

    /// Constant folding of functions: exact special values, floats evaluated.
    fn fold(&mut self, f: Func, n: Number) -> Result<Option<Id>> {
        let exact = match f {
            Func::Sin | Func::Tan if n.is_zero() => Some(Number::ZERO),
            Func::Sin | Func::Cos if n.is_float() => quarter_turns(n.to_f64()).map(|k| {
                // sin(kπ/2) and cos(kπ/2) for k mod 4 = 0, 1, 2, 3.
                let sin = [0, 1, 0, -1][k];
                Number::int(if f == Func::Sin {
                    sin
                } else {
                    [1, 0, -1, 0][k]
                })
            }),
            Func::Cos | Func::Exp if n.is_zero() => Some(Number::ONE),
            Func::Ln if n.is_one() && !n.is_float() => Some(Number::ZERO),
            Func::Abs => Some(n.abs()),
            Func::Sqrt => n.exact_sqrt(),
            Func::Sinh | Func::Tanh | Func::Asin | Func::Atan if n.is_zero() => Some(Number::ZERO),
            Func::Cosh if n.is_zero() => Some(Number::ONE),
            Func::Acos if n.is_one() && !n.is_float() => Some(Number::ZERO),
            Func::Sign if n.is_zero() => Some(Number::ZERO),
            Func::Sign => Some(Number::int(if n.is_negative() { -1 } else { 1 })),
            Func::Hold => Some(n),
            _ => None,
        };
        if let Some(v) = exact {
            return self.num(v).map(Some);
        }
        if matches!(f, Func::Ln | Func::Sqrt) && (n.is_negative() || (f == Func::Ln && n.is_zero()))
        {
            return Err(SymbolicError::NonFiniteConstant);
        }
        if matches!(f, Func::Asin | Func::Acos) && n.to_f64().abs() > 1.0 {
            return Err(SymbolicError::NonFiniteConstant);
        }
        if n.is_float() {
            return self.float(f.apply(n.to_f64())).map(Some);
        }
        Ok(None)
    }

    /// `sin(a)`.
    pub fn sin(&mut self, a: Id) -> Result<Id> {
        self.func(Func::Sin, a)
    }
    /// `cos(a)`.
    pub fn cos(&mut self, a: Id) -> Result<Id> {
        self.func(Func::Cos, a)
    }
    /// `tan(a)`.
    pub fn tan(&mut self, a: Id) -> Result<Id> {
        self.func(Func::Tan, a)
    }
    /// `exp(a)`.
    pub fn exp(&mut self, a: Id) -> Result<Id> {
        self.func(Func::Exp, a)
    }
    /// `ln(a)`.
    pub fn ln(&mut self, a: Id) -> Result<Id> {
        self.func(Func::Ln, a)
    }
    /// `|a|`.
    pub fn abs(&mut self, a: Id) -> Result<Id> {
        self.func(Func::Abs, a)
    }
    /// `√a`.
    pub fn sqrt(&mut self, a: Id) -> Result<Id> {
        self.func(Func::Sqrt, a)
    }

    /// `sinh(a)`.
    pub fn sinh(&mut self, a: Id) -> Result<Id> {
        self.func(Func::Sinh, a)
    }
    /// `cosh(a)`.
    pub fn cosh(&mut self, a: Id) -> Result<Id> {
        self.func(Func::Cosh, a)
    }
    /// `tanh(a)`.
    pub fn tanh(&mut self, a: Id) -> Result<Id> {
        self.func(Func::Tanh, a)
    }
    /// `asin(a)`.
    pub fn asin(&mut self, a: Id) -> Result<Id> {
        self.func(Func::Asin, a)
    }
    /// `acos(a)`.
    pub fn acos(&mut self, a: Id) -> Result<Id> {
        self.func(Func::Acos, a)
    }
    /// `atan(a)`.
    pub fn atan(&mut self, a: Id) -> Result<Id> {
        self.func(Func::Atan, a)
    }
    /// `a`, held as one factor where it is a sum ([`Func::Hold`]): `k ·
    /// hold(x + y)` stays a product of two factors where `k · (x + y)`
    /// becomes `k x + k y`.
    ///
    /// ```
    /// use appell_symbolic::Graph;
    /// let mut g = Graph::new();
    /// let [x, sum, three] = ["x", "x + y", "3"].map(|s| g.parse(s).unwrap());
    /// let held = g.hold(sum).unwrap();
    /// let product = g.mul(three, held).unwrap();
    /// assert_eq!(g.display(product).to_string(), "3*(x + y)");
    /// let spread = g.mul(three, sum).unwrap();
    /// assert_eq!(g.display(spread).to_string(), "3*x + 3*y");
    /// assert_eq!(g.hold(x).unwrap(), x);
    /// let at = [("x", 1.0), ("y", 2.0)];
    /// assert_eq!(g.eval_named(product, &at).unwrap(), 9.0);
    /// ```
    pub fn hold(&mut self, a: Id) -> Result<Id> {
        self.func(Func::Hold, a)
    }

    /// `sign(a)`: 1, −1, or 0 at zero ([`Func::Sign`]).
    pub fn signum(&mut self, a: Id) -> Result<Id> {
        self.func(Func::Sign, a)
    }

    /// `powf(x, y)`, `x` to the power `y`. An integer exponent (exact, or a
    /// float with an integral value up to 64 in magnitude) is [`Graph::powi`],
    /// an exponent of one half [`Graph::sqrt`]; constants fold.
    ///
    /// ```
    /// use appell_symbolic::Graph;
    /// let mut g = Graph::new();
    /// let e = g.parse("powf(x, 2.0) - x^2 + powf(y, 0.5) - sqrt(y)").unwrap();
    /// assert!(g.is_zero(e));
    /// let p = g.parse("powf(x, a)").unwrap();
    /// assert_eq!(g.display(p).to_string(), "powf(x, a)");
    /// ```
    pub fn powf(&mut self, x: Id, y: Id) -> Result<Id> {
        if let Some(n) = self.as_number(y) {
            let v = n.to_f64();
            let integral = match n.as_integer() {
                Some(k) => k.abs() <= i32::MAX as i128,
                None => n.is_float() && v.fract() == 0.0 && v.abs() <= 64.0,
            };
            if integral {
                return self.powi(x, v as i64);
            }
            if v == 0.5 {
                return self.sqrt(x);
            }
            if let Some(m) = self.as_number(x) {
                let r = m.to_f64().powf(v);
                if !r.is_finite() {
                    return Err(SymbolicError::NonFiniteConstant);
                }
                return self.float(r);
            }
        }
        if let Some(m) = self.as_number(x) {
            if m.is_one() {
                return self.int(1);
            }
        }
        self.intern(Node::Powf(x, y))
    }

    /// `select(c, a, b)`: `a` where `c > 0`, else `b`. Collapses when both
    /// branches are equal or the sign of `c` is known.
    ///
    /// ```
    /// use appell_symbolic::Graph;
    /// let mut g = Graph::new();
    /// let e = g.parse("select(x, y, y)").unwrap();
    /// let y = g.parse("y").unwrap();
    /// assert_eq!(e, y);
    /// let two = g.parse("select(2, a, b)").unwrap();
    /// assert_eq!(g.display(two).to_string(), "a");
    /// ```
    pub fn select(&mut self, c: Id, a: Id, b: Id) -> Result<Id> {
        if a == b {
            return Ok(a);
        }
        match self.sign(c, &crate::Assumptions::new()) {
            crate::Sign::Positive => return Ok(a),
            crate::Sign::Negative => return Ok(b),
            _ if self.is_zero(c) => return Ok(b),
            _ => {}
        }
        // select(c, select(c, a, _), b) = select(c, a, b), and the same
        // in the other branch.
        let a = match *self.node(a) {
            Node::Select(c2, inner, _) if c2 == c => inner,
            _ => a,
        };
        let b = match *self.node(b) {
            Node::Select(c2, _, inner) if c2 == c => inner,
            _ => b,
        };
        if a == b {
            return Ok(a);
        }
        self.intern(Node::Select(c, a, b))
    }

    /// `min(a, b)`, as `select(b − a, a, b)`.
    pub fn min(&mut self, a: Id, b: Id) -> Result<Id> {
        let c = self.sub(b, a)?;
        self.select(c, a, b)
    }

    /// `max(a, b)`, as `select(a − b, a, b)`.
    pub fn max(&mut self, a: Id, b: Id) -> Result<Id> {
        let c = self.sub(a, b)?;
        self.select(c, a, b)
    }

    /// `atan2(y, x)`, the angle of the point `(x, y)`.
    pub fn atan2(&mut self, y: Id, x: Id) -> Result<Id> {
        if self.is_zero(y) && self.sign(x, &crate::Assumptions::new()) == crate::Sign::Positive {
            return self.num(Number::ZERO);
        }
        if let (Some(ny), Some(nx)) = (self.as_number(y), self.as_number(x)) {
            if ny.is_zero() && !nx.is_negative() && !nx.is_zero() {
                return self.num(Number::ZERO);
            }
            if ny.is_float() || nx.is_float() {
                return self.float(ny.to_f64().atan2(nx.to_f64()));
            }
        }
        self.intern(Node::Atan2(y, x))
    }
}

fn add_coefficient(acc: &mut BTreeMap<Id, Number>, b: Id, k: Number) {
    let entry = acc.entry(b).or_insert(Number::ZERO);
    *entry = entry.add(k);
}
