//! The passes that run on a lowered program, one file each.
//!
//! Every pass keeps each output's value up to rounding and changes only the
//! work; most share work that the lowering, one expression at a time,
//! computes twice.

use crate::graph::Graph;

use super::inst::Inst;

mod absorb_negations;
mod balance_sums;
mod modp;
mod pairs;
mod prune;
mod share_equal_values;
mod share_products;
mod share_reciprocals;
mod share_sums;

/// Runs the passes on a lowered program.
pub(super) fn run(graph: &Graph, insts: Vec<Inst>, outputs: Vec<u32>) -> (Vec<Inst>, Vec<u32>) {
    use prune::prune;
    // Lowering builds forms that end up unused (a sum's terms before
    // their common factors are taken out): drop them first, so that
    // only live instructions count as uses below.
    let (insts, outputs) = prune(insts, outputs);
    let (insts, outputs) = share_equal_values::share_equal_values(graph, insts, outputs);
    let (insts, outputs) = prune(insts, outputs);
    let (insts, outputs) = share_reciprocals::share_reciprocals(insts, outputs);
    let (insts, outputs) = share_products::share_products(graph, insts, outputs);
    let (insts, outputs) = prune(insts, outputs);
    let (insts, outputs) = share_sums::share_sums(graph, insts, outputs);
    let (insts, outputs) = prune(insts, outputs);
    let (insts, outputs) = absorb_negations::absorb_negations(insts, outputs);
    balance_sums::balance_sums(graph, insts, outputs)
}

/// Rewrites a program instruction by instruction: `special(i, inst, out,
/// map)` may emit instruction i's replacement into `out` (`map` gives the
/// new index of every earlier instruction) and return its index; else the
/// instruction is copied with its operands renumbered.
pub(super) fn rewrite(
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
