//! [`Pass::ShareSums`](super::Pass::ShareSums): sums that share two terms
//! share their sum.

use crate::graph::{FxHashMap, Graph};
use crate::number::Number;

use super::super::inst::{parameter_only_flags, use_counts, Inst};
use super::pairs::{share_pairs, shared_value};
use super::rewrite;

/// Sums that share two terms share their sum (`a + b + c, a + b − d →
/// t = a + b; t + c, t − d`; `a − b` and `b − a` share one subtraction):
/// each maximal tree of additions and subtractions is read as its signed
/// terms, and the pair of terms found in the most trees becomes one
/// operation, greedily, while some pair is found in two trees or more.
pub(super) fn share_sums(
    graph: &Graph,
    insts: Vec<Inst>,
    outputs: Vec<u32>,
) -> (Vec<Inst>, Vec<u32>) {
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
        let (kept, c) = signed_terms(&insts, &interior, i);
        cancelled |= c;
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
        Some(signed_sum(out, pos, neg))
    })
}

/// The signed terms (id, negated) of the tree of additions, subtractions
/// and negations rooted at instruction `i`, and whether some cancelled.
fn signed_terms(insts: &[Inst], interior: &[bool], i: usize) -> (Vec<(u32, bool)>, bool) {
    let mut cancelled = false;
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
    (kept, cancelled)
}

/// `Σ pos − Σ neg` appended to `out`, as a chain of additions then
/// subtractions; returns its index.
fn signed_sum(out: &mut Vec<Inst>, pos: Vec<u32>, mut neg: Vec<u32>) -> u32 {
    if pos.is_empty() && neg.is_empty() {
        out.push(Inst::Const(Number::ZERO));
        return (out.len() - 1) as u32;
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
    acc
}

#[cfg(test)]
mod tests {
    use crate::emit::tests::check;
    use crate::graph::Graph;

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
    fn a_value_added_and_subtracted_cancels() {
        let mut g = Graph::new();
        // (sin y + z)·w and w·sin y + w·z are different nodes that lower to
        // one value: their difference is no work at all.
        let p = check(&mut g, &["(sin(y) + z)*w - w*sin(y) - w*z + x*d"]);
        let ops = p.op_count();
        assert_eq!(ops.total(), 1, "{ops}");
    }
}
