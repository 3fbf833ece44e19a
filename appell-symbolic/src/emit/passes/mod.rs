//! The passes that run on a lowered program, by name ([`Pass`]), the choice
//! of which run ([`LowerOptions`]), and what each did ([`PassReport`]).
//!
//! Every pass keeps each output's value up to rounding and changes only the
//! work; most share work that the lowering, one expression at a time,
//! computes twice. They run in the order of [`Pass::ALL`].

use std::collections::BTreeSet;
use std::fmt;

use crate::graph::Graph;

use super::inst::{Inst, OpCount};

mod absorb_negations;
mod balance_sums;
mod modp;
mod pairs;
mod prune;
mod share_equal_values;
mod share_products;
mod share_reciprocals;
mod share_sums;

/// A named pass of [`Program::lower`](super::Program::lower).
///
/// ```
/// use appell_symbolic::Pass;
/// assert_eq!(Pass::ALL[0], Pass::Prune);
/// assert_eq!(Pass::ShareSums.name(), "share_sums");
/// assert_eq!(Pass::from_name("share_sums"), Some(Pass::ShareSums));
/// assert_eq!(Pass::BalanceSums.to_string(), "balance_sums");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Pass {
    /// Keeps only the instructions the outputs need, once each (equal
    /// instructions merged), renumbered in order. It runs first, since the
    /// lowering leaves forms behind that end up unused (a sum's terms before
    /// their common factors are taken out), so that only live instructions
    /// count as uses in the passes after it. Every other pass returns a
    /// program without unused instructions when given one.
    Prune,
    /// One instruction for each value that several compute in different
    /// forms (a sum kept factored in one place and multiplied out in
    /// another), found by evaluating every instruction exactly modulo a
    /// prime at random points; an equal earlier form is used only if it
    /// reads nothing of a later stage, or of the state, that the later form
    /// does not. Ends with a prune.
    ShareEqualValues,
    /// Divisions by a shared denominator become one reciprocal and
    /// multiplications (`a/d, b/d → r = 1/d; a·r, b·r`).
    ShareReciprocals,
    /// Products that share two factors share their product (`a·b·c, a·b·d →
    /// t = a·b; t·c, t·d`), greedily, most shared pair first. Ends with a
    /// prune.
    ShareProducts,
    /// Sums that share two terms share their sum (`a + b + c, a + b − d →
    /// t = a + b; t + c, t − d`), and a term added and subtracted in one
    /// sum cancels. Ends with a prune.
    ShareSums,
    /// Negations absorbed by their readers (`x + (−a)` is `x − a`), so a
    /// negation disappears when every reader can take its sign; values stay
    /// the same bit for bit.
    AbsorbNegations,
    /// Every sum of three terms or more re-associated so that its result is
    /// ready early under a latency model (running sums that take each term
    /// as it becomes ready). Ends with a prune.
    BalanceSums,
}

impl Pass {
    /// Every pass, in the order [`Program::lower`](super::Program::lower)
    /// runs them.
    pub const ALL: [Pass; 7] = [
        Pass::Prune,
        Pass::ShareEqualValues,
        Pass::ShareReciprocals,
        Pass::ShareProducts,
        Pass::ShareSums,
        Pass::AbsorbNegations,
        Pass::BalanceSums,
    ];

    /// The pass's name in snake case, as in [`PassReport`]'s text.
    pub fn name(self) -> &'static str {
        match self {
            Pass::Prune => "prune",
            Pass::ShareEqualValues => "share_equal_values",
            Pass::ShareReciprocals => "share_reciprocals",
            Pass::ShareProducts => "share_products",
            Pass::ShareSums => "share_sums",
            Pass::AbsorbNegations => "absorb_negations",
            Pass::BalanceSums => "balance_sums",
        }
    }

    /// The pass of a [`Pass::name`], if any.
    pub fn from_name(name: &str) -> Option<Pass> {
        Pass::ALL.into_iter().find(|p| p.name() == name)
    }

    /// Runs the pass on `insts` and the instruction of each output.
    pub(super) fn run(
        self,
        graph: &Graph,
        insts: Vec<Inst>,
        outputs: Vec<u32>,
    ) -> (Vec<Inst>, Vec<u32>) {
        use prune::prune;
        // Three passes leave the instructions they replaced behind, unread
        // or equal to others, and end with a prune. share_reciprocals leaves
        // none, absorb_negations prunes itself when it changes anything, and
        // balance_sums prunes what it rebuilt.
        match self {
            Pass::Prune => prune(insts, outputs),
            Pass::ShareEqualValues => {
                let (insts, outputs) =
                    share_equal_values::share_equal_values(graph, insts, outputs);
                prune(insts, outputs)
            }
            Pass::ShareReciprocals => share_reciprocals::share_reciprocals(insts, outputs),
            Pass::ShareProducts => {
                let (insts, outputs) = share_products::share_products(graph, insts, outputs);
                prune(insts, outputs)
            }
            Pass::ShareSums => {
                let (insts, outputs) = share_sums::share_sums(graph, insts, outputs);
                prune(insts, outputs)
            }
            Pass::AbsorbNegations => absorb_negations::absorb_negations(insts, outputs),
            Pass::BalanceSums => balance_sums::balance_sums(graph, insts, outputs),
        }
    }
}

