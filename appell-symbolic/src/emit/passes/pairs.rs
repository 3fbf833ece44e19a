//! The greedy sharing of pairs that
//! [`share_products`](super::share_products) and
//! [`share_sums`](super::share_sums) both run: over trees of one operation,
//! the pair of items found in the most trees becomes one instruction, until
//! no pair is found twice.

use crate::graph::FxHashMap;

use super::super::inst::Inst;

/// Greedy sharing of pairs over trees (each a list of items): while some
/// pair is found in two trees or more, the pair found in the most trees
/// (ties: the smallest) becomes a new item, numbered `first` + its index,
/// in every tree that holds it. `pairs_of` lists a tree's pairs and
/// `replace` puts the new item in place of one occurrence of a pair
/// (false if the tree has none). Counts are kept up to date incrementally:
/// only the trees that held the chosen pair are read again. Returns the
/// pairs in the order chosen.
pub(super) fn share_pairs<I, P: Copy + Ord + std::hash::Hash>(
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
pub(super) fn shared_value<P: Copy + PairItems>(
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
pub(super) trait PairItems {
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
