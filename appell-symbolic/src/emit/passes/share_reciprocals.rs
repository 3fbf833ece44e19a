//! [`Pass::ShareReciprocals`](super::Pass::ShareReciprocals): one
//! reciprocal for a shared denominator.

use std::collections::BTreeMap;

use crate::number::Number;

use super::super::inst::Inst;
use super::rewrite;

/// Divisions by a denominator that several divisions share become one
/// reciprocal and multiplications (`a/d, b/d → r = 1/d; a·r, b·r`): a
/// division costs several multiplications.
pub(super) fn share_reciprocals(insts: Vec<Inst>, outputs: Vec<u32>) -> (Vec<Inst>, Vec<u32>) {
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
