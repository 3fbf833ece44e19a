//! Lowering: the canonical n-ary graph becomes binary instructions (`+ − ×
//! ÷`, negation, integer powers by repeated squaring, function calls),
//! hash-consed so that e.g. `x²` is computed once for `x³` and `x⁴`. Sums
//! are written with their common factors taken out and their parameter-only
//! parts merged, products with their parameter-only factors grouped into one
//! hoistable value.

use crate::graph::{Func, FxHashMap, Graph, Id, Node};
use crate::number::Number;

use super::inst::Inst;

/// Lowers the expressions `roots` of `graph`: the instructions, and the
/// instruction of each root. Forms that ended up unused (a sum's terms
/// before their common factors were taken out) are still there; the
/// [`Pass::Prune`](super::Pass::Prune) pass drops them.
pub(super) fn lower(graph: &Graph, roots: &[Id]) -> (Vec<Inst>, Vec<u32>) {
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
    (l.insts, outputs)
}

/// Exponents up to this are computed by multiplication chains.
const MAX_CHAIN_EXPONENT: i32 = 64;

/// The longest nested sum [`Lowering::flatten`] distributes.
const MAX_DISTRIBUTED: usize = 8;

/// A term of a sum: coefficient, factors, and a parameter-only value
/// multiplied in (the merged parameter parts of terms that shared their
/// state-dependent factors).
type Term = (Number, Vec<(Id, i32)>, Option<u32>);

/// The lowering of one graph in progress.
struct Lowering<'g> {
    graph: &'g Graph,
    /// How many nodes (and roots) read each node.
    readers: FxHashMap<Id, u32>,
    /// The instructions so far.
    insts: Vec<Inst>,
    /// Each instruction's index, so that an instruction is pushed once.
    index: FxHashMap<Inst, u32>,
    /// The instruction each lowered node became.
    memo: FxHashMap<Id, u32>,
}

impl Lowering<'_> {
    /// The index of `inst` (commutative operands in order), pushed unless
    /// an equal instruction is there already.
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

    /// The instruction of a constant.
    fn constant(&mut self, n: Number) -> u32 {
        self.push(Inst::Const(n))
    }

    /// `bᵉ` for `e ≥ 1`: repeated squaring up to [`MAX_CHAIN_EXPONENT`],
    /// a `powi` beyond.
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

    /// `items` combined left to right by `op`; None for no items.
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
        let terms = self.collect_parameters(terms);
        if terms.len() >= 2 {
            if let Some((base, inverse)) = self.common_factor(&terms) {
                return self.take_out(constant, terms, base, inverse);
            }
        }
        self.chain_terms(constant, terms)
    }

    /// The factor [`Lowering::sum`] takes out of `terms` first, as its
    /// lowered value and whether the terms divide by it; None when no factor
    /// is in two terms or more.
    fn common_factor(&self, terms: &[Term]) -> Option<(u32, bool)> {
        // The factor (not parameter-only: those are hoisted anyway) that
        // the most terms contain; ties go to the smallest id.
        // Counted by lowered value: two nodes may lower to one value.
        // A parameter-only factor counts too (it is hoisted, but each
        // term still multiplies by it), after a state factor as often
        // found.
        // All (value, divides, is state) pairs, once per term, sorted:
        // runs of one pair count the terms that have it.
        let mut seen: Vec<(u32, bool, bool)> = Vec::new();
        for (_, factors, extra) in terms {
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
        best.map(|(_, key)| key)
    }

    /// `constant + Σ terms` with `base` (its reciprocal if `inverse`) taken
    /// out of the terms that have it: `base·(Σ reduced) + Σ others`, each
    /// part a [`Lowering::sum`] again.
    fn take_out(&mut self, constant: Number, terms: Vec<Term>, base: u32, inverse: bool) -> u32 {
        let step = if inverse { 1 } else { -1 };
        let memo = &self.memo;
        let is_f = |b: Id, e: i32| memo[&b] == base && (e < 0) == inverse;
        let (with, without): (Vec<_>, Vec<_>) = terms.into_iter().partition(|(_, fs, extra)| {
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
        self.push(Inst::Add(grouped, rest))
    }

    /// `constant + Σ terms` with no factor to take out: the parameter-only
    /// terms first (so their partial sum is hoistable), then the others in
    /// order, each added, or subtracted when its sign cannot join a
    /// parameter-only factor.
    fn chain_terms(&mut self, constant: Number, terms: Vec<Term>) -> u32 {
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

    /// The instruction of node `id`, whose children are lowered already.
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
            Node::Fun(Func::Hold, a) => self.memo[a],
            Node::Fun(f, a) => {
                let a = self.memo[a];
                self.push(Inst::Call(*f, a))
            }
            Node::Atan2(y, x) => {
                let (y, x) = (self.memo[y], self.memo[x]);
                self.push(Inst::Atan2(y, x))
            }
            Node::Powf(x, y) => {
                let (x, y) = (self.memo[x], self.memo[y]);
                self.push(Inst::Powf(x, y))
            }
            Node::Select(c, a, b) => {
                let (c, a, b) = (self.memo[c], self.memo[a], self.memo[b]);
                self.push(Inst::Select(c, a, b))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::emit::tests::check;
    use crate::emit::{Inst, Program};
    use crate::graph::Graph;

    #[test]
    fn held_sums_keep_a_recursion_from_multiplying_out() {
        // A velocity handed down a chain of turns, as a tree's recursions
        // do: each level is the previous one turned and shifted. Unheld,
        // each level's terms are multiplied into the next level's products
        // (2, 4, 8, ... terms; the lowering takes common factors out again,
        // not all of them); held, each level is one factor of the next.
        let mut g = Graph::new();
        let chain = |g: &mut Graph, hold: bool| {
            let mut v = [g.parse("x").unwrap(), g.parse("y").unwrap()];
            for k in 0..5 {
                let (c, s) = (
                    g.parse(&format!("cos(v{k})")).unwrap(),
                    g.parse(&format!("sin(v{k})")).unwrap(),
                );
                let a = g.mul(c, v[0]).unwrap();
                let b = g.mul(s, v[1]).unwrap();
                let e = g.mul(s, v[0]).unwrap();
                let f = g.mul(c, v[1]).unwrap();
                let three = g.int(3).unwrap();
                let shift = g.mul(three, v[1]).unwrap();
                v = [g.sub(a, b).unwrap(), g.add(e, f).unwrap()];
                v[0] = g.add(v[0], shift).unwrap();
                if hold {
                    v = [g.hold(v[0]).unwrap(), g.hold(v[1]).unwrap()];
                }
            }
            v
        };
        let spread = chain(&mut g, false);
        let kept = chain(&mut g, true);
        let count = |roots: &[crate::graph::Id]| Program::lower(&g, roots).op_count().total();
        assert!(
            count(&kept) < count(&spread),
            "{} against {}",
            count(&kept),
            count(&spread)
        );
        let at = crate::emit::tests::values(&g);
        let value = |roots: &[crate::graph::Id]| Program::lower(&g, roots).eval(&at).unwrap();
        for (a, b) in value(&kept).iter().zip(value(&spread)) {
            assert!((a - b).abs() <= 1e-13 * b.abs().max(1.0), "{a} vs {b}");
        }
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
}
