//! Emission: from expression roots to straight-line Rust over a generic scalar.
//!
//! Two steps. [`Program::lower`] turns the canonical n-ary graph into binary
//! instructions (`+ − × ÷`, negation, integer powers by repeated squaring,
//! function calls), hash-consed again so that e.g. `x²` is computed once for
//! `x³` and `x⁴`. [`Program::to_rust`] then writes one `let` per instruction
//! used more than once (common-subexpression elimination is "a node used twice
//! becomes a `let`"), inlines the rest, and separates the instructions that
//! depend on parameters only, so they can be computed once per parameter set.
//!
//! The output is deterministic: names, order and text depend only on the
//! graph, never on hash-map iteration.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::{self, Write};

use crate::error::Result;
use crate::graph::{Func, FxHashMap, Graph, Id, Node, Symbol, SymbolKind};
use crate::number::Number;

/// One binary instruction of a lowered program. Operands index earlier
/// instructions.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Inst {
    /// A constant.
    Const(Number),
    /// A symbol's value.
    Symbol(Symbol),
    /// `a + b`.
    Add(u32, u32),
    /// `a − b`.
    Sub(u32, u32),
    /// `a · b`.
    Mul(u32, u32),
    /// `a / b`.
    Div(u32, u32),
    /// `−a`.
    Neg(u32),
    /// `aⁿ` (only for exponents above 64; smaller ones are multiplication
    /// chains, whose IEEE result is fully specified).
    Powi(u32, i32),
    /// `f(a)`.
    Call(Func, u32),
    /// `atan2(y, x)`.
    Atan2(u32, u32),
}

impl Inst {
    /// The same instruction with each operand `x` replaced by `r(x)`.
    fn remap(self, r: impl Fn(u32) -> u32) -> Inst {
        match self {
            Inst::Add(a, b) => Inst::Add(r(a), r(b)),
            Inst::Sub(a, b) => Inst::Sub(r(a), r(b)),
            Inst::Mul(a, b) => Inst::Mul(r(a), r(b)),
            Inst::Div(a, b) => Inst::Div(r(a), r(b)),
            Inst::Atan2(a, b) => Inst::Atan2(r(a), r(b)),
            Inst::Neg(a) => Inst::Neg(r(a)),
            Inst::Powi(a, e) => Inst::Powi(r(a), e),
            Inst::Call(f, a) => Inst::Call(f, r(a)),
            leaf => leaf,
        }
    }

    fn operands(&self) -> Vec<u32> {
        match *self {
            Inst::Const(_) | Inst::Symbol(_) => vec![],
            Inst::Add(a, b) | Inst::Sub(a, b) | Inst::Mul(a, b) | Inst::Div(a, b) => vec![a, b],
            Inst::Atan2(y, x) => vec![y, x],
            Inst::Neg(a) | Inst::Powi(a, _) | Inst::Call(_, a) => vec![a],
        }
    }
}

/// Operation counts of emitted code, by kind.
///
/// ```
/// use appell_symbolic::Graph;
/// let mut g = Graph::new();
/// let e = g.parse("sin(x)^2*y + sin(x)*z - 1/y").unwrap();
/// let ops = g.op_count(&[e]).unwrap();
/// assert_eq!(ops.calls, 1); // sin(x) once
/// assert_eq!(ops.div, 1);
/// assert_eq!(ops.total(), ops.add + ops.mul + ops.div + ops.neg + ops.calls + ops.powi);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OpCount {
    /// Additions and subtractions.
    pub add: usize,
    /// Multiplications.
    pub mul: usize,
    /// Divisions.
    pub div: usize,
    /// Negations.
    pub neg: usize,
    /// Calls of `sin cos tan exp ln abs sqrt atan2`.
    pub calls: usize,
    /// `powi` calls (exponents above 64).
    pub powi: usize,
}

impl OpCount {
    /// All operations.
    pub fn total(&self) -> usize {
        self.add + self.mul + self.div + self.neg + self.calls + self.powi
    }

    fn count(&mut self, inst: &Inst, times: usize) {
        match inst {
            Inst::Const(_) | Inst::Symbol(_) => {}
            Inst::Add(..) | Inst::Sub(..) => self.add += times,
            Inst::Mul(..) => self.mul += times,
            Inst::Div(..) => self.div += times,
            Inst::Neg(_) => self.neg += times,
            Inst::Powi(..) => self.powi += times,
            Inst::Call(..) | Inst::Atan2(..) => self.calls += times,
        }
    }
}

impl std::ops::Add for OpCount {
    type Output = OpCount;
    fn add(self, o: OpCount) -> OpCount {
        OpCount {
            add: self.add + o.add,
            mul: self.mul + o.mul,
            div: self.div + o.div,
            neg: self.neg + o.neg,
            calls: self.calls + o.calls,
            powi: self.powi + o.powi,
        }
    }
}

impl fmt::Display for OpCount {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} ops ({} add, {} mul, {} div, {} neg, {} calls, {} powi)",
            self.total(),
            self.add,
            self.mul,
            self.div,
            self.neg,
            self.calls,
            self.powi
        )
    }
}

/// Deepest nesting of operations written inline in one expression.
const MAX_INLINE_DEPTH: usize = 16;

/// Exponents up to this are computed by multiplication chains.
const MAX_CHAIN_EXPONENT: i32 = 64;

/// The longest nested sum [`Lowering::flatten`] distributes.
const MAX_DISTRIBUTED: usize = 8;

/// A lowered, hash-consed straight-line program computing some roots.
#[derive(Clone, Debug)]
pub struct Program {
    insts: Vec<Inst>,
    outputs: Vec<u32>,
    parameter_only: Vec<bool>,
    uses: Vec<u32>,
}

/// A term of a sum: coefficient, factors, and a parameter-only value
/// multiplied in (the merged parameter parts of terms that shared their
/// state-dependent factors).
type Term = (Number, Vec<(Id, i32)>, Option<u32>);

struct Lowering<'g> {
    graph: &'g Graph,
    /// How many nodes (and roots) read each node.
    readers: FxHashMap<Id, u32>,
    insts: Vec<Inst>,
    index: FxHashMap<Inst, u32>,
    memo: FxHashMap<Id, u32>,
}

