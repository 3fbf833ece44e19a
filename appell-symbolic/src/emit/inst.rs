//! The instruction set of a lowered program ([`Inst`]), operation counts
//! ([`OpCount`]), and the facts about an instruction list that several
//! passes and the writer read: which instructions depend on parameters only,
//! and how often each is read.

use std::fmt;

use crate::graph::{Func, Graph, Symbol, SymbolKind};
use crate::number::Number;

/// One binary instruction of a lowered program. Operands index earlier
/// instructions.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Inst {
    /// A constant.
    Const(Number),
    /// A symbol's value.
    Symbol(Symbol),
    /// `a + b`.
    Add(u32, u32),
    /// `a − b`.
    Sub(u32, u32),
    /// `a · b`.
    Mul(u32, u32),
    /// `a / b`.
    Div(u32, u32),
    /// `−a`.
    Neg(u32),
    /// `aⁿ` (only for exponents above 64; smaller ones are multiplication
    /// chains, whose IEEE result is fully specified).
    Powi(u32, i32),
    /// `f(a)`.
    Call(Func, u32),
    /// `atan2(y, x)`.
    Atan2(u32, u32),
    /// `powf(x, y)`.
    Powf(u32, u32),
    /// `select(c, a, b)`: `a` where `c > 0`, else `b`.
    Select(u32, u32, u32),
}

impl Inst {
    /// The same instruction with each operand `x` replaced by `r(x)`.
    pub(super) fn remap(self, r: impl Fn(u32) -> u32) -> Inst {
        match self {
            Inst::Add(a, b) => Inst::Add(r(a), r(b)),
            Inst::Sub(a, b) => Inst::Sub(r(a), r(b)),
            Inst::Mul(a, b) => Inst::Mul(r(a), r(b)),
            Inst::Div(a, b) => Inst::Div(r(a), r(b)),
            Inst::Atan2(a, b) => Inst::Atan2(r(a), r(b)),
            Inst::Powf(a, b) => Inst::Powf(r(a), r(b)),
            Inst::Select(c, a, b) => Inst::Select(r(c), r(a), r(b)),
            Inst::Neg(a) => Inst::Neg(r(a)),
            Inst::Powi(a, e) => Inst::Powi(r(a), e),
            Inst::Call(f, a) => Inst::Call(f, r(a)),
            leaf => leaf,
        }
    }

    /// The instructions this one reads, in order (with repeats).
    pub(super) fn operands(&self) -> Vec<u32> {
        match *self {
            Inst::Const(_) | Inst::Symbol(_) => vec![],
            Inst::Add(a, b) | Inst::Sub(a, b) | Inst::Mul(a, b) | Inst::Div(a, b) => vec![a, b],
            Inst::Atan2(y, x) | Inst::Powf(y, x) => vec![y, x],
            Inst::Select(c, a, b) => vec![c, a, b],
            Inst::Neg(a) | Inst::Powi(a, _) | Inst::Call(_, a) => vec![a],
        }
    }
}

/// Operation counts of emitted code, by kind.
///
/// ```
/// use appell_symbolic::Graph;
/// let mut g = Graph::new();
/// let e = g.parse("sin(x)^2*y + sin(x)*z - 1/y").unwrap();
/// let ops = g.op_count(&[e]).unwrap();
/// assert_eq!(ops.calls, 1); // sin(x) once
/// assert_eq!(ops.div, 1);
/// assert_eq!(ops.total(), ops.add + ops.mul + ops.div + ops.neg + ops.calls + ops.powi);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OpCount {
    /// Additions and subtractions.
    pub add: usize,
    /// Multiplications.
    pub mul: usize,
    /// Divisions.
    pub div: usize,
    /// Negations.
    pub neg: usize,
    /// Calls of `sin cos tan exp ln abs sqrt atan2`.
    pub calls: usize,
    /// `powi` calls (exponents above 64).
    pub powi: usize,
}

impl OpCount {
    /// All operations.
    pub fn total(&self) -> usize {
        self.add + self.mul + self.div + self.neg + self.calls + self.powi
    }

    /// The operations of `insts`, each executed once.
    pub(super) fn of(insts: &[Inst]) -> OpCount {
        let mut c = OpCount::default();
        for inst in insts {
            c.count(inst, 1);
        }
        c
    }

    /// Adds `inst`, executed `times` times.
    pub(super) fn count(&mut self, inst: &Inst, times: usize) {
        match inst {
            Inst::Const(_) | Inst::Symbol(_) => {}
            Inst::Add(..) | Inst::Sub(..) => self.add += times,
            Inst::Mul(..) => self.mul += times,
            Inst::Div(..) => self.div += times,
            Inst::Neg(_) => self.neg += times,
            Inst::Powi(..) => self.powi += times,
            Inst::Call(..) | Inst::Atan2(..) | Inst::Powf(..) => self.calls += times,
            // A comparison and a choice, counted with the additions.
            Inst::Select(..) => self.add += times,
        }
    }
}

impl std::ops::Add for OpCount {
    type Output = OpCount;
    fn add(self, o: OpCount) -> OpCount {
        OpCount {
            add: self.add + o.add,
            mul: self.mul + o.mul,
            div: self.div + o.div,
            neg: self.neg + o.neg,
            calls: self.calls + o.calls,
            powi: self.powi + o.powi,
        }
    }
}

impl fmt::Display for OpCount {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} ops ({} add, {} mul, {} div, {} neg, {} calls, {} powi)",
            self.total(),
            self.add,
            self.mul,
            self.div,
            self.neg,
            self.calls,
            self.powi
        )
    }
}
/// Whether each instruction depends on parameters (and constants) only.
pub(super) fn parameter_only_flags(graph: &Graph, insts: &[Inst]) -> Vec<bool> {
    let mut flags: Vec<bool> = Vec::with_capacity(insts.len());
    for inst in insts {
        let p = parameter_only(graph, inst, &flags);
        flags.push(p);
    }
    flags
}

/// Whether `inst` depends on parameters (and constants) only, given the
/// flags of the instructions before it.
pub(super) fn parameter_only(graph: &Graph, inst: &Inst, flags: &[bool]) -> bool {
    match inst {
        Inst::Const(_) => true,
        Inst::Symbol(s) => graph.symbol_kind(*s) == SymbolKind::Parameter,
        other => other.operands().iter().all(|&o| flags[o as usize]),
    }
}

/// How many instructions (and outputs) read each instruction.
pub(super) fn use_counts(insts: &[Inst], outputs: &[u32]) -> Vec<u32> {
    let mut uses = vec![0u32; insts.len()];
    for inst in insts {
        for o in inst.operands() {
            uses[o as usize] += 1;
        }
    }
    for &o in outputs {
        uses[o as usize] += 1;
    }
    uses
}
