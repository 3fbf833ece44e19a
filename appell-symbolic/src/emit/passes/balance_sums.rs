//! [`Pass::BalanceSums`](super::Pass::BalanceSums): sums re-associated so
//! that their results are ready early, under a latency model.

use crate::graph::{Func, Graph};

use super::super::inst::{parameter_only, use_counts, Inst};
use super::prune::prune;

/// Rough latency, in cycles, of an instruction on a current x86-64 core:
/// the model [`balance_sums`] orders a sum's terms by.
pub(super) fn latency(inst: &Inst) -> u32 {
    match inst {
        Inst::Const(_) | Inst::Symbol(_) => 0,
        Inst::Neg(_) | Inst::Call(Func::Abs, _) => 1,
        Inst::Add(..) | Inst::Sub(..) | Inst::Mul(..) => 4,
        Inst::Div(..) => 14,
        Inst::Call(Func::Sqrt, _) => 20,
        Inst::Powi(..) => 30,
        Inst::Select(..) => 4,
        Inst::Call(..) | Inst::Atan2(..) | Inst::Powf(..) => 60,
    }
}

/// How far (in cycles of [`latency`]) a running sum may lag behind a term
/// before the term starts a running sum of its own. Slacks of 0, 8 and 16
/// time alike on a large model's rhs, and all beat the plain chain.
const SUM_SLACK: u32 = 8;

/// The program [`balance_sums`] rebuilds, with the cycle each value is
/// ready at under [`latency`] (0 for parameter-only values, computed
/// beforehand).
struct Scheduled {
    /// The instructions.
    insts: Vec<Inst>,
    /// When each value is ready.
    ready: Vec<u32>,
    /// Whether each value is parameter-only.
    parameter: Vec<bool>,
}

impl Scheduled {
    /// Appends `inst`, ready at `ready` or else when its operands are,
    /// plus its latency; returns its index.
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
pub(super) fn balance_sums(
    graph: &Graph,
    insts: Vec<Inst>,
    outputs: Vec<u32>,
) -> (Vec<Inst>, Vec<u32>) {
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
    let mut out = Scheduled {
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

#[cfg(test)]
mod tests {
    use super::latency;
    use crate::emit::tests::check;
    use crate::emit::{Inst, Program};
    use crate::graph::{Func, Graph};

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