impl Lowering<'_> {
    fn push(&mut self, inst: Inst) -> u32 {
        let inst = match inst {
            Inst::Add(a, b) if b < a => Inst::Add(b, a),
            Inst::Mul(a, b) if b < a => Inst::Mul(b, a),
            i => i,
        };
        if let Some(&i) = self.index.get(&inst) {
            return i;
        }
        let i = self.insts.len() as u32;
        self.insts.push(inst.clone());
        self.index.insert(inst, i);
        i
    }

    fn constant(&mut self, n: Number) -> u32 {
        self.push(Inst::Const(n))
    }

    fn power(&mut self, b: u32, e: i32) -> u32 {
        debug_assert!(e >= 1);
        if e == 1 {
            b
        } else if e > MAX_CHAIN_EXPONENT {
            self.push(Inst::Powi(b, e))
        } else if e % 2 == 0 {
            let h = self.power(b, e / 2);
            self.push(Inst::Mul(h, h))
        } else {
            let h = self.power(b, e - 1);
            self.push(Inst::Mul(h, b))
        }
    }

    fn chain(&mut self, items: &[u32], op: fn(u32, u32) -> Inst) -> Option<u32> {
        let mut it = items.iter().copied();
        let first = it.next()?;
        Some(it.fold(first, |acc, x| self.push(op(acc, x))))
    }

    /// `coeff · Π bᵉ`: the coefficient and the parameter-only factors form
    /// one value (hoistable), multiplied by the rest and divided by the rest's
    /// denominator. A negative coefficient is folded into the parameter-only
    /// value when there is one, else applied as a negation.
    fn product(&mut self, coeff: Number, factors: &[(Id, i32)], extra: Option<u32>) -> u32 {
        type Factors = Vec<(Id, i32)>;
        let (params, others): (Factors, Factors) = factors
            .iter()
            .copied()
            .partition(|&(b, _)| self.graph.is_parameter_only(b));
        let fold_sign = !params.is_empty() || extra.is_some();
        let k = if fold_sign { coeff } else { coeff.abs() };
        let group = |l: &mut Self, list: &[(Id, i32)], k: Option<Number>| -> Option<u32> {
            let mut num = Vec::new();
            let mut den = Vec::new();
            if let Some(k) = k {
                if !k.is_one() || k.is_float() {
                    num.push(l.constant(k));
                }
            }
            for &(b, e) in list {
                let base = l.memo[&b];
                if e > 0 {
                    num.push(l.power(base, e));
                } else {
                    den.push(l.power(base, -e));
                }
            }
            let n = l.chain(&num, Inst::Mul);
            let d = l.chain(&den, Inst::Mul);
            match (n, d) {
                (n, None) => n,
                (Some(n), Some(d)) => Some(l.push(Inst::Div(n, d))),
                (None, Some(d)) => {
                    let one = l.constant(Number::ONE);
                    Some(l.push(Inst::Div(one, d)))
                }
            }
        };
        let mut p = group(self, &params, Some(k));
        if let Some(x) = extra {
            p = Some(match p {
                Some(p) => self.push(Inst::Mul(p, x)),
                None => x,
            });
        }
        // The rest: numerator times the parameter value, then one division.
        let mut num = Vec::new();
        let mut den = Vec::new();
        for &(b, e) in &others {
            let base = self.memo[&b];
            if e > 0 {
                num.push(self.power(base, e));
            } else {
                den.push(self.power(base, -e));
            }
        }
        let mut items = Vec::new();
        items.extend(p);
        items.extend(num);
        let n = match self.chain(&items, Inst::Mul) {
            Some(n) => n,
            None => self.constant(Number::ONE),
        };
        let v = match self.chain(&den, Inst::Mul) {
            Some(d) => self.push(Inst::Div(n, d)),
            None => n,
        };
        if coeff.is_negative() && !fold_sign {
            self.push(Inst::Neg(v))
        } else {
            v
        }
    }

    /// `constant + Σ k·Π bᵉ`, with common factors taken out greedily
    /// (`a·x + a·y + z → a·(x + y) + z`): the state-dependent factor shared by
    /// the most terms first, so each is multiplied once. Terms whose
    /// state-dependent factors are the same are one term first, their
    /// parameter-only parts summed (hoisted): `p·x·y + q·x·y → (p + q)·x·y`.
    fn sum(&mut self, constant: Number, terms: Vec<Term>) -> u32 {
        let (constant, terms) = self.flatten(constant, terms);
        let mut terms = self.collect_parameters(terms);
        if terms.len() >= 2 {
            // The factor (not parameter-only: those are hoisted anyway) that
            // the most terms contain; ties go to the smallest id.
            // Counted by lowered value: two nodes may lower to one value.
            // A parameter-only factor counts too (it is hoisted, but each
            // term still multiplies by it), after a state factor as often
            // found.
            // All (value, divides, is state) pairs, once per term, sorted:
            // runs of one pair count the terms that have it.
            let mut seen: Vec<(u32, bool, bool)> = Vec::new();
            for (_, factors, extra) in &terms {
                // A parameter factor saves a multiplication only where it
                // is the term's one parameter-only factor (else it joins
                // the others in one hoisted product anyway).
                let params = factors
                    .iter()
                    .filter(|&&(b, _)| self.graph.is_parameter_only(b))
                    .count()
                    + usize::from(extra.is_some());
                let start = seen.len();
                seen.extend(
                    factors
                        .iter()
                        .map(|&(b, e)| (self.memo[&b], e < 0, !self.graph.is_parameter_only(b)))
                        .filter(|&(_, _, state)| state || params == 1),
                );
                // The merged parameter part too, when it is the only one.
                if let (Some(x), 1) = (extra, params) {
                    seen.push((*x, false, false));
                }
                seen[start..].sort_unstable();
                let mut w = start;
                for r in start..seen.len() {
                    if r == start || seen[r] != seen[w - 1] {
                        seen[w] = seen[r];
                        w += 1;
                    }
                }
                seen.truncate(w);
            }
            seen.sort_unstable();
            let mut best: Option<((usize, bool), (u32, bool))> = None;
            let mut r = 0;
            while r < seen.len() {
                let (inst, inverse, state) = seen[r];
                let mut c = 0;
                while r < seen.len() && seen[r].0 == inst && seen[r].1 == inverse {
                    c += 1;
                    r += 1;
                }
                // Most terms first, a state factor before a parameter, then
                // the smallest value.
                if c >= 2 && best.is_none_or(|(score, _)| (c, state) > score) {
                    best = Some(((c, state), (inst, inverse)));
                }
            }
            let best = best.map(|(_, key)| key);
            if let Some((base, inverse)) = best {
                let step = if inverse { 1 } else { -1 };
                let memo = &self.memo;
                let is_f = |b: Id, e: i32| memo[&b] == base && (e < 0) == inverse;
                let (with, without): (Vec<_>, Vec<_>) =
                    terms.drain(..).partition(|(_, fs, extra)| {
                        fs.iter().any(|&(b, e)| is_f(b, e)) || (!inverse && *extra == Some(base))
                    });
                let reduced: Vec<Term> = with
                    .into_iter()
                    .map(|(k, fs, extra)| {
                        // One power of the factor comes out (of the first
                        // node that lowers to it).
                        let mut done = false;
                        let fs = fs
                            .into_iter()
                            .filter_map(|(b, e)| {
                                if done || !is_f(b, e) {
                                    return Some((b, e));
                                }
                                done = true;
                                match e + step {
                                    0 => None,
                                    r => Some((b, r)),
                                }
                            })
                            .collect::<Vec<_>>();
                        // Else it is the merged parameter part.
                        let extra = if done { extra } else { None };
                        (k, fs, extra)
                    })
                    .collect();
                let inner = self.sum(Number::ZERO, reduced);
                let grouped = if inverse {
                    self.push(Inst::Div(inner, base))
                } else {
                    self.push(Inst::Mul(inner, base))
                };
                if without.is_empty() && constant.is_zero() {
                    return grouped;
                }
                let rest = self.sum(constant, without);
                return self.push(Inst::Add(grouped, rest));
            }
        }
        let mut pos = Vec::new();
        let mut neg = Vec::new();
        type Ordered = (bool, usize, Term);
        let mut ordered: Vec<Ordered> = terms
            .into_iter()
            .enumerate()
            .map(|(i, t)| {
                (
                    !t.1.iter().all(|&(b, _)| self.graph.is_parameter_only(b)),
                    i,
                    t,
                )
            })
            .collect();
        ordered.sort_by_key(|t| (t.0, t.1));
        for (_, _, (k, factors, extra)) in ordered {
            // A coefficient joins the term's parameter-only factors (sign
            // included, so the term is simply added); without such factors
            // the sign becomes a subtraction.
            let has_param = extra.is_some()
                || factors
                    .iter()
                    .any(|&(f, _)| self.graph.is_parameter_only(f));
            if factors.is_empty() && extra.is_none() {
                let c = self.constant(k.abs());
                if k.is_negative() {
                    neg.push(c)
                } else {
                    pos.push(c)
                }
            } else if has_param || !k.is_negative() {
                pos.push(self.product(k, &factors, extra));
            } else {
                neg.push(self.product(k.abs(), &factors, extra));
            }
        }
        if !constant.is_zero() {
            let c = self.constant(constant.abs());
            if constant.is_negative() {
                neg.push(c)
            } else {
                pos.push(c)
            }
        }
        let start = match self.chain(&pos, Inst::Add) {
            Some(v) => v,
            None => match neg.is_empty() {
                true => return self.constant(Number::ZERO),
                false => {
                    let first = neg.remove(0);
                    self.push(Inst::Neg(first))
                }
            },
        };
        neg.iter()
            .fold(start, |acc, &x| self.push(Inst::Sub(acc, x)))
    }

    /// A term that holds a sum read nowhere else (`k·x·(a + b)`) gives its
    /// terms to the enclosing sum (`k·x·a + k·x·b`), so the common factors
    /// and parameter parts are sought over all of them (then taken out
    /// again). A shared sum stays whole: it is computed once.
    fn flatten(&self, mut constant: Number, terms: Vec<Term>) -> (Number, Vec<Term>) {
        let nested = |t: &Term| -> Option<usize> {
            if t.2.is_some() {
                return None;
            }
            t.1.iter().position(|&(b, e)| {
                e == 1
                    && self.readers[&b] == 1
                    && matches!(self.graph.node(b), Node::Add { terms, .. } if terms.len() <= MAX_DISTRIBUTED)
            })
        };
        if !terms.iter().any(|t| nested(t).is_some()) {
            return (constant, terms);
        }
        let mut out = Vec::with_capacity(terms.len() * 2);
        let mut stack: Vec<Term> = terms.into_iter().rev().collect();
        while let Some(t) = stack.pop() {
            let Some(at) = nested(&t) else {
                out.push(t);
                continue;
            };
            let (k, mut rest, _) = t;
            let (sum_id, _) = rest.remove(at);
            let Node::Add {
                constant: c,
                terms: inner,
            } = self.graph.node(sum_id)
            else {
                unreachable!("a nested sum")
            };
            if !c.is_zero() {
                if rest.is_empty() {
                    constant = constant + k * *c;
                } else {
                    stack.push((k * *c, rest.clone(), None));
                }
            }
            for &(b, kb) in inner.iter().rev() {
                let mut factors = match self.graph.node(b) {
                    Node::Mul { factors, .. } => factors.to_vec(),
                    _ => vec![(b, 1)],
                };
                for &(f, e) in &rest {
                    match factors.iter_mut().find(|x| x.0 == f) {
                        Some(x) => x.1 += e,
                        None => factors.push((f, e)),
                    }
                }
                factors.retain(|x| x.1 != 0);
                factors.sort_unstable();
                stack.push((k * kb, factors, None));
            }
        }
        (constant, out)
    }

    /// Terms with the same state-dependent factors merged into one, whose
    /// parameter-only part is the (hoisted) sum of theirs.
    fn collect_parameters(&mut self, terms: Vec<Term>) -> Vec<Term> {
        if terms.len() < 2 {
            return terms;
        }
        // Keyed by lowered value: two nodes may lower to one value. The
        // keys share one buffer; equal keys are adjacent once sorted.
        let mut buffer: Vec<(u32, i32)> = Vec::new();
        let mut spans: Vec<(usize, usize, usize)> = Vec::with_capacity(terms.len());
        for (i, (_, factors, _)) in terms.iter().enumerate() {
            let start = buffer.len();
            buffer.extend(
                factors
                    .iter()
                    .filter(|&&(b, _)| !self.graph.is_parameter_only(b))
                    .map(|&(b, e)| (self.memo[&b], e)),
            );
            buffer[start..].sort_unstable();
            if buffer.len() > start {
                spans.push((start, buffer.len(), i));
            }
        }
        spans.sort_by(|a, b| buffer[a.0..a.1].cmp(&buffer[b.0..b.1]).then(a.2.cmp(&b.2)));
        let mut groups: Vec<Vec<usize>> = Vec::new();
        let mut r = 0;
        while r < spans.len() {
            let key = &buffer[spans[r].0..spans[r].1];
            let mut members = vec![spans[r].2];
            r += 1;
            while r < spans.len() && &buffer[spans[r].0..spans[r].1] == key {
                members.push(spans[r].2);
                r += 1;
            }
            if members.len() >= 2 {
                groups.push(members);
            }
        }
        if groups.is_empty() {
            return terms;
        }
        let mut merged: Vec<Option<Term>> = terms.into_iter().map(Some).collect();
        let mut out = Vec::new();
        for members in groups {
            let state: Vec<(Id, i32)> = merged[members[0]]
                .as_ref()
                .expect("each term in one group")
                .1
                .iter()
                .copied()
                .filter(|&(b, _)| !self.graph.is_parameter_only(b))
                .collect();
            // Plain coefficients add up as numbers (x − x is no term).
            let mut number = Number::ZERO;
            let mut parts = Vec::with_capacity(members.len());
            for &i in &members {
                let (k, factors, extra) = merged[i].take().expect("each term in one group");
                let params: Vec<(Id, i32)> = factors
                    .into_iter()
                    .filter(|&(b, _)| self.graph.is_parameter_only(b))
                    .collect();
                if params.is_empty() && extra.is_none() {
                    number = number + k;
                } else {
                    parts.push(self.product(k, &params, extra));
                }
            }
            if parts.is_empty() {
                if !number.is_zero() {
                    out.push((number, state, None));
                }
                continue;
            }
            if !number.is_zero() {
                parts.push(self.constant(number));
            }
            let value = self.chain(&parts, Inst::Add).expect("one part or more");
            out.push((Number::ONE, state, Some(value)));
        }
        // Unmerged terms first, in their order, then the merged ones.
        let mut all: Vec<Term> = merged.into_iter().flatten().collect();
        all.extend(out);
        all
    }

    fn lower_node(&mut self, id: Id) -> u32 {
        let node = self.graph.node(id);
        match node {
            Node::Num(n) => self.constant(*n),
            Node::Sym(s) => self.push(Inst::Symbol(*s)),
            Node::Add { constant, terms } => {
                let terms: Vec<Term> = terms
                    .iter()
                    .map(|&(b, k)| {
                        let factors = match self.graph.node(b) {
                            Node::Mul { factors, .. } => factors.to_vec(),
                            _ => vec![(b, 1)],
                        };
                        (k, factors, None)
                    })
                    .collect();
                self.sum(*constant, terms)
            }
            Node::Mul { coeff, factors } => {
                let factors = factors.to_vec();
                self.product(*coeff, &factors, None)
            }
            Node::Fun(f, a) => {
                let a = self.memo[a];
                self.push(Inst::Call(*f, a))
            }
            Node::Atan2(y, x) => {
                let (y, x) = (self.memo[y], self.memo[x]);
                self.push(Inst::Atan2(y, x))
            }
        }
    }
}

/// Divisions by a denominator that several divisions share become one
/// reciprocal and multiplications (`a/d, b/d → r = 1/d; a·r, b·r`): a
/// division costs several multiplications.
fn share_reciprocals(insts: Vec<Inst>, outputs: Vec<u32>) -> (Vec<Inst>, Vec<u32>) {
    let mut uses = vec![0usize; insts.len()];
    for inst in &insts {
        if let Inst::Div(_, d) = inst {
            uses[*d as usize] += 1;
        }
    }
    if uses.iter().all(|&u| u < 2) {
        return (insts, outputs);
    }
    let mut recip: BTreeMap<u32, u32> = BTreeMap::new();
    let mut one: Option<u32> = None;
    rewrite(insts, outputs, |_, inst, out, map| {
        let Inst::Div(a, d) = *inst else { return None };
        if uses[d as usize] < 2 {
            return None;
        }
        let nd = map[d as usize];
        let rec = match recip.get(&nd) {
            Some(&x) => x,
            None => {
                let o = *one.get_or_insert_with(|| {
                    out.push(Inst::Const(Number::ONE));
                    (out.len() - 1) as u32
                });
                out.push(Inst::Div(o, nd));
                let x = (out.len() - 1) as u32;
                recip.insert(nd, x);
                x
            }
        };
        out.push(Inst::Mul(map[a as usize], rec));
        Some((out.len() - 1) as u32)
    })
}

/// Products that share two factors share their product
/// (`a·b·c, a·b·d → t = a·b; t·c, t·d`): each maximal tree of
/// multiplications is read as its multiset of factors, and the pair of
/// factors found in the most trees becomes one multiplication, greedily,
/// while some pair is found in two trees or more. Reassociating a product
/// changes its rounding by a few half-ulps at most (no cancellation).
fn share_products(graph: &Graph, insts: Vec<Inst>, outputs: Vec<u32>) -> (Vec<Inst>, Vec<u32>) {
    let n = insts.len();
    // Parameter-only values are hoisted: they stay whole, and the
    // parameter-only factors of a product stay one (hoisted) product.
    let parameter_only = parameter_only_flags(graph, &insts);
    let uses = use_counts(&insts, &outputs);
    let is_mul = |i: u32| matches!(insts[i as usize], Inst::Mul(..));
    // Interior: a multiplication used once, by a multiplication.
    let mut interior = vec![false; n];
    for inst in &insts {
        if let Inst::Mul(a, b) = *inst {
            for x in [a, b] {
                if is_mul(x) && uses[x as usize] == 1 && !parameter_only[x as usize] {
                    interior[x as usize] = true;
                }
            }
        }
    }
    // Leaves of each tree root, as sorted lists; a leaf id >= n stands for
    // a shared pair created below.
    let mut roots: Vec<u32> = Vec::new();
    let mut leaves: Vec<Vec<u32>> = Vec::new();
    for (i, inst) in insts.iter().enumerate() {
        if !matches!(inst, Inst::Mul(..)) || interior[i] || parameter_only[i] {
            continue;
        }
        let mut list = Vec::new();
        let mut stack = vec![i as u32];
        while let Some(x) = stack.pop() {
            match insts[x as usize] {
                Inst::Mul(a, b) if x as usize == i || interior[x as usize] => {
                    stack.push(a);
                    stack.push(b);
                }
                _ => list.push(x),
            }
        }
        list.sort_unstable();
        roots.push(i as u32);
        leaves.push(list);
    }
    let mut pairs: Vec<(u32, u32)> = Vec::new();
    // The parameter-only factors of each tree, as one product.
    let mut grouped: FxHashMap<Vec<u32>, u32> = FxHashMap::default();
    for list in leaves.iter_mut() {
        let (params, mut rest): (Vec<u32>, Vec<u32>) =
            list.iter().partition(|&&x| parameter_only[x as usize]);
        if params.len() < 2 {
            continue;
        }
        let mut acc = params[0];
        for (j, &x) in params.iter().enumerate().skip(1) {
            let key = params[..=j].to_vec();
            acc = *grouped.entry(key).or_insert_with(|| {
                pairs.push((acc, x));
                (n + pairs.len() - 1) as u32
            });
        }
        rest.push(acc);
        rest.sort_unstable();
        *list = rest;
    }
    let first = n + pairs.len();
    let shared = share_pairs(
        &mut leaves,
        first,
        |list| {
            let mut seen = Vec::new();
            for x in 0..list.len() {
                for y in x + 1..list.len() {
                    seen.push((list[x], list[y]));
                }
            }
            seen
        },
        |list, (a, b), id| {
            let Some(ia) = list.iter().position(|&x| x == a) else {
                return false;
            };
            let ib = if a == b {
                list.iter()
                    .skip(ia + 1)
                    .position(|&x| x == b)
                    .map(|j| j + ia + 1)
            } else {
                list.iter().position(|&x| x == b)
            };
            let Some(ib) = ib else { return false };
            let (hi, lo) = (ia.max(ib), ia.min(ib));
            list.remove(hi);
            list.remove(lo);
            list.push(id);
            list.sort_unstable();
            true
        },
    );
    pairs.extend(shared);
    if pairs.is_empty() {
        return (insts, outputs);
    }
    // Rebuild: each root becomes the chain over its remaining factors; a
    // shared pair is emitted where first needed.
    let root_of: FxHashMap<u32, usize> = roots.iter().enumerate().map(|(k, &r)| (r, k)).collect();
    let mut pair_at: Vec<Option<u32>> = vec![None; pairs.len()];
    rewrite(insts, outputs, |i, _, out, map| {
        if let Some(&k) = root_of.get(&(i as u32)) {
            let mut acc: Option<u32> = None;
            for &x in &leaves[k] {
                let v = shared_value(x, n, map, &pairs, &mut pair_at, out, &|(_, _), a, b| {
                    Inst::Mul(a.min(b), a.max(b))
                });
                acc = Some(match acc {
                    None => v,
                    Some(a) => {
                        out.push(Inst::Mul(a, v));
                        (out.len() - 1) as u32
                    }
                });
            }
            return Some(acc.expect("a product has factors"));
        }
        // An interior multiplication is never read: its tree's root reads
        // the leaves directly.
        interior[i].then(|| {
            out.push(Inst::Const(Number::ZERO));
            (out.len() - 1) as u32
        })
    })
}