impl fmt::Display for Pass {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Which passes [`Program::lower_with`](super::Program::lower_with) runs:
/// by default all of them, as [`Program::lower`](super::Program::lower).
/// Switching passes off measures what each saves, or finds the pass behind
/// a wrong result; every choice gives a program that computes the same
/// values up to rounding.
///
/// ```
/// use appell_symbolic::{LowerOptions, Pass};
/// let options = LowerOptions::default().without(Pass::ShareSums);
/// assert!(!options.runs(Pass::ShareSums));
/// assert!(options.runs(Pass::ShareProducts));
/// // Only the first prune and the sharing of products:
/// let options = LowerOptions::none().with(Pass::Prune).with(Pass::ShareProducts);
/// assert!(options.runs(Pass::ShareProducts) && !options.runs(Pass::BalanceSums));
/// ```
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct LowerOptions {
    /// The passes switched off.
    off: BTreeSet<Pass>,
}

impl LowerOptions {
    /// Every pass switched off: the program as the lowering writes it.
    pub fn none() -> LowerOptions {
        LowerOptions {
            off: Pass::ALL.into_iter().collect(),
        }
    }

    /// The same options with `pass` switched off.
    pub fn without(mut self, pass: Pass) -> LowerOptions {
        self.off.insert(pass);
        self
    }

    /// The same options with `pass` switched on.
    pub fn with(mut self, pass: Pass) -> LowerOptions {
        self.off.remove(&pass);
        self
    }

    /// Whether `pass` runs.
    pub fn runs(&self, pass: Pass) -> bool {
        !self.off.contains(&pass)
    }
}

/// The size of a program between two passes: its instructions (symbols
/// and constants included) and their operations, each counted once,
/// whether or not an output still needs it.
///
/// ```
/// use appell_symbolic::{Graph, Program};
/// let mut g = Graph::new();
/// let e = g.parse("x*y + sin(x)").unwrap();
/// let p = Program::lower(&g, &[e]);
/// let last = p.pass_report().last().unwrap().after;
/// assert_eq!(last.insts, p.insts().len());
/// assert_eq!(last.ops, p.op_count());
/// assert_eq!(last.to_string(), "5 insts, 3 ops");
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ProgramSize {
    /// Instructions.
    pub insts: usize,
    /// Their operations.
    pub ops: OpCount,
}

impl ProgramSize {
    /// The size of `insts`.
    fn of(insts: &[Inst]) -> ProgramSize {
        ProgramSize {
            insts: insts.len(),
            ops: OpCount::of(insts),
        }
    }
}

impl fmt::Display for ProgramSize {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} insts, {} ops", self.insts, self.ops.total())
    }
}

/// What one pass did: the program's size before and after it.
///
/// ```
/// use appell_symbolic::{Graph, LowerOptions, Pass, Program};
/// let mut g = Graph::new();
/// let e = g.parse("x*y*z + x*y*w").unwrap();
/// let p = Program::lower_with(&g, &[e], &LowerOptions::default());
/// for r in p.pass_report() {
///     println!("{r}"); // "<pass>: <insts> insts, <ops> ops → <insts> insts, <ops> ops"
///     assert!(r.after.ops.total() <= r.before.ops.total());
/// }
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PassReport {
    /// The pass.
    pub pass: Pass,
    /// The program it was given.
    pub before: ProgramSize,
    /// The program it returned.
    pub after: ProgramSize,
}

impl fmt::Display for PassReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {} → {}", self.pass, self.before, self.after)
    }
}

/// Runs the passes `options` selects, in the order of [`Pass::ALL`], on a
/// lowered program: the program they return and a report per pass run.
pub(super) fn run(
    graph: &Graph,
    insts: Vec<Inst>,
    outputs: Vec<u32>,
    options: &LowerOptions,
) -> (Vec<Inst>, Vec<u32>, Vec<PassReport>) {
    let mut report = Vec::new();
    let (mut insts, mut outputs) = (insts, outputs);
    for pass in Pass::ALL.into_iter().filter(|&p| options.runs(p)) {
        let before = ProgramSize::of(&insts);
        (insts, outputs) = pass.run(graph, insts, outputs);
        let after = ProgramSize::of(&insts);
        report.push(PassReport {
            pass,
            before,
            after,
        });
    }
    (insts, outputs, report)
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
