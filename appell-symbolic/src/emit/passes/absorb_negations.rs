//! [`Pass::AbsorbNegations`](super::Pass::AbsorbNegations): negations
//! absorbed by their readers.

use crate::graph::FxHashMap;

use super::super::inst::Inst;
use super::prune::prune;

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
pub(super) fn absorb_negations(mut insts: Vec<Inst>, outputs: Vec<u32>) -> (Vec<Inst>, Vec<u32>) {
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

#[cfg(test)]
mod tests {
    use super::absorb_negations;
    use crate::emit::tests::{program, values};
    use crate::emit::Inst;
    use crate::graph::{Graph, SymbolKind};

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
}
