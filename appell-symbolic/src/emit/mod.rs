//! Emission: from expression roots to straight-line Rust over a generic scalar.
//!
//! Two steps. [`Program::lower`] turns the canonical n-ary graph into binary
//! instructions (`+ − × ÷`, negation, integer powers by repeated squaring,
//! function calls), hash-consed again so that e.g. `x²` is computed once for
//! `x³` and `x⁴`, then runs the sharing passes of [`Pass::ALL`] over them
//! ([`Program::lower_with`] can switch passes off and reports what each
//! did). [`Program::to_rust`] then writes one `let` per instruction used
//! more than once (common-subexpression elimination is "a node used twice
//! becomes a `let`"), inlines the rest, and separates the instructions that
//! depend on parameters only, so they can be computed once per parameter set.
//!
//! The output is deterministic: names, order and text depend only on the
//! graph, never on hash-map iteration.
//!
//! The parts: `inst` (the instructions and operation counts), `lower`
//! (graph to instructions), `passes` (one file per pass), `writer`
//! (instructions to Rust: what is bound, named, hoisted, staged and
//! parenthesized) and `syntax` (the fragments the writer builds, rendered
//! as text or as tokens).

use crate::error::Result;
use crate::graph::{Graph, Id, Symbol};

mod code;
mod inst;
mod lower;
mod passes;
mod syntax;
mod writer;

#[cfg(test)]
mod tests;
#[cfg(test)]
mod token_tests;

pub use code::{EmitOptions, RustCode, RustTokens};
pub use inst::{Inst, OpCount};
pub use passes::{LowerOptions, Pass, PassReport, ProgramSize};
pub use syntax::{ConstantForm, RustPath, ScalarType};

use inst::{parameter_only_flags, use_counts};

/// A lowered, hash-consed straight-line program computing some roots.
#[derive(Clone, Debug)]
pub struct Program {
    insts: Vec<Inst>,
    outputs: Vec<u32>,
    parameter_only: Vec<bool>,
    uses: Vec<u32>,
    /// What each pass did, in the order they ran.
    report: Vec<PassReport>,
}

impl Program {
    /// Lowers the expressions `roots` of `graph`, running every pass of
    /// [`Pass::ALL`].
    ///
    /// ```
    /// use appell_symbolic::{Graph, Program};
    /// let mut g = Graph::new();
    /// let e = g.parse("x*y*z + x*y*w").unwrap();
    /// let p = Program::lower(&g, &[e]);
    /// assert_eq!(p.outputs().len(), 1);
    /// assert_eq!(p.op_count().total(), 3); // x·y·(z + w)
    /// ```
    pub fn lower(graph: &Graph, roots: &[Id]) -> Program {
        Program::lower_with(graph, roots, &LowerOptions::default())
    }

    /// Lowers the expressions `roots` of `graph`, running the passes
    /// `options` selects, and records what each did
    /// ([`Program::pass_report`]). With the default options this is
    /// [`Program::lower`].
    ///
    /// ```
    /// use appell_symbolic::{Graph, LowerOptions, Pass, Program};
    /// let mut g = Graph::new();
    /// let a = g.parse("x*y*z").unwrap();
    /// let b = g.parse("x*z*w").unwrap();
    /// let all = Program::lower(&g, &[a, b]);
    /// let without = LowerOptions::default().without(Pass::ShareProducts);
    /// let fewer = Program::lower_with(&g, &[a, b], &without);
    /// // Without sharing x·z, each product computes it.
    /// assert_eq!(all.op_count().mul + 1, fewer.op_count().mul);
    /// assert!(fewer.pass_report().iter().all(|r| r.pass != Pass::ShareProducts));
    /// ```
    pub fn lower_with(graph: &Graph, roots: &[Id], options: &LowerOptions) -> Program {
        let (insts, outputs) = lower::lower(graph, roots);
        let (insts, outputs, report) = passes::run(graph, insts, outputs, options);
        let parameter_only = parameter_only_flags(graph, &insts);
        let uses = use_counts(&insts, &outputs);
        Program {
            insts,
            outputs,
            parameter_only,
            uses,
            report,
        }
    }

    /// What each pass did, in the order they ran: its name and the
    /// program's size before and after it. The first entry's `before` is the
    /// lowering's output; each entry's `after` is the next one's `before`.
    ///
    /// ```
    /// use appell_symbolic::{Graph, Pass, Program};
    /// let mut g = Graph::new();
    /// let e = g.parse("(x + y)*z - x*z").unwrap();
    /// let p = Program::lower(&g, &[e]);
    /// let passes: Vec<Pass> = p.pass_report().iter().map(|r| r.pass).collect();
    /// assert_eq!(passes, Pass::ALL);
    /// assert_eq!(p.pass_report().last().unwrap().after.ops, p.op_count());
    /// ```
    pub fn pass_report(&self) -> &[PassReport] {
        &self.report
    }