/// Sums that share two terms share their sum (`a + b + c, a + b − d →
/// t = a + b; t + c, t − d`; `a − b` and `b − a` share one subtraction):
/// each maximal tree of additions and subtractions is read as its signed
/// terms, and the pair of terms found in the most trees becomes one
/// operation, greedily, while some pair is found in two trees or more.
fn share_sums(graph: &Graph, insts: Vec<Inst>, outputs: Vec<u32>) -> (Vec<Inst>, Vec<u32>) {
    let n = insts.len();
    let parameter_only = parameter_only_flags(graph, &insts);
    let uses = use_counts(&insts, &outputs);
    let is_sum = |i: u32| matches!(insts[i as usize], Inst::Add(..) | Inst::Sub(..));
    // Interior: an addition, subtraction or negation used once, by an
    // addition or subtraction (a negated term is a subtracted one).
    let is_neg = |i: u32| matches!(insts[i as usize], Inst::Neg(..));
    let mut interior = vec![false; n];
    for inst in &insts {
        if let Inst::Add(a, b) | Inst::Sub(a, b) = *inst {
            for x in [a, b] {
                if (is_sum(x) || is_neg(x)) && uses[x as usize] == 1 && !parameter_only[x as usize]
                {
                    interior[x as usize] = true;
                }
            }
        }
    }
    // Signed terms (id, negated) of each tree; ids >= n are shared pairs.
    let mut roots: Vec<u32> = Vec::new();
    let mut terms: Vec<Vec<(u32, bool)>> = Vec::new();
    let mut cancelled = false;
    for (i, inst) in insts.iter().enumerate() {
        if !matches!(inst, Inst::Add(..) | Inst::Sub(..)) || interior[i] || parameter_only[i] {
            continue;
        }
        let mut list = Vec::new();
        let mut stack = vec![(i as u32, false)];
        while let Some((x, neg)) = stack.pop() {
            let whole = x as usize == i || interior[x as usize];
            match insts[x as usize] {
                Inst::Add(a, b) if whole => {
                    stack.push((a, neg));
                    stack.push((b, neg));
                }
                Inst::Sub(a, b) if whole => {
                    stack.push((a, neg));
                    stack.push((b, !neg));
                }
                Inst::Neg(a) if x as usize != i && interior[x as usize] => {
                    stack.push((a, !neg));
                }
                _ => list.push((x, neg)),
            }
        }
        // x − x (two nodes of the graph that lowered to one value) is 0.
        list.sort_unstable();
        let mut kept: Vec<(u32, bool)> = Vec::with_capacity(list.len());
        for t in list {
            match kept.iter().position(|&(x, neg)| x == t.0 && neg != t.1) {
                Some(at) => {
                    kept.remove(at);
                    cancelled = true;
                }
                None => kept.push(t),
            }
        }
        roots.push(i as u32);
        terms.push(kept);
    }
    // A pair (a, b, b negated relative to a), a < b; the shared value is
    // a ± b, entering a tree with a's sign.
    let pairs: Vec<(u32, u32, bool)> = share_pairs(
        &mut terms,
        n,
        |list| {
            let mut seen = Vec::new();
            for x in 0..list.len() {
                for y in x + 1..list.len() {
                    let ((a, na), (b, nb)) = (list[x], list[y]);
                    if a != b {
                        seen.push((a.min(b), a.max(b), na != nb));
                    }
                }
            }
            seen
        },
        |list, (a, b, opposite), id| {
            let Some(ia) = list.iter().position(|&(x, _)| x == a) else {
                return false;
            };
            let na = list[ia].1;
            let Some(ib) = list
                .iter()
                .position(|&(x, nb)| x == b && (na != nb) == opposite)
            else {
                return false;
            };
            let (hi, lo) = (ia.max(ib), ia.min(ib));
            list.remove(hi);
            list.remove(lo);
            list.push((id, na));
            list.sort_unstable();
            true
        },
    );
    if pairs.is_empty() && !cancelled {
        return (insts, outputs);
    }
    let root_of: FxHashMap<u32, usize> = roots.iter().enumerate().map(|(k, &r)| (r, k)).collect();
    let mut pair_at: Vec<Option<u32>> = vec![None; pairs.len()];
    rewrite(insts, outputs, |i, _, out, map| {
        let Some(&k) = root_of.get(&(i as u32)) else {
            // An interior term is never read: its tree's root reads the
            // terms directly.
            return interior[i].then(|| {
                out.push(Inst::Const(Number::ZERO));
                (out.len() - 1) as u32
            });
        };
        let mut pos = Vec::new();
        let mut neg = Vec::new();
        for &(x, negated) in &terms[k] {
            let v = shared_value(
                x,
                n,
                map,
                &pairs,
                &mut pair_at,
                out,
                &|(_, _, opposite), a, b| {
                    if opposite {
                        Inst::Sub(a, b)
                    } else {
                        Inst::Add(a.min(b), a.max(b))
                    }
                },
            );
            if negated {
                neg.push(v);
            } else {
                pos.push(v);
            }
        }
        if pos.is_empty() && neg.is_empty() {
            out.push(Inst::Const(Number::ZERO));
            return Some((out.len() - 1) as u32);
        }
        let mut acc = match pos.first() {
            Some(&first) => first,
            None => {
                // −(a − b) is b − a.
                let first = neg.remove(0);
                out.push(match out[first as usize] {
                    Inst::Sub(a, b) => Inst::Sub(b, a),
                    _ => Inst::Neg(first),
                });
                (out.len() - 1) as u32
            }
        };
        for &v in pos.iter().skip(1) {
            out.push(Inst::Add(acc.min(v), acc.max(v)));
            acc = (out.len() - 1) as u32;
        }
        for v in neg {
            out.push(Inst::Sub(acc, v));
            acc = (out.len() - 1) as u32;
        }
        Some(acc)
    })
}

/// Rewrites a program instruction by instruction: `special(i, inst, out,
/// map)` may emit instruction i's replacement into `out` (`map` gives the
/// new index of every earlier instruction) and return its index; else the
/// instruction is copied with its operands renumbered.
fn rewrite(
    insts: Vec<Inst>,
    outputs: Vec<u32>,
    mut special: impl FnMut(usize, &Inst, &mut Vec<Inst>, &[u32]) -> Option<u32>,
) -> (Vec<Inst>, Vec<u32>) {
    let mut out: Vec<Inst> = Vec::with_capacity(insts.len() + 8);
    let mut map = vec![u32::MAX; insts.len()];
    for (i, inst) in insts.into_iter().enumerate() {
        let at = match special(i, &inst, &mut out, &map) {
            Some(at) => at,
            None => {
                out.push(inst.remap(|x| map[x as usize]));
                (out.len() - 1) as u32
            }
        };
        map[i] = at;
    }
    let outputs = outputs.iter().map(|&o| map[o as usize]).collect();
    (out, outputs)
}

/// `−v` appended to `out`, folded into a constant or into a negation it
/// undoes; returns its index.
fn negated(out: &mut Vec<Inst>, v: u32) -> u32 {
    match out[v as usize] {
        Inst::Const(c) => out.push(Inst::Const(-c)),
        Inst::Neg(y) => return y,
        _ => out.push(Inst::Neg(v)),
    }
    (out.len() - 1) as u32
}

/// `prune` on a pair.
fn prune_pair((insts, outputs): (Vec<Inst>, Vec<u32>)) -> (Vec<Inst>, Vec<u32>) {
    prune(insts, outputs)
}

/// Arithmetic modulo the Mersenne prime 2⁶¹ − 1, where
/// [`share_equal_values`] evaluates programs exactly.
mod modp {
    pub const P: u64 = (1 << 61) - 1;

    pub fn add(a: u64, b: u64) -> u64 {
        let s = a + b;
        if s >= P {
            s - P
        } else {
            s
        }
    }

    pub fn neg(a: u64) -> u64 {
        if a == 0 {
            0
        } else {
            P - a
        }
    }

    pub fn mul(a: u64, b: u64) -> u64 {
        let t = a as u128 * b as u128;
        let r = ((t & P as u128) + (t >> 61)) as u64;
        if r >= P {
            r - P
        } else {
            r
        }
    }

    pub fn pow(mut a: u64, mut e: u64) -> u64 {
        let mut r = 1;
        while e > 0 {
            if e & 1 == 1 {
                r = mul(r, a);
            }
            a = mul(a, a);
            e >>= 1;
        }
        r
    }

    /// The inverse, or None for zero.
    pub fn inv(a: u64) -> Option<u64> {
        (a != 0).then(|| pow(a, P - 2))
    }

    /// An integer's residue.
    pub fn int(n: i128) -> u64 {
        let r = (n.unsigned_abs() % P as u128) as u64;
        if n < 0 {
            neg(r)
        } else {
            r
        }
    }
}

/// Number of random points [`share_equal_values`] compares at.
const VALUE_POINTS: usize = 2;

