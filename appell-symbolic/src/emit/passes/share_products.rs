//! [`Pass::ShareProducts`](super::Pass::ShareProducts): products that
//! share two factors share their product.

use crate::graph::{FxHashMap, Graph};
use crate::number::Number;

use super::super::inst::{parameter_only_flags, use_counts, Inst};
use super::pairs::{share_pairs, shared_value};
use super::rewrite;

/// Products that share two factors share their product
/// (`a·b·c, a·b·d → t = a·b; t·c, t·d`): each maximal tree of
/// multiplications is read as its multiset of factors, and the pair of
/// factors found in the most trees becomes one multiplication, greedily,
/// while some pair is found in two trees or more. Reassociating a product
/// changes its rounding by a few half-ulps at most (no cancellation).
pub(super) fn share_products(
    graph: &Graph,
    insts: Vec<Inst>,
    outputs: Vec<u32>,
) -> (Vec<Inst>, Vec<u32>) {
    let n = insts.len();
    // Parameter-only values are hoisted: they stay whole, and the
    // parameter-only factors of a product stay one (hoisted) product.
    let parameter_only = parameter_only_flags(graph, &insts);
    let Trees {
        interior,
        roots,
        mut leaves,
    } = trees(&insts, &outputs, &parameter_only);
    let mut pairs = group_parameters(&mut leaves, &parameter_only, n);
    let first = n + pairs.len();
    let shared = share_pairs(&mut leaves, first, pairs_of, take_pair);
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

/// The maximal trees of multiplications of a program.
struct Trees {
    /// Whether each instruction is inside a tree: a multiplication used
    /// once, by a multiplication.
    interior: Vec<bool>,
    /// Each tree's root.
    roots: Vec<u32>,
    /// Each tree's factors, sorted; an id past the program stands for a
    /// pair shared later.
    leaves: Vec<Vec<u32>>,
}

/// The trees of multiplications of `insts`, parameter-only ones left out.
fn trees(insts: &[Inst], outputs: &[u32], parameter_only: &[bool]) -> Trees {
    let n = insts.len();
    let uses = use_counts(insts, outputs);
    let is_mul = |i: u32| matches!(insts[i as usize], Inst::Mul(..));
    let mut interior = vec![false; n];
    for inst in insts {
        if let Inst::Mul(a, b) = *inst {
            for x in [a, b] {
                if is_mul(x) && uses[x as usize] == 1 && !parameter_only[x as usize] {
                    interior[x as usize] = true;
                }
            }
        }
    }
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
    Trees {
        interior,
        roots,
        leaves,
    }
}

/// The parameter-only factors of each tree made one product, built pair
/// by pair and shared between trees with the same ones: the pairs, each
/// named `n + k`.
fn group_parameters(leaves: &mut [Vec<u32>], parameter_only: &[bool], n: usize) -> Vec<(u32, u32)> {
    let mut pairs: Vec<(u32, u32)> = Vec::new();
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
    pairs
}

/// Every pair of a tree's factors.
fn pairs_of(list: &[u32]) -> Vec<(u32, u32)> {
    let mut seen = Vec::new();
    for x in 0..list.len() {
        for y in x + 1..list.len() {
            seen.push((list[x], list[y]));
        }
    }
    seen
}

/// Replaces the factors `a` and `b` of a tree by the shared pair `id`;
/// false where the tree does not hold both.
fn take_pair(list: &mut Vec<u32>, (a, b): (u32, u32), id: u32) -> bool {
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
}

#[cfg(test)]
mod tests {
    use crate::emit::tests::check;
    use crate::emit::Inst;
    use crate::graph::Graph;

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
}