    /// The instructions, in evaluation order.
    pub fn insts(&self) -> &[Inst] {
        &self.insts
    }

    /// The instruction of each root.
    pub fn outputs(&self) -> &[u32] {
        &self.outputs
    }

    /// Operations executed once all shared subexpressions are computed once.
    pub fn op_count(&self) -> OpCount {
        OpCount::of(&self.insts)
    }

    /// Operations of the same program written as trees, every shared
    /// subexpression recomputed where used (the count before CSE).
    pub fn tree_op_count(&self) -> OpCount {
        let mult = self.tree_multiplicity();
        let mut c = OpCount::default();
        for (i, inst) in self.insts.iter().enumerate() {
            c.count(inst, mult[i]);
        }
        c
    }

    /// How many times each instruction runs when every shared
    /// subexpression is recomputed where used.
    fn tree_multiplicity(&self) -> Vec<usize> {
        let mut mult = vec![0usize; self.insts.len()];
        for &o in &self.outputs {
            mult[o as usize] += 1;
        }
        for i in (0..self.insts.len()).rev() {
            let m = mult[i];
            for o in self.insts[i].operands() {
                mult[o as usize] = mult[o as usize].saturating_add(m);
            }
        }
        mult
    }

    /// Runs the program in `f64` (the emitted Rust computes exactly this).
    pub fn eval(&self, env: &dyn Fn(Symbol) -> Option<f64>) -> Option<Vec<f64>> {
        let mut v: Vec<f64> = Vec::with_capacity(self.insts.len());
        for inst in &self.insts {
            let x = match *inst {
                Inst::Const(n) => n.to_f64(),
                Inst::Symbol(s) => env(s)?,
                Inst::Add(a, b) => v[a as usize] + v[b as usize],
                Inst::Sub(a, b) => v[a as usize] - v[b as usize],
                Inst::Mul(a, b) => v[a as usize] * v[b as usize],
                Inst::Div(a, b) => v[a as usize] / v[b as usize],
                Inst::Neg(a) => -v[a as usize],
                Inst::Powi(a, e) => v[a as usize].powi(e),
                Inst::Call(f, a) => f.apply(v[a as usize]),
                Inst::Atan2(y, x) => v[y as usize].atan2(v[x as usize]),
                Inst::Powf(x, y) => v[x as usize].powf(v[y as usize]),
                Inst::Select(c, a, b) => {
                    if v[c as usize] > 0.0 {
                        v[a as usize]
                    } else {
                        v[b as usize]
                    }
                }
            };
            v.push(x);
        }
        Some(self.outputs.iter().map(|&o| v[o as usize]).collect())
    }

    /// Writes the program as Rust statements (text).
    pub fn to_rust(&self, graph: &Graph, options: &EmitOptions) -> RustCode {
        writer::write(self, graph, options).text()
    }

    /// Writes the program as Rust tokens: the statements and expressions of
    /// [`Program::to_rust`], built as `proc_macro2` tokens without parsing
    /// (see [`RustTokens`] for how float literals are spelled).
    ///
    /// ```
    /// use appell_symbolic::{ConstantForm, EmitOptions, Graph, Program, ScalarType};
    /// let mut g = Graph::new();
    /// let e = g.parse("x/2 - y").unwrap();
    /// let program = Program::lower(&g, &[e]);
    /// let options = EmitOptions {
    ///     scalar: ScalarType::named("f64"),
    ///     constant: ConstantForm::F64Literal,
    ///     ..EmitOptions::default()
    /// };
    /// let tokens = program.to_tokens(&g, &options);
    /// let text = program.to_rust(&g, &options);
    /// assert_eq!(text.body, ["let k1_2: f64 = 0.5_f64;"]);
    /// assert_eq!(tokens.body[0].to_string(), "let k1_2 : f64 = 0.5f64 ;");
    /// assert_eq!(tokens.outputs[0].to_string(), "x * k1_2 - y");
    /// ```
    ///
    /// # Panics
    ///
    /// If a symbol is read by a name that is not a Rust identifier (see
    /// [`EmitOptions::symbol_text`]).
    pub fn to_tokens(&self, graph: &Graph, options: &EmitOptions) -> RustTokens {
        writer::write(self, graph, options).tokens()
    }
}

impl Graph {
    /// Operation count of the emitted code for `roots`, with shared
    /// subexpressions computed once (parameter-only work included).
    pub fn op_count(&self, roots: &[Id]) -> Result<OpCount> {
        Ok(Program::lower(self, roots).op_count())
    }
}