/// One instruction for each value that several compute in different forms.
///
/// The graph's canonical forms leave some equal values apart (a sum kept
/// factored in one place and multiplied out in another); after lowering,
/// such a pair is two instructions. Every instruction is evaluated exactly,
/// modulo the prime 2⁶¹ − 1, at [`VALUE_POINTS`] pseudo-random points: each
/// symbol, each call other than sine, cosine and tangent (a square root,
/// say), each `atan2`, each non-integer constant and each rational constant
/// too large for the prime stands for an independent random residue, and
/// the sine and cosine of one argument for a random point of the unit
/// circle (rationally parametrized). Every kind of variable draws from its
/// own stream, so a sine's argument that is a small integer cannot tie it to
/// a symbol. Two instructions with the same residues (or opposite ones) at
/// every point are then the same rational function of those variables,
/// except with a probability of about (degree / 2⁶¹)² (Schwartz–Zippel), and
/// so the same value at every state; the later one is replaced by the
/// earlier (or its negation), which may be a symbol or a constant: `(a − b)
/// − a` becomes `−b`. Identities that need more of a function's meaning
/// than sin² + cos² = 1 (the double angle, √x² = |x|) are not found, which
/// only misses a merge.
///
/// The earlier form is used only where it reads no auxiliary symbol (the
/// unknowns of a solve, which a staged program computes between stages) or
/// acceleration the later one does not, and reads the state only if the
/// later one does: a value stays in its stage, and a parameter-only value
/// stays computed once per parameter set. Values change only by the
/// rounding of the form dropped.
fn share_equal_values(graph: &Graph, insts: Vec<Inst>, outputs: Vec<u32>) -> (Vec<Inst>, Vec<u32>) {
    use modp::*;
    let n = insts.len();
    let mix = |mut z: u64| {
        z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        (z ^ (z >> 31)) % P
    };
    // The streams the kinds of variable draw from.
    const FLOAT: u64 = 0xF10A_7000_0000_0001;
    const RATIONAL: u64 = 0x4A71_0000_0000_0002;
    const SYMBOL: u64 = 0x5E4B_0000_0000_0003;
    const CIRCLE: u64 = 0xC14C_1E00_0000_0004;
    const CALL: u64 = 0xCA11_0000_0000_0005;
    // What each instruction reads, directly or not, that an equal earlier
    // form may not add: the state (`parameter_only_flags`), and the
    // auxiliary symbols and accelerations, a bit each, `words` words per
    // instruction.
    let parameter = parameter_only_flags(graph, &insts);
    let mut late_bit: FxHashMap<Symbol, usize> = FxHashMap::default();
    for inst in &insts {
        if let Inst::Symbol(s) = *inst {
            if matches!(
                graph.symbol_kind(s),
                SymbolKind::Auxiliary | SymbolKind::Acceleration(_)
            ) {
                let next = late_bit.len();
                late_bit.entry(s).or_insert(next);
            }
        }
    }
    let words = late_bit.len().div_ceil(64).max(1);
    let mut late = vec![0u64; n * words];
    for (i, inst) in insts.iter().enumerate() {
        if let Some(&bit) = match *inst {
            Inst::Symbol(s) => late_bit.get(&s),
            _ => None,
        } {
            late[i * words + bit / 64] |= 1 << (bit % 64);
        }
        for x in inst.operands() {
            for w in 0..words {
                late[i * words + w] |= late[x as usize * words + w];
            }
        }
    }
    let reads_within = |i: usize, j: usize| {
        (parameter[i] || !parameter[j])
            && (0..words).all(|w| late[i * words + w] & !late[j * words + w] == 0)
    };
    // A residue per instruction and point; None where a division by zero
    // (a probability of about 2⁻⁶¹) leaves it undefined.
    let mut values: Vec<Option<[u64; VALUE_POINTS]>> = Vec::with_capacity(n);
    for (i, inst) in insts.iter().enumerate() {
        let mut out = [0u64; VALUE_POINTS];
        let mut defined = true;
        for (k, slot) in out.iter_mut().enumerate() {
            let v = |x: u32| values[x as usize].map(|v| v[k]);
            let fresh = |kind: u64, x: u64| mix(mix(x ^ kind).wrapping_add(k as u64 + 1));
            let r = match *inst {
                Inst::Const(c) => match c {
                    Number::Rational { num, den }
                        if num.unsigned_abs() < P as u128 && den.unsigned_abs() < P as u128 =>
                    {
                        inv(int(den)).map(|d| mul(int(num), d))
                    }
                    // Too large for the prime: two such constants could
                    // share a residue, so each is a variable of its own.
                    Number::Rational { num, den } => {
                        let fold = |x: i128| mix(x as u64) ^ ((x >> 64) as u64);
                        Some(fresh(RATIONAL, fold(num) ^ mix(fold(den))))
                    }
                    Number::Float(_) => Some(fresh(FLOAT, c.to_f64().to_bits())),
                },
                Inst::Symbol(s) => Some(fresh(SYMBOL, s.0 as u64)),
                Inst::Add(a, b) => v(a).zip(v(b)).map(|(a, b)| add(a, b)),
                Inst::Sub(a, b) => v(a).zip(v(b)).map(|(a, b)| add(a, neg(b))),
                Inst::Mul(a, b) => v(a).zip(v(b)).map(|(a, b)| mul(a, b)),
                Inst::Div(a, b) => v(a).zip(v(b).and_then(inv)).map(|(a, b)| mul(a, b)),
                Inst::Neg(a) => v(a).map(neg),
                Inst::Powi(a, e) => v(a).and_then(|a| {
                    let base = if e < 0 { inv(a)? } else { a };
                    Some(pow(base, e.unsigned_abs() as u64))
                }),
                // The sine and cosine of one argument are a point of the
                // unit circle, (2t, 1 − t²)/(1 + t²) for a t drawn from the
                // argument's residue, so sin² + cos² = 1 holds exactly.
                Inst::Call(f @ (Func::Sin | Func::Cos | Func::Tan), a) => v(a).and_then(|a| {
                    let t = fresh(CIRCLE, a);
                    let d = inv(add(1, mul(t, t)))?;
                    let sin = mul(add(t, t), d);
                    let cos = mul(add(1, neg(mul(t, t))), d);
                    Some(match f {
                        Func::Sin => sin,
                        Func::Cos => cos,
                        _ => mul(sin, inv(cos)?),
                    })
                }),
                // Other calls and atan2 are variables of their own.
                Inst::Call(..) | Inst::Atan2(..) => Some(fresh(CALL, i as u64)),
            };
            match r {
                Some(r) => *slot = r,
                None => defined = false,
            }
        }
        values.push(defined.then_some(out));
    }
    // The instructions met so far, by value, earliest first; constants and
    // symbols are among them but are never replaced themselves.
    let mut earlier: FxHashMap<[u64; VALUE_POINTS], Vec<u32>> = FxHashMap::default();
    let mut replace: Vec<Option<(u32, bool)>> = vec![None; n];
    for (j, inst) in insts.iter().enumerate() {
        let Some(v) = values[j] else { continue };
        if v.iter().all(|&x| x == 0) {
            continue;
        }
        let leaf = matches!(inst, Inst::Const(_) | Inst::Symbol(_));
        if !leaf {
            let usable = |key: &[u64; VALUE_POINTS]| {
                earlier
                    .get(key)
                    .and_then(|c| c.iter().copied().find(|&i| reads_within(i as usize, j)))
            };
            replace[j] = usable(&v)
                .map(|i| (i, false))
                .or_else(|| usable(&v.map(neg)).map(|i| (i, true)));
        }
        if replace[j].is_none() {
            earlier.entry(v).or_default().push(j as u32);
        }
    }
    rewrite(insts, outputs, |j, _, out, map| {
        let (i, is_negated) = replace[j]?;
        let at = map[i as usize];
        Some(if is_negated { negated(out, at) } else { at })
    })
}

/// How deep a negation is carried through products and differences before
/// it is given up (each step rewrites one more instruction).
const MAX_SIGN_DEPTH: usize = 8;

/// Absorbs negations into their readers: `x + (−a)` is `x − a`,
/// `x − (−a)` is `x + a`, and a product, quotient or `(−a) − x` passes the
/// sign on to its own readers (`(−a)·b` read by a sum is `− a·b` there).
/// A `Neg` whose sign every reader can take this way disappears, and so
/// does `b − a` computed beside `a − b` (its negation). IEEE
/// negation is exact and rounding is symmetric, so every value is the same
/// bit for bit; only the work changes.
fn absorb_negations(mut insts: Vec<Inst>, outputs: Vec<u32>) -> (Vec<Inst>, Vec<u32>) {
    let mut readers: Vec<Vec<u32>> = vec![Vec::new(); insts.len()];
    for (i, inst) in insts.iter().enumerate() {
        let mut ops = inst.operands();
        ops.dedup();
        for o in ops {
            readers[o as usize].push(i as u32);
        }
    }
    let mut output = vec![false; insts.len()];
    for &o in &outputs {
        output[o as usize] = true;
    }
    // The rewrites that make value `v` (about to be replaced by its
    // negation `v'`) cost nothing: each reader's new instruction, or None.
    fn plan(
        v: u32,
        insts: &[Inst],
        readers: &[Vec<u32>],
        output: &[bool],
        depth: usize,
        planned: &mut FxHashMap<u32, Inst>,
    ) -> bool {
        if output[v as usize] || depth > MAX_SIGN_DEPTH {
            return false;
        }
        for &r in &readers[v as usize] {
            if planned.contains_key(&r) {
                // Reached twice (a diamond): keep it simple, give up.
                return false;
            }
            // The reader rewritten over v' (its value unchanged), or the
            // reader's negation over v' (its sign then passed on).
            let (inst, flips) = match insts[r as usize] {
                Inst::Add(a, b) if a == v && b != v => (Inst::Sub(b, a), false),
                Inst::Add(a, b) if b == v && a != v => (Inst::Sub(a, b), false),
                Inst::Sub(a, b) if b == v && a != v => (Inst::Add(a.min(b), a.max(b)), false),
                Inst::Sub(a, b) if a == v && b != v => (Inst::Add(a.min(b), a.max(b)), true),
                Inst::Mul(a, b) if a != b => (Inst::Mul(a, b), true),
                Inst::Div(a, b) if a != b => (Inst::Div(a, b), true),
                _ => return false,
            };
            planned.insert(r, inst);
            if flips && !plan(r, insts, readers, output, depth + 1, planned) {
                return false;
            }
        }
        true
    }
    let mut changed = false;
    // b − a beside a − b is the negation of the latter.
    let mut differences: FxHashMap<(u32, u32), u32> = FxHashMap::default();
    for i in 0..insts.len() {
        let a = match insts[i] {
            Inst::Neg(a) => a,
            Inst::Sub(x, y) => match differences.get(&(y, x)) {
                Some(&d) => d,
                None => {
                    differences.insert((x, y), i as u32);
                    continue;
                }
            },
            _ => continue,
        };
        let mut planned = FxHashMap::default();
        if !plan(i as u32, &insts, &readers, &output, 0, &mut planned) {
            continue;
        }
        // Every reader of the Neg reads its operand instead.
        for (r, inst) in planned {
            insts[r as usize] = inst.remap(|x| if x == i as u32 { a } else { x });
            for o in insts[r as usize].operands() {
                if !readers[o as usize].contains(&r) {
                    readers[o as usize].push(r);
                }
            }
        }
        readers[i].clear();
        changed = true;
    }
    if !changed {
        return (insts, outputs);
    }
    prune(insts, outputs)
}

/// Greedy sharing of pairs over trees (each a list of items): while some
/// pair is found in two trees or more, the pair found in the most trees
/// (ties: the smallest) becomes a new item, numbered `first` + its index,
/// in every tree that holds it. `pairs_of` lists a tree's pairs and
/// `replace` puts the new item in place of one occurrence of a pair
/// (false if the tree has none). Counts are kept up to date incrementally:
/// only the trees that held the chosen pair are read again. Returns the
/// pairs in the order chosen.
fn share_pairs<I, P: Copy + Ord + std::hash::Hash>(
    trees: &mut [Vec<I>],
    first: usize,
    pairs_of: impl Fn(&[I]) -> Vec<P>,
    mut replace: impl FnMut(&mut Vec<I>, P, u32) -> bool,
) -> Vec<P> {
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;
    let distinct = |tree: &[I]| {
        let mut ps = pairs_of(tree);
        ps.sort_unstable();
        ps.dedup();
        ps
    };
    let mut counts: FxHashMap<P, usize> = FxHashMap::default();
    let mut holders: FxHashMap<P, Vec<usize>> = FxHashMap::default();
    let mut held: Vec<Vec<P>> = Vec::with_capacity(trees.len());
    for (t, tree) in trees.iter().enumerate() {
        let ps = distinct(tree);
        for &p in &ps {
            *counts.entry(p).or_insert(0) += 1;
            holders.entry(p).or_default().push(t);
        }
        held.push(ps);
    }
    // Largest count first, then the smallest pair; an entry whose count is
    // no longer the pair's is stale and skipped.
    let mut heap: BinaryHeap<(usize, Reverse<P>)> = counts
        .iter()
        .filter(|&(_, &c)| c >= 2)
        .map(|(&p, &c)| (c, Reverse(p)))
        .collect();
    let mut chosen = Vec::new();
    while let Some((c, Reverse(p))) = heap.pop() {
        if counts.get(&p) != Some(&c) {
            continue;
        }
        let id = (first + chosen.len()) as u32;
        chosen.push(p);
        let mut list = holders.remove(&p).unwrap_or_default();
        list.sort_unstable();
        list.dedup();
        for t in list {
            if held[t].binary_search(&p).is_err() {
                continue;
            }
            for q in std::mem::take(&mut held[t]) {
                let c = counts.get_mut(&q).expect("a counted pair");
                *c -= 1;
                if *c >= 2 {
                    heap.push((*c, Reverse(q)));
                }
            }
            replace(&mut trees[t], p, id);
            let ps = distinct(&trees[t]);
            for &q in &ps {
                let c = counts.entry(q).or_insert(0);
                *c += 1;
                if *c >= 2 {
                    heap.push((*c, Reverse(q)));
                }
                holders.entry(q).or_default().push(t);
            }
            held[t] = ps;
        }
    }
    chosen
}

