//! [`Pass::Prune`](super::Pass::Prune): dead instructions out, equal
//! instructions merged.

use crate::graph::FxHashMap;

use super::super::inst::Inst;

/// Which instructions the outputs need, directly or not.
fn needed(insts: &[Inst], outputs: &[u32]) -> Vec<bool> {
    let mut needed = vec![false; insts.len()];
    for &o in outputs {
        needed[o as usize] = true;
    }
    for i in (0..insts.len()).rev() {
        if needed[i] {
            for op in insts[i].operands() {
                needed[op as usize] = true;
            }
        }
    }
    needed
}

/// Keeps only the instructions the outputs need, once each, renumbered in
/// order.
pub(super) fn prune(insts: Vec<Inst>, outputs: Vec<u32>) -> (Vec<Inst>, Vec<u32>) {
    let needed = needed(&insts, &outputs);
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