/// The instruction holding item `x` of [`share_pairs`]: an original
/// instruction's new index (`map`), or a shared pair's value, emitted into
/// `out` by `make(pair, a, b)` from its two items where first needed.
fn shared_value<P: Copy + PairItems>(
    x: u32,
    n: usize,
    map: &[u32],
    pairs: &[P],
    pair_at: &mut [Option<u32>],
    out: &mut Vec<Inst>,
    make: &dyn Fn(P, u32, u32) -> Inst,
) -> u32 {
    if (x as usize) < n {
        return map[x as usize];
    }
    let k = x as usize - n;
    if let Some(at) = pair_at[k] {
        return at;
    }
    let (a, b) = pairs[k].items();
    let a = shared_value(a, n, map, pairs, pair_at, out, make);
    let b = shared_value(b, n, map, pairs, pair_at, out, make);
    out.push(make(pairs[k], a, b));
    let at = (out.len() - 1) as u32;
    pair_at[k] = Some(at);
    at
}

/// The two items a shared pair combines.
trait PairItems {
    fn items(&self) -> (u32, u32);
}

impl PairItems for (u32, u32) {
    fn items(&self) -> (u32, u32) {
        *self
    }
}

impl PairItems for (u32, u32, bool) {
    fn items(&self) -> (u32, u32) {
        (self.0, self.1)
    }
}

/// Rough latency, in cycles, of an instruction on a current x86-64 core:
/// the model [`balance_sums`] orders a sum's terms by.
fn latency(inst: &Inst) -> u32 {
    match inst {
        Inst::Const(_) | Inst::Symbol(_) => 0,
        Inst::Neg(_) | Inst::Call(Func::Abs, _) => 1,
        Inst::Add(..) | Inst::Sub(..) | Inst::Mul(..) => 4,
        Inst::Div(..) => 14,
        Inst::Call(Func::Sqrt, _) => 20,
        Inst::Powi(..) => 30,
        Inst::Call(..) | Inst::Atan2(..) => 60,
    }
}

/// How far (in cycles of [`latency`]) a running sum may lag behind a term
/// before the term starts a running sum of its own. Measured on the
/// bicycle's rhs: 0, 8 and 16 time alike, and all beat the plain chain.
const SUM_SLACK: u32 = 8;

/// Re-associates every sum so that its result is ready early.
///
/// Lowering writes a sum of n terms as a chain: n − 1 additions one after
/// the other, each waiting for the last. Here the terms of each maximal
/// sum (the additions and subtractions read only by the next one) are
/// added in the order their values become ready, into running sums that
/// each take a term as soon as it is ready, with a new running sum
/// started when the others lag more than [`SUM_SLACK`] cycles behind; the
/// running sums are then added pairwise, earliest first. A product read
/// only by the sum stays an operand of an addition, so emission can still
/// fuse it. The operation count is unchanged; values change only by
/// rounding (the terms are the same, added in another order).
fn balance_sums(graph: &Graph, insts: Vec<Inst>, outputs: Vec<u32>) -> (Vec<Inst>, Vec<u32>) {
    let n = insts.len();
    let uses = use_counts(&insts, &outputs);
    let is_sum = |i: u32| matches!(insts[i as usize], Inst::Add(..) | Inst::Sub(..));
    let mut internal = vec![false; n];
    for inst in &insts {
        if let Inst::Add(a, b) | Inst::Sub(a, b) = *inst {
            for o in [a, b] {
                if a != b && uses[o as usize] == 1 && is_sum(o) {
                    internal[o as usize] = true;
                }
            }
        }
    }
    struct Out {
        insts: Vec<Inst>,
        ready: Vec<u32>,
        parameter: Vec<bool>,
    }
    impl Out {
        fn push(&mut self, graph: &Graph, inst: Inst, ready: Option<u32>) -> u32 {
            let parameter = parameter_only(graph, &inst, &self.parameter);
            let r = if parameter {
                0
            } else {
                ready.unwrap_or_else(|| {
                    let start = inst
                        .operands()
                        .iter()
                        .map(|&o| self.ready[o as usize])
                        .max();
                    start.unwrap_or(0) + latency(&inst)
                })
            };
            self.insts.push(inst);
            self.ready.push(r);
            self.parameter.push(parameter);
            (self.insts.len() - 1) as u32
        }
        /// `±x ± y` as one instruction and the sign of its value.
        fn combine(
            &mut self,
            graph: &Graph,
            x: (u32, bool),
            y: (u32, bool),
            ready: u32,
        ) -> (u32, bool) {
            let (inst, neg) = match (x.1, y.1) {
                (false, false) => (Inst::Add(x.0, y.0), false),
                (false, true) => (Inst::Sub(x.0, y.0), false),
                (true, false) => (Inst::Sub(y.0, x.0), false),
                (true, true) => (Inst::Add(x.0, y.0), true),
            };
            (self.push(graph, inst, Some(ready)), neg)
        }
    }
    let mut out = Out {
        insts: Vec::with_capacity(n),
        ready: Vec::with_capacity(n),
        parameter: Vec::with_capacity(n),
    };
    let mut map = vec![u32::MAX; n];
    for i in 0..n {
        if internal[i] {
            continue;
        }
        if !is_sum(i as u32) {
            let inst = insts[i].clone().remap(|x| map[x as usize]);
            map[i] = out.push(graph, inst, None);
            continue;
        }
        // The terms, left to right, with their signs.
        let mut terms: Vec<(u32, bool)> = Vec::new();
        let mut stack = vec![(i as u32, false)];
        while let Some((j, neg)) = stack.pop() {
            match insts[j as usize] {
                Inst::Add(a, b) | Inst::Sub(a, b) if j == i as u32 || internal[j as usize] => {
                    let sub = matches!(insts[j as usize], Inst::Sub(..));
                    stack.push((b, neg != sub));
                    stack.push((a, neg));
                }
                _ => terms.push((j, neg)),
            }
        }
        if terms.len() <= 2 {
            let inst = insts[i].clone().remap(|x| map[x as usize]);
            map[i] = out.push(graph, inst, None);
            continue;
        }
        // When each term can start: a product read only here is fused
        // into its addition, so it starts when its factors are ready.
        // Parameter-only terms first, so they are summed once, in `prepare`.
        let mut timed: Vec<(bool, u32, usize, u32, bool)> = terms
            .iter()
            .enumerate()
            .map(|(k, &(j, neg))| {
                let t = map[j as usize];
                let start = match out.insts[t as usize] {
                    Inst::Mul(a, b) if uses[j as usize] == 1 && !out.parameter[t as usize] => {
                        out.ready[a as usize].max(out.ready[b as usize])
                    }
                    _ => out.ready[t as usize],
                };
                (!out.parameter[t as usize], start, k, t, neg)
            })
            .collect();
        timed.sort();
        // Running sums: (ready, value, sign).
        let mut running: Vec<(u32, u32, bool)> = Vec::new();
        for (_, start, _, t, neg) in timed {
            let earliest = (0..running.len()).min_by_key(|&r| (running[r].0, r));
            match earliest {
                Some(r) if running[r].0 <= start + SUM_SLACK => {
                    let (ready, v, s) = running[r];
                    let at = if out.parameter[t as usize] && out.parameter[v as usize] {
                        0
                    } else {
                        ready.max(start) + 4
                    };
                    let (v, s) = out.combine(graph, (v, s), (t, neg), at);
                    running[r] = (out.ready[v as usize], v, s);
                }
                _ => running.push((out.ready[t as usize], t, neg)),
            }
        }
        while running.len() > 1 {
            running.sort_by_key(|&(ready, v, _)| std::cmp::Reverse((ready, v)));
            let (rx, x, sx) = running.pop().expect("two running sums");
            let (ry, y, sy) = running.pop().expect("two running sums");
            let (v, s) = out.combine(graph, (x, sx), (y, sy), rx.max(ry) + 4);
            running.push((out.ready[v as usize], v, s));
        }
        let (_, mut v, neg) = running[0];
        if neg {
            v = out.push(graph, Inst::Neg(v), None);
        }
        map[i] = v;
    }
    let outputs = outputs.iter().map(|&o| map[o as usize]).collect();
    prune(out.insts, outputs)
}

/// Whether each instruction depends on parameters (and constants) only.
fn parameter_only_flags(graph: &Graph, insts: &[Inst]) -> Vec<bool> {
    let mut flags: Vec<bool> = Vec::with_capacity(insts.len());
    for inst in insts {
        let p = parameter_only(graph, inst, &flags);
        flags.push(p);
    }
    flags
}

/// Whether `inst` depends on parameters (and constants) only, given the
/// flags of the instructions before it.
fn parameter_only(graph: &Graph, inst: &Inst, flags: &[bool]) -> bool {
    match inst {
        Inst::Const(_) => true,
        Inst::Symbol(s) => graph.symbol_kind(*s) == SymbolKind::Parameter,
        other => other.operands().iter().all(|&o| flags[o as usize]),
    }
}

/// How many instructions (and outputs) read each instruction.
fn use_counts(insts: &[Inst], outputs: &[u32]) -> Vec<u32> {
    let mut uses = vec![0u32; insts.len()];
    for inst in insts {
        for o in inst.operands() {
            uses[o as usize] += 1;
        }
    }
    for &o in outputs {
        uses[o as usize] += 1;
    }
    uses
}

/// Keeps only the instructions the outputs need, once each, renumbered in
/// order.
fn prune(insts: Vec<Inst>, outputs: Vec<u32>) -> (Vec<Inst>, Vec<u32>) {
    let mut needed = vec![false; insts.len()];
    for &o in &outputs {
        needed[o as usize] = true;
    }
    for i in (0..insts.len()).rev() {
        if needed[i] {
            for op in insts[i].operands() {
                needed[op as usize] = true;
            }
        }
    }
    let mut renumber = vec![u32::MAX; insts.len()];
    let mut kept = Vec::new();
    let mut index: FxHashMap<Inst, u32> = FxHashMap::default();
    for (i, inst) in insts.into_iter().enumerate() {
        if !needed[i] {
            continue;
        }
        let r = |x: u32| renumber[x as usize];
        // Commutative operands in order, so equal instructions are equal.
        let inst = match inst.remap(r) {
            Inst::Add(a, b) => Inst::Add(a.min(b), a.max(b)),
            Inst::Mul(a, b) => Inst::Mul(a.min(b), a.max(b)),
            other => other,
        };
        // The same instruction twice (a product rebuilt from shared
        // factors) is kept once.
        renumber[i] = *index.entry(inst.clone()).or_insert_with(|| {
            kept.push(inst);
            (kept.len() - 1) as u32
        });
    }
    let outputs = outputs.iter().map(|&o| renumber[o as usize]).collect();
    (kept, outputs)
}

impl Program {
    /// Lowers the expressions `roots` of `graph`.
    pub fn lower(graph: &Graph, roots: &[Id]) -> Program {
        let order = graph.reachable(roots);
        let mut readers: FxHashMap<Id, u32> = FxHashMap::default();
        for &id in order.iter().chain(roots) {
            readers.entry(id).or_insert(0);
        }
        for &id in &order {
            for c in graph.node(id).children() {
                *readers.entry(c).or_insert(0) += 1;
            }
        }
        for &r in roots {
            *readers.entry(r).or_insert(0) += 1;
        }
        let mut l = Lowering {
            graph,
            readers,
            insts: Vec::new(),
            index: FxHashMap::default(),
            memo: FxHashMap::default(),
        };
        for id in order {
            let i = l.lower_node(id);
            l.memo.insert(id, i);
        }
        let outputs: Vec<u32> = roots.iter().map(|r| l.memo[r]).collect();
        // Lowering builds forms that end up unused (a sum's terms before
        // their common factors are taken out): drop them first, so that
        // only live instructions count as uses below.
        let (insts, outputs) = prune(l.insts, outputs);
        let (insts, outputs) = prune_pair(share_equal_values(graph, insts, outputs));
        let (insts, outputs) = share_reciprocals(insts, outputs);
        let (insts, outputs) = share_products(graph, insts, outputs);
        let (insts, outputs) = prune(insts, outputs);
        let (insts, outputs) = share_sums(graph, insts, outputs);
        let (insts, outputs) = prune(insts, outputs);
        let (insts, outputs) = absorb_negations(insts, outputs);
        let (insts, outputs) = balance_sums(graph, insts, outputs);
        let parameter_only = parameter_only_flags(graph, &insts);
        let uses = use_counts(&insts, &outputs);
        Program {
            insts,
            outputs,
            parameter_only,
            uses,
        }
    }

    /// The instructions, in evaluation order.
    pub fn insts(&self) -> &[Inst] {
        &self.insts
    }

    /// The instruction of each root.
    pub fn outputs(&self) -> &[u32] {
        &self.outputs
    }

    /// Operations executed once all shared subexpressions are computed once.
    pub fn op_count(&self) -> OpCount {
        let mut c = OpCount::default();
        for inst in &self.insts {
            c.count(inst, 1);
        }
        c
    }

    /// Operations of the same program written as trees, every shared
    /// subexpression recomputed where used (the count before CSE).
    pub fn tree_op_count(&self) -> OpCount {
        let mult = self.tree_multiplicity();
        let mut c = OpCount::default();
        for (i, inst) in self.insts.iter().enumerate() {
            c.count(inst, mult[i]);
        }
        c
    }

    fn tree_multiplicity(&self) -> Vec<usize> {
        let mut mult = vec![0usize; self.insts.len()];
        for &o in &self.outputs {
            mult[o as usize] += 1;
        }
        for i in (0..self.insts.len()).rev() {
            let m = mult[i];
            for o in self.insts[i].operands() {
                mult[o as usize] = mult[o as usize].saturating_add(m);
            }
        }
        mult
    }

    /// Runs the program in `f64` (the emitted Rust computes exactly this).
    pub fn eval(&self, env: &dyn Fn(Symbol) -> Option<f64>) -> Option<Vec<f64>> {
        let mut v: Vec<f64> = Vec::with_capacity(self.insts.len());
        for inst in &self.insts {
            let x = match *inst {
                Inst::Const(n) => n.to_f64(),
                Inst::Symbol(s) => env(s)?,
                Inst::Add(a, b) => v[a as usize] + v[b as usize],
                Inst::Sub(a, b) => v[a as usize] - v[b as usize],
                Inst::Mul(a, b) => v[a as usize] * v[b as usize],
                Inst::Div(a, b) => v[a as usize] / v[b as usize],
                Inst::Neg(a) => -v[a as usize],
                Inst::Powi(a, e) => v[a as usize].powi(e),
                Inst::Call(f, a) => f.apply(v[a as usize]),
                Inst::Atan2(y, x) => v[y as usize].atan2(v[x as usize]),
            };
            v.push(x);
        }
        Some(self.outputs.iter().map(|&o| v[o as usize]).collect())
    }

    /// Writes the program as Rust statements.
    pub fn to_rust(&self, graph: &Graph, options: &EmitOptions) -> RustCode {
        Writer::new(self, graph, options).write()
    }
}

/// Choices for [`Program::to_rust`].
#[derive(Clone, Debug)]
pub struct EmitOptions {
    /// The scalar type in the emitted code (a generic parameter name or a
    /// concrete type).
    pub scalar: String,
    /// The expression that turns an `f64` literal into the scalar;
    /// `{ty}` is replaced by [`EmitOptions::scalar`] and `{lit}` by the literal.
    pub constant: String,
    /// Share subexpressions used more than once through `let` bindings. Off,
    /// every use is written out (readable for very small problems only).
    pub cse: bool,
    /// Move parameter-only subexpressions into [`RustCode::prepare`].
    pub hoist_parameters: bool,
    /// How each symbol is read (default: its name, as a local binding).
    pub symbol_text: BTreeMap<Symbol, String>,
    /// The stage at which each symbol becomes available (default 0). A
    /// statement belongs to the latest stage of the symbols it reads, and
    /// [`RustCode::stages`] lists the statements stage by stage, so a caller
    /// can compute some values between stages (e.g. a numeric solve whose
    /// results are the symbols of the next stage) within one program that
    /// shares every common subexpression.
    pub symbol_stage: BTreeMap<Symbol, usize>,
    /// Write a product that feeds a sum or a difference, and is not shared,
    /// as `x.fused_mul_add(y, z)` (a method the scalar trait must provide,
    /// equal to `x * y + z`): one instruction where the target fuses them.
    /// A difference is written with the sign moved onto a factor or the
    /// addend, which IEEE arithmetic gives exactly, so an unfused
    /// `fused_mul_add` gives the same values as the plain text.
    pub fused: bool,
}

impl Default for EmitOptions {
    fn default() -> Self {
        EmitOptions {
            scalar: "T".to_string(),
            constant: "<{ty} as ::appell_runtime::Scalar>::from_f64({lit})".to_string(),
            cse: true,
            hoist_parameters: true,
            symbol_text: BTreeMap::new(),
            symbol_stage: BTreeMap::new(),
            fused: false,
        }
    }
}

/// Emitted Rust code: statements and the expression of each output.
///
/// The statements use method-call syntax (`x.sin()`, `x.powi(20)`) on the
/// scalar, so the runtime's scalar trait must be in scope where they are
/// placed.
///
/// ```
/// use appell_symbolic::{EmitOptions, Graph, Program};
/// let mut g = Graph::new();
/// let m = g.parameter("m").unwrap();
/// let l = g.parameter("l").unwrap();
/// let e = g.parse("m*l^2*sin(q)*cos(q) + m*l^2*q").unwrap();
/// let program = Program::lower(&g, &[e]);
/// let code = program.to_rust(&g, &EmitOptions::default());
/// assert_eq!(code.hoisted, vec!["p0".to_string()]);      // m*l^2, once per parameter set
/// assert!(code.prepare.iter().any(|s| s.starts_with("let p0 = ")));
/// assert_eq!(code.outputs[0], "q.sin() * p0 * q.cos() + q * p0");
/// # let _ = (m, l);
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RustCode {
    /// Statements that compute the hoisted parameter-only values (they read
    /// parameters only).
    pub prepare: Vec<String>,
    /// Names bound by `prepare` that the body reads.
    pub hoisted: Vec<String>,
    /// Statements of the per-call body.
    pub body: Vec<String>,
    /// The same statements split by stage ([`EmitOptions::symbol_stage`]):
    /// `stages[s]` reads symbols of stages up to `s` only; constants are in
    /// stage 0. One entry when no symbol has a later stage.
    pub stages: Vec<Vec<String>>,
    /// One expression per root, valid after `body`.
    pub outputs: Vec<String>,
    /// Operations per call (body and outputs).
    pub ops: OpCount,
    /// Operations once per parameter set (prepare).
    pub prepare_ops: OpCount,
}

impl RustCode {
    /// A complete generic function computing all outputs at once (prepare and
    /// body together), for tests and small tools:
    /// `fn name<T: Trait>(symbols…) -> [T; N]`.
    pub fn function(&self, name: &str, scalar_trait: &str, args: &[String]) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "#[allow(clippy::all, unused_variables, unused_parens, non_snake_case)]\n\
             pub fn {name}<T: {scalar_trait}>({}) -> [T; {}] {{",
            args.iter()
                .map(|a| format!("{a}: T"))
                .collect::<Vec<_>>()
                .join(", "),
            self.outputs.len()
        );
        let mut seen = BTreeSet::new();
        for st in self.prepare.iter().chain(&self.body) {
            // A constant both sections bind is written once.
            if seen.insert(st.as_str()) {
                let _ = writeln!(s, "    {st}");
            }
        }
        let _ = writeln!(s, "    [{}]\n}}", self.outputs.join(", "));
        s
    }
}

impl RustCode {
    /// Two functions that keep the hoisting visible: `{name}_prepare(params)`
    /// returns the hoisted values, and `{name}(hoisted, params, state)`
    /// computes the outputs reading only those, the parameters and the state.
    /// A body that used a value internal to the preparation would not compile.
    pub fn split_functions(
        &self,
        name: &str,
        scalar_trait: &str,
        params: &[String],
        state: &[String],
    ) -> String {
        let h = self.hoisted.len();
        let typed = |v: &[String]| {
            v.iter()
                .map(|a| format!("{a}: T"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let mut s = String::new();
        let _ = writeln!(
            s,
            "#[allow(clippy::all, unused_variables, unused_parens, non_snake_case)]\n\
             pub fn {name}_prepare<T: {scalar_trait}>({}) -> [T; {h}] {{",
            typed(params)
        );
        for st in &self.prepare {
            let _ = writeln!(s, "    {st}");
        }
        let _ = writeln!(s, "    [{}]\n}}", self.hoisted.join(", "));
        let mut args = vec![format!("hoisted: &[T; {h}]")];
        if !params.is_empty() {
            args.push(typed(params));
        }
        if !state.is_empty() {
            args.push(typed(state));
        }
        let _ = writeln!(
            s,
            "#[allow(clippy::all, unused_variables, unused_parens, non_snake_case)]\n\
             pub fn {name}<T: {scalar_trait}>({}) -> [T; {}] {{",
            args.join(", "),
            self.outputs.len()
        );
        let _ = writeln!(s, "    let [{}] = *hoisted;", self.hoisted.join(", "));
        for st in &self.body {
            let _ = writeln!(s, "    {st}");
        }
        let _ = writeln!(s, "    [{}]\n}}", self.outputs.join(", "));
        s
    }
}

#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Prec {
    Sum = 0,
    Product = 1,
    Unary = 2,
    Atom = 3,
}

struct Writer<'a> {
    p: &'a Program,
    g: &'a Graph,
    o: &'a EmitOptions,
    /// Name of each instruction that is bound (`let`), a symbol or a constant.
    names: Vec<Option<String>>,
    used_names: BTreeSet<String>,
    hoisted: Vec<bool>,
}

impl<'a> Writer<'a> {
    fn new(p: &'a Program, g: &'a Graph, o: &'a EmitOptions) -> Writer<'a> {
        let n = p.insts.len();
        let mut used_names = BTreeSet::new();
        for (s, info) in g.symbols() {
            used_names.insert(o.symbol_text.get(&s).cloned().unwrap_or(info.name.clone()));
        }
        Writer {
            p,
            g,
            o,
            names: vec![None; n],
            used_names,
            hoisted: vec![false; n],
        }
    }

    fn symbol_text(&self, s: Symbol) -> String {
        self.o
            .symbol_text
            .get(&s)
            .cloned()
            .unwrap_or_else(|| self.g.symbol_name(s).to_string())
    }

    fn fresh(&mut self, wanted: String) -> String {
        let mut name = wanted.clone();
        let mut k = 2;
        while self.used_names.contains(&name) {
            name = format!("{wanted}_{k}");
            k += 1;
        }
        self.used_names.insert(name.clone());
        name
    }

    /// A readable name for a bound instruction when one is obvious.
    fn suggest(&self, i: usize) -> Option<String> {
        let leaf = |j: u32| -> Option<String> {
            match &self.p.insts[j as usize] {
                Inst::Symbol(s) => Some(self.symbol_text(*s)),
                _ => self.names[j as usize].clone(),
            }
        };
        let ident = |s: String| {
            (s.len() <= 24 && s.chars().all(|c| c.is_alphanumeric() || c == '_')).then_some(s)
        };
        match self.p.insts[i] {
            Inst::Call(f, a) => ident(format!("{}_{}", f.name(), leaf(a)?)),
            Inst::Mul(a, b) if a == b => ident(format!("{}_sq", leaf(a)?)),
            Inst::Atan2(y, x) => ident(format!("atan2_{}_{}", leaf(y)?, leaf(x)?)),
            _ => None,
        }
    }

    fn constant_name(n: Number) -> String {
        match n {
            Number::Rational { num, den: 1 } => format!("k{num}").replace('-', "m"),
            Number::Rational { num, den } => format!("k{num}_{den}").replace('-', "m"),
            // Floats get a short name; the literal is in the binding.
            Number::Float(_) => "kf".to_string(),
        }
    }

    fn literal(n: Number) -> String {
        let x = n.to_f64();
        format!("{x:?}")
    }

    fn write(mut self) -> RustCode {
        let n = self.p.insts.len();
        let p = self.p;
        // Decide what is hoisted: parameter-only, non-leaf instructions read by
        // a per-call instruction or an output.
        let nontrivial = |i: usize| !matches!(p.insts[i], Inst::Const(_) | Inst::Symbol(_));
        let mut boundary = vec![false; n];
        if self.o.hoist_parameters {
            for i in 0..n {
                if !p.parameter_only[i] {
                    for op in p.insts[i].operands() {
                        boundary[op as usize] = true;
                    }
                }
            }
            for &o in &p.outputs {
                boundary[o as usize] = true;
            }
            for (i, h) in self.hoisted.iter_mut().enumerate() {
                *h = p.parameter_only[i] && nontrivial(i);
            }
        }
        // Which instructions get a `let`.
        let mut bind = vec![false; n];
        for i in 0..n {
            if !nontrivial(i) {
                continue;
            }
            let shared = p.uses[i] >= 2;
            bind[i] = (self.o.cse && shared) || (self.hoisted[i] && boundary[i]);
        }
        // Long chains (a sum of hundreds of terms) are cut by a `let` every
        // few levels, so no written expression nests deeper than
        // MAX_INLINE_DEPTH (the writer recurses on nesting, and deep lines do
        // not read).
        let mut depth = vec![0usize; n];
        for i in 0..n {
            if !nontrivial(i) || bind[i] {
                continue;
            }
            let d = 1 + p.insts[i]
                .operands()
                .iter()
                .map(|&o| depth[o as usize])
                .max()
                .unwrap_or(0);
            if d > MAX_INLINE_DEPTH {
                bind[i] = true;
            } else {
                depth[i] = d;
            }
        }
        // The stage of each instruction: the latest of its symbols'.
        let mut stage = vec![0usize; n];
        for i in 0..n {
            stage[i] = match p.insts[i] {
                Inst::Symbol(s) => self.o.symbol_stage.get(&s).copied().unwrap_or(0),
                ref other => other
                    .operands()
                    .iter()
                    .map(|&o| stage[o as usize])
                    .max()
                    .unwrap_or(0),
            };
        }
        let stage_count = 1 + stage.iter().copied().max().unwrap_or(0);
        let mut staged: Vec<Vec<String>> = vec![Vec::new(); stage_count];
        let mut prepare = Vec::new();
        let mut body = Vec::new();
        let mut hoisted_names = Vec::new();
        // Constants: bound once at the top of the section that first needs them.
        let mut const_names: BTreeMap<usize, String> = BTreeMap::new();
        for i in 0..n {
            if let Inst::Const(c) = p.insts[i] {
                let name = self.fresh(Self::constant_name(c));
                const_names.insert(i, name.clone());
                self.names[i] = Some(name);
            }
        }
        let mut const_in_prepare = BTreeSet::new();
        let mut const_in_body = BTreeSet::new();
        let mut counter_p = 0;
        let mut counter_t = 0;
        let mut body_ops = OpCount::default();
        let mut prepare_ops = OpCount::default();
        // Count operations: bound instructions once; inlined ones once per
        // inline use when CSE is off (their text is repeated).
        let mult = if self.o.cse {
            vec![1usize; n]
        } else {
            p.tree_multiplicity()
        };
        for (i, inst) in p.insts.iter().enumerate() {
            if self.hoisted[i] {
                prepare_ops.count(inst, if bind[i] { 1 } else { mult[i] });
            } else {
                body_ops.count(inst, if bind[i] { 1 } else { mult[i] });
            }
        }
        for i in 0..n {
            if !bind[i] {
                continue;
            }
            let wanted = self.suggest(i).unwrap_or_else(|| {
                if self.hoisted[i] {
                    counter_p += 1;
                    format!("p{}", counter_p - 1)
                } else {
                    counter_t += 1;
                    format!("t{}", counter_t - 1)
                }
            });
            let (text, _) = self.expr_inline(i);
            let name = self.fresh(wanted);
            let consts = self.constants_of(i, &bind);
            if self.hoisted[i] {
                for c in consts {
                    if const_in_prepare.insert(c) {
                        prepare.push(self.const_stmt(c, &const_names));
                    }
                }
                prepare.push(format!("let {name} = {text};"));
                if boundary[i] {
                    hoisted_names.push(name.clone());
                }
            } else {
                for c in consts {
                    if const_in_body.insert(c) {
                        let st = self.const_stmt(c, &const_names);
                        staged[0].push(st.clone());
                        body.push(st);
                    }
                }
                staged[stage[i]].push(format!("let {name} = {text};"));
                body.push(format!("let {name} = {text};"));
            }
            self.names[i] = Some(name);
        }
        let mut outputs = Vec::new();
        for k in 0..p.outputs.len() {
            let o = p.outputs[k] as usize;
            for c in self.constants_of(o, &bind) {
                if const_in_body.insert(c) {
                    let st = self.const_stmt(c, &const_names);
                    staged[0].push(st.clone());
                    body.push(st);
                }
            }
            outputs.push(self.expr(o).0);
        }
        // Constants first in each section (stable order by instruction).
        let split = |v: Vec<String>| {
            let (mut c, rest): (Vec<String>, Vec<String>) =
                v.into_iter().partition(|s| s.starts_with("let k"));
            c.extend(rest);
            c
        };
        RustCode {
            prepare: split(prepare),
            hoisted: hoisted_names,
            body: split(body),
            stages: staged.into_iter().map(split).collect(),
            outputs,
            ops: body_ops,
            prepare_ops,
        }
    }

    fn const_stmt(&self, i: usize, names: &BTreeMap<usize, String>) -> String {
        let Inst::Const(c) = self.p.insts[i] else {
            unreachable!("constant")
        };
        let text = self
            .o
            .constant
            .replace("{ty}", &self.o.scalar)
            .replace("{lit}", &Self::literal(c));
        format!("let {}: {} = {text};", names[&i], self.o.scalar)
    }

    /// Constants read by the inline text of instruction `i`.
    fn constants_of(&self, i: usize, bind: &[bool]) -> Vec<usize> {
        let mut out = Vec::new();
        let mut stack = self.p.insts[i].operands();
        if matches!(self.p.insts[i], Inst::Const(_)) {
            out.push(i);
        }
        while let Some(j) = stack.pop() {
            let j = j as usize;
            match self.p.insts[j] {
                Inst::Const(_) => out.push(j),
                _ if bind[j] => {}
                Inst::Symbol(_) => {}
                _ => stack.extend(self.p.insts[j].operands()),
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The text of instruction `i` as used by another (its name when bound).
    fn expr(&self, i: usize) -> (String, Prec) {
        if let Some(n) = &self.names[i] {
            return (n.clone(), Prec::Atom);
        }
        if let Inst::Symbol(s) = self.p.insts[i] {
            return (self.symbol_text(s), Prec::Atom);
        }
        self.expr_inline(i)
    }

    /// The operands of a commutative operation, ordered so that a nested
    /// operation of the same level stands on the left, where it needs no
    /// parentheses (`a * b` and `b * a` are the same IEEE value).
    fn commuted(&self, a: u32, b: u32, level: Prec) -> ((String, Prec), (String, Prec)) {
        let (l, r) = (self.expr(a as usize), self.expr(b as usize));
        if r.1 == level && l.1 != level {
            (r, l)
        } else {
            (l, r)
        }
    }

    /// The factors of instruction `i` when it is a product written inline
    /// (not bound), so a sum reading it can fuse it.
    fn inline_product(&self, i: u32) -> Option<(u32, u32)> {
        match self.p.insts[i as usize] {
            Inst::Mul(a, b) if self.names[i as usize].is_none() => Some((a, b)),
            _ => None,
        }
    }

    /// `x.fused_mul_add(y, z)` for a sum or difference with an inline
    /// product operand: a + x·y, x·y + b, a − x·y as (−x)·y + a, and
    /// x·y − b as x·y + (−b).
    fn fused_inline(&self, i: usize) -> Option<String> {
        let atom = |j: u32| {
            let (s, p) = self.expr(j as usize);
            if p < Prec::Atom {
                format!("({s})")
            } else {
                s
            }
        };
        let arg = |j: u32| self.expr(j as usize).0;
        let fused = |x: String, y: u32, z: String| format!("{x}.fused_mul_add({}, {z})", arg(y));
        match self.p.insts[i] {
            Inst::Add(a, b) => {
                if let Some((x, y)) = self.inline_product(b) {
                    Some(fused(atom(x), y, arg(a)))
                } else {
                    let (x, y) = self.inline_product(a)?;
                    Some(fused(atom(x), y, arg(b)))
                }
            }
            Inst::Sub(a, b) => {
                if let Some((x, y)) = self.inline_product(b) {
                    Some(fused(format!("(-{})", atom(x)), y, arg(a)))
                } else {
                    let (x, y) = self.inline_product(a)?;
                    Some(fused(atom(x), y, format!("-{}", atom(b))))
                }
            }
            _ => None,
        }
    }

    /// The text of instruction `i` itself.
    fn expr_inline(&self, i: usize) -> (String, Prec) {
        let wrap = |(s, p): (String, Prec), min: Prec| {
            if p < min {
                format!("({s})")
            } else {
                s
            }
        };
        let right = |(s, p): (String, Prec), level: Prec| {
            if p <= level {
                format!("({s})")
            } else {
                s
            }
        };
        if self.o.fused {
            if let Some(text) = self.fused_inline(i) {
                return (text, Prec::Atom);
            }
        }
        match self.p.insts[i] {
            Inst::Const(_) | Inst::Symbol(_) => self.expr(i),
            Inst::Add(a, b) => {
                let (l, r) = self.commuted(a, b, Prec::Sum);
                (
                    format!("{} + {}", wrap(l, Prec::Sum), right(r, Prec::Sum)),
                    Prec::Sum,
                )
            }
            Inst::Sub(a, b) => (
                format!(
                    "{} - {}",
                    wrap(self.expr(a as usize), Prec::Sum),
                    right(self.expr(b as usize), Prec::Sum)
                ),
                Prec::Sum,
            ),
            Inst::Mul(a, b) => {
                let (l, r) = self.commuted(a, b, Prec::Product);
                (
                    format!("{} * {}", wrap(l, Prec::Product), right(r, Prec::Product)),
                    Prec::Product,
                )
            }
            Inst::Div(a, b) => (
                format!(
                    "{} / {}",
                    wrap(self.expr(a as usize), Prec::Product),
                    right(self.expr(b as usize), Prec::Product)
                ),
                Prec::Product,
            ),
            Inst::Neg(a) => (
                format!("-{}", wrap(self.expr(a as usize), Prec::Atom)),
                Prec::Unary,
            ),
            Inst::Powi(a, e) => (
                format!("{}.powi({e})", wrap(self.expr(a as usize), Prec::Atom)),
                Prec::Atom,
            ),
            Inst::Call(f, a) => (
                format!("{}.{}()", wrap(self.expr(a as usize), Prec::Atom), f.name()),
                Prec::Atom,
            ),
            Inst::Atan2(y, x) => (
                format!(
                    "{}.atan2({})",
                    wrap(self.expr(y as usize), Prec::Atom),
                    self.expr(x as usize).0
                ),
                Prec::Atom,
            ),
        }
    }
}

impl Graph {
    /// Operation count of the emitted code for `roots`, with shared
    /// subexpressions computed once (parameter-only work included).
    pub fn op_count(&self, roots: &[Id]) -> Result<OpCount> {
        Ok(Program::lower(self, roots).op_count())
    }
}

#[cfg(test)]
mod stage_tests {
    use super::*;
    use crate::graph::SymbolKind;

    #[test]
    fn statements_are_split_by_the_latest_stage_they_read() {
        let mut g = Graph::new();
        let _q = g.coordinate("q").unwrap();
        let x = g.declare("x", SymbolKind::Auxiliary).unwrap();
        let w = g.declare("w", SymbolKind::Auxiliary).unwrap();
        // sin(q)·cos(q) is shared by every stage; x·sin(q)·cos(q) by the
        // last two; w reads both.
        let a = g.parse("sin(q)*cos(q) + q").unwrap();
        let b = g.parse("sin(q)*cos(q)*x + x^2").unwrap();
        let c = g
            .parse("(sin(q)*cos(q)*x + x^2)*w + w^2 + sin(q)*cos(q)")
            .unwrap();
        let p = Program::lower(&g, &[a, b, c]);
        let mut o = EmitOptions::default();
        o.symbol_stage.insert(x, 1);
        o.symbol_stage.insert(w, 2);
        let code = p.to_rust(&g, &o);
        assert_eq!(code.stages.len(), 3);
        let mut all: Vec<String> = code.stages.concat();
        let mut body = code.body.clone();
        all.sort();
        body.sort();
        assert_eq!(all, body, "the stages hold exactly the body's statements");
        let mentions = |v: &[String], name: &str| {
            v.iter().any(|s| {
                s.split(|c: char| !c.is_alphanumeric() && c != '_')
                    .any(|t| t == name)
            })
        };
        assert!(!mentions(&code.stages[0], "x") && !mentions(&code.stages[0], "w"));
        assert!(!mentions(&code.stages[1], "w"));
        assert!(mentions(&code.stages[0], "q"));
        // Without stages, one stage holds everything.
        let plain = p.to_rust(&g, &EmitOptions::default());
        assert_eq!(plain.stages.len(), 1);
        assert_eq!(plain.stages[0], plain.body);
    }
}

#[cfg(test)]
mod sharing_tests {
    use super::*;

    fn values(g: &Graph) -> impl Fn(Symbol) -> Option<f64> + '_ {
        |s| {
            Some(match g.symbol_name(s) {
                "x" => 0.7,
                "y" => -1.3,
                "z" => 2.1,
                "w" => 0.4,
                "d" => 1.9,
                "p" => 3.0,
                "q" => -0.5,
                name if name.len() == 2 && name.starts_with('v') => {
                    0.1 + name.as_bytes()[1] as f64 / 50.0
                }
                _ => return None,
            })
        }
    }

    fn check(g: &mut Graph, texts: &[&str]) -> Program {
        let roots: Vec<Id> = texts.iter().map(|t| g.parse(t).unwrap()).collect();
        let p = Program::lower(g, &roots);
        let got = p.eval(&values(g)).unwrap();
        let expected = crate::eval::Tape::new(g, &roots).eval(&values(g)).unwrap();
        for (a, b) in got.iter().zip(&expected) {
            assert!((a - b).abs() <= 1e-14 * b.abs().max(1.0), "{a} vs {b}");
        }
        p
    }

    #[test]
    fn products_sharing_two_factors_share_their_product() {
        let mut g = Graph::new();
        // x·y is found in three products: computed once, each product then
        // costs one more multiplication (4 in all, against 6).
        let p = check(&mut g, &["x*y*z", "x*y*w", "x*y*z*w + z"]);
        let ops = p.op_count();
        assert_eq!(ops.mul, 4, "{ops}");
        assert_eq!(ops.add, 1, "{ops}");
    }

    #[test]
    fn parameter_only_factors_stay_one_hoisted_value() {
        let mut g = Graph::new();
        g.parameter("p").unwrap();
        g.parameter("q").unwrap();
        let p = check(&mut g, &["p*q*sin(x)", "p*q*cos(x)*y"]);
        // p·q is one parameter-only value, multiplied in at run time once
        // per product.
        let state_muls = p
            .insts()
            .iter()
            .enumerate()
            .filter(|(i, inst)| matches!(inst, Inst::Mul(..)) && !p.parameter_only[*i])
            .count();
        assert_eq!(state_muls, 3);
        assert!(p
            .insts()
            .iter()
            .enumerate()
            .any(|(i, inst)| matches!(inst, Inst::Mul(..)) && p.parameter_only[i]));
    }

    #[test]
    fn a_shared_denominator_is_taken_out_of_a_sum() {
        let mut g = Graph::new();
        // x/d + y/d + z → (x + y)/d + z: one division, two additions.
        let p = check(&mut g, &["x/d + y/d + z"]);
        let ops = p.op_count();
        assert_eq!((ops.div, ops.add, ops.mul), (1, 2, 0), "{ops}");
    }

    #[test]
    fn sums_sharing_two_terms_share_their_sum() {
        let mut g = Graph::new();
        // x + y is found in three sums (once with the opposite sign):
        // computed once, then one operation per sum (4 in all, against 6).
        // The third sum is the second's negation, and may be written so.
        let p = check(
            &mut g,
            &[
                "sin(x) + cos(y) + z",
                "sin(x) + cos(y) - w",
                "w - sin(x) - cos(y)",
            ],
        );
        let ops = p.op_count();
        assert_eq!(ops.add + ops.neg, 4, "{ops}");
    }

    #[test]
    fn terms_with_the_same_state_factors_share_one_parameter_sum() {
        let mut g = Graph::new();
        g.parameter("p").unwrap();
        g.parameter("q").unwrap();
        // p·x·y + q·x·y + z → (p + q)·(x·y) + z: two multiplications and
        // one addition at run time, p + q hoisted.
        let p = check(&mut g, &["p*sin(x)*y + q*y*sin(x) + z"]);
        let run_time = |want: fn(&Inst) -> bool| {
            p.insts()
                .iter()
                .enumerate()
                .filter(|(i, inst)| want(inst) && !p.parameter_only[*i])
                .count()
        };
        assert_eq!(run_time(|i| matches!(i, Inst::Mul(..))), 2);
        assert_eq!(run_time(|i| matches!(i, Inst::Add(..) | Inst::Sub(..))), 1);
    }

    #[test]
    fn a_value_added_and_subtracted_cancels() {
        let mut g = Graph::new();
        // (sin y + z)·w and w·sin y + w·z are different nodes that lower to
        // one value: their difference is no work at all.
        let p = check(&mut g, &["(sin(y) + z)*w - w*sin(y) - w*z + x*d"]);
        let ops = p.op_count();
        assert_eq!(ops.total(), 1, "{ops}");
    }

    #[test]
    fn terms_added_and_subtracted_cancel_between_instructions() {
        let mut g = Graph::new();
        let [x, y, z] = ["x", "y", "z"].map(|n| g.declare(n, SymbolKind::Auxiliary).unwrap());
        use Inst::*;
        // t = x·x − 1 shared; z·(t − x·x) is −z and y·(x·x − t) is y: the
        // bicycle's front-contact rows had both (its rhs 991 → 968 ops).
        let insts = vec![
            Symbol(x),
            Symbol(y),
            Symbol(z),
            Const(Number::ONE),
            Mul(0, 0),
            Sub(4, 3),
            Sub(5, 4),
            Mul(2, 6),
            Sub(4, 5),
            Mul(1, 8),
            // (x + y) − x is y, and (y − z) + z is y.
            Add(0, 1),
            Sub(10, 0),
            Sub(1, 2),
            Add(12, 2),
            Mul(11, 13),
        ];
        let outputs = vec![7, 9, 14];
        let (after, outs) = prune_pair(share_equal_values(&g, insts, outputs));
        let program = Program {
            parameter_only: vec![false; after.len()],
            uses: use_counts(&after, &outs),
            insts: after,
            outputs: outs,
        };
        let got = program.eval(&values(&g)).unwrap();
        assert_eq!(got, vec![-2.1, -1.3, 1.3 * 1.3]);
        let ops = program.op_count();
        // −z, y as is, and y·y: one negation and one product.
        assert_eq!(
            (ops.neg, ops.mul, ops.add, ops.total()),
            (1, 1, 0, 2),
            "{ops}"
        );
    }

    #[test]
    fn a_value_computed_in_two_forms_is_computed_once() {
        let mut g = Graph::new();
        let [x, y] = ["x", "y"].map(|n| g.declare(n, SymbolKind::Auxiliary).unwrap());
        use Inst::*;
        let insts = vec![
            Symbol(x),
            Symbol(y),
            // (x + y)(x − y), x·x − y·y and y·y − x·x.
            Add(0, 1),
            Sub(0, 1),
            Mul(2, 3),
            Mul(0, 0),
            Mul(1, 1),
            Sub(5, 6),
            Sub(6, 5),
            // √(x·x)·√(x·x) equals x·x but reads a square root: kept.
            Call(Func::Sqrt, 5),
            Mul(9, 9),
        ];
        let outputs = vec![4, 7, 8, 10, 5];
        let (after, outs) = prune_pair(share_equal_values(&g, insts, outputs));
        assert_eq!(outs[1], outs[0], "{after:?}");
        assert_eq!(after[outs[2] as usize], Neg(outs[0]), "{after:?}");
        assert_ne!(outs[3], outs[4], "{after:?}");
        assert!(matches!(after[outs[3] as usize], Mul(..)), "{after:?}");
    }

    #[test]
    fn an_equal_earlier_form_that_reads_more_is_not_used() {
        let mut g = Graph::new();
        let p = g.parameter("p").unwrap();
        let x = g.declare("x", SymbolKind::Coordinate).unwrap();
        let a = g.declare("a", SymbolKind::Auxiliary).unwrap();
        use Inst::*;
        let insts = vec![
            Symbol(p),
            Symbol(x),
            Symbol(a),
            // (p + x)·p − x·p reads the state; p·p, later, is computed once
            // per parameter set and stays so.
            Add(0, 1),
            Mul(3, 0),
            Mul(1, 0),
            Sub(4, 5),
            Mul(0, 0),
            // (x + a)·x − a·x reads the unknown a of a later stage; x·x,
            // later, must not wait for it.
            Add(1, 2),
            Mul(8, 1),
            Mul(2, 1),
            Sub(9, 10),
            Mul(1, 1),
            // (x·x + a) − a reads x and a, like both forms of x·x before
            // it: either may stand for it.
            Add(12, 2),
            Sub(13, 2),
        ];
        let outputs = vec![6, 7, 11, 12, 14];
        let (after, outs) = prune_pair(share_equal_values(&g, insts, outputs));
        assert_ne!(outs[1], outs[0], "{after:?}");
        assert_eq!(after[outs[1] as usize], Mul(0, 0), "{after:?}");
        assert_ne!(outs[3], outs[2], "{after:?}");
        assert!([outs[2], outs[3]].contains(&outs[4]), "{after:?}");
        assert_eq!(after.len(), 13, "{after:?}");
    }

    #[test]
    fn negations_are_absorbed_by_their_readers() {
        let mut g = Graph::new();
        let [x, y, z, w] =
            ["x", "y", "z", "w"].map(|n| g.declare(n, SymbolKind::Auxiliary).unwrap());
        // w + ((−x) − y)·z and w − ((−x) − y)·x: the sign of −x passes
        // through the difference and the products to the sums.
        use Inst::*;
        let insts = vec![
            Symbol(x),
            Symbol(y),
            Symbol(z),
            Symbol(w),
            Neg(0),
            Sub(4, 1),
            Mul(5, 2),
            Add(3, 6),
            Mul(0, 5),
            Sub(3, 8),
        ];
        let program = |insts: Vec<Inst>, outputs: Vec<u32>| Program {
            parameter_only: vec![false; insts.len()],
            uses: use_counts(&insts, &outputs),
            insts,
            outputs,
        };
        let before = program(insts.clone(), vec![7, 9]);
        let (insts, outputs) = absorb_negations(insts, vec![7, 9]);
        let after = program(insts, outputs);
        assert_eq!(before.eval(&values(&g)), after.eval(&values(&g)));
        let ops = after.op_count();
        assert_eq!((ops.neg, ops.total()), (0, 5), "{ops}");
        // An output keeps its sign: nothing to absorb into.
        let (insts, _) = absorb_negations(vec![Symbol(x), Neg(0)], vec![1]);
        assert_eq!(insts[1], Neg(0));
        // w·(x − y) + z·(y − x): y − x is −(x − y), and the sum subtracts.
        let insts = vec![
            Symbol(x),
            Symbol(y),
            Symbol(z),
            Symbol(w),
            Sub(0, 1),
            Mul(3, 4),
            Sub(1, 0),
            Mul(2, 6),
            Add(5, 7),
        ];
        let before = program(insts.clone(), vec![8]);
        let (insts, outputs) = absorb_negations(insts, vec![8]);
        let after = program(insts, outputs);
        assert_eq!(before.eval(&values(&g)), after.eval(&values(&g)));
        let ops = after.op_count();
        assert_eq!((ops.add, ops.mul), (2, 2), "{ops}");
    }

    #[test]
    fn a_merged_parameter_part_shared_by_terms_is_taken_out() {
        let mut g = Graph::new();
        g.parameter("p").unwrap();
        g.parameter("q").unwrap();
        // (p + q)·sin x + (p + q)·cos y, each parameter sum merged from two
        // terms: (p + q)·(sin x + cos y), the sum hoisted.
        let p = check(&mut g, &["p*sin(x) + q*sin(x) + p*cos(y) + q*cos(y)"]);
        let ops = p.op_count();
        assert_eq!((ops.mul, ops.add), (1, 2), "{ops}");
    }

    #[test]
    fn a_parameter_shared_by_several_terms_is_taken_out() {
        let mut g = Graph::new();
        g.parameter("p").unwrap();
        // p·x + p·y + p·z → p·(x + y + z): one multiplication.
        let p = check(&mut g, &["p*sin(x) + p*cos(y) + p*z"]);
        let ops = p.op_count();
        assert_eq!((ops.mul, ops.add), (1, 2), "{ops}");
    }

    /// The longest chain of [`latency`] through the program.
    fn critical_path(p: &Program) -> u32 {
        let mut ready: Vec<u32> = Vec::new();
        for inst in p.insts() {
            let start = inst.operands().iter().map(|&o| ready[o as usize]).max();
            ready.push(start.unwrap_or(0) + latency(inst));
        }
        p.outputs()
            .iter()
            .map(|&o| ready[o as usize])
            .max()
            .unwrap_or(0)
    }

    #[test]
    fn a_long_sum_is_added_in_parallel_running_sums() {
        let mut g = Graph::new();
        // Ten products of twenty different factors: nothing to factor out.
        let text = "va*vb + vc*vd + ve*vf + vg*vh + vi*vj + vk*vl + vm*vn + vo*vp + vq*vr + vs*vt";
        let p = check(&mut g, &[text]);
        let ops = p.op_count();
        // Ten products and nine additions, as written.
        assert_eq!((ops.mul, ops.add), (10, 9), "{ops}");
        // A chain would take 4 + 9 · 4 = 40 cycles; running sums of about
        // three terms each, added pairwise, take 24.
        assert!(critical_path(&p) <= 24, "{}", critical_path(&p));
    }

    #[test]
    fn a_late_term_joins_the_sum_last() {
        let mut g = Graph::new();
        let p = check(&mut g, &["x + y + z + sin(w)"]);
        // sin(w) is ready at 60 (the model's call latency): x + y + z are
        // summed meanwhile and sin(w) is added once, at the end.
        assert_eq!(critical_path(&p), 64);
        let last = *p.outputs().last().unwrap();
        let Inst::Add(a, b) = p.insts()[last as usize] else {
            panic!("{:?}", p.insts()[last as usize]);
        };
        assert!([a, b]
            .iter()
            .any(|&o| matches!(p.insts()[o as usize], Inst::Call(Func::Sin, _))));
    }

    #[test]
    fn signs_survive_reassociation() {
        let mut g = Graph::new();
        // Differences of every shape, some parameter-only terms among them.
        g.parameter("p").unwrap();
        g.parameter("q").unwrap();
        let p = check(
            &mut g,
            &[
                "x - y - z*w + d - p + q*x - (y - w) - sin(z)",
                "p - x*y - z*d - w",
            ],
        );
        assert_eq!(p.op_count().neg, 0);
    }
}
