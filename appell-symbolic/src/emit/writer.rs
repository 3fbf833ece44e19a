//! Writing a [`Program`] as Rust. The writer decides the code once, as
//! fragments ([`Frag`], [`Let`]): names, what is bound and what inlined,
//! what is hoisted into `prepare`, the stages, fused multiply-adds and
//! parentheses. [`RustCode`] and [`RustTokens`] (in `code.rs`) are two
//! renderings of the same [`Written`] program.

use std::collections::{BTreeMap, BTreeSet};

use crate::graph::{Graph, Symbol};
use crate::number::Number;

use super::code::{EmitOptions, RustCode, RustTokens};
use super::inst::{Inst, OpCount};
use super::syntax::{self, BinOp, Frag, Let, Prec};
use super::Program;

/// Deepest nesting of operations written inline in one expression.
const MAX_INLINE_DEPTH: usize = 16;

/// The statements of a [`RustCode`] as they are written.
#[derive(Default)]
struct Sections {
    /// [`RustCode::prepare`].
    prepare: Vec<Let>,
    /// [`RustCode::body`].
    body: Vec<Let>,
    /// [`RustCode::stages`].
    staged: Vec<Vec<Let>>,
    /// Names bound by `prepare` that the body reads.
    hoisted: Vec<String>,
    /// The constants (by instruction) already bound in `prepare`.
    const_in_prepare: BTreeSet<usize>,
    /// The constants (by instruction) already bound in the body.
    const_in_body: BTreeSet<usize>,
}

/// A program as the writer decided it, before it is rendered as text
/// ([`Written::text`]) or tokens ([`Written::tokens`]).
pub(super) struct Written<'a> {
    o: &'a EmitOptions,
    prepare: Vec<Let>,
    hoisted: Vec<String>,
    body: Vec<Let>,
    stages: Vec<Vec<Let>>,
    outputs: Vec<Frag>,
    ops: OpCount,
    prepare_ops: OpCount,
}

impl Written<'_> {
    /// The program as text ([`Program::to_rust`]).
    pub(super) fn text(&self) -> RustCode {
        let o = self.o;
        let stmts = |v: &[Let]| v.iter().map(|s| s.text(o)).collect::<Vec<_>>();
        RustCode {
            prepare: stmts(&self.prepare),
            hoisted: self.hoisted.clone(),
            body: stmts(&self.body),
            stages: self.stages.iter().map(|s| stmts(s)).collect(),
            outputs: self.outputs.iter().map(|f| syntax::text(f, o)).collect(),
            ops: self.ops,
            prepare_ops: self.prepare_ops,
        }
    }

    /// The program as tokens ([`Program::to_tokens`]).
    pub(super) fn tokens(&self) -> RustTokens {
        let o = self.o;
        let stmts = |v: &[Let]| v.iter().map(|s| s.tokens(o)).collect::<Vec<_>>();
        RustTokens {
            prepare: stmts(&self.prepare),
            hoisted: self.hoisted.iter().map(|h| Let::name_token(h)).collect(),
            body: stmts(&self.body),
            stages: self.stages.iter().map(|s| stmts(s)).collect(),
            outputs: self.outputs.iter().map(|f| syntax::tokens(f, o)).collect(),
            ops: self.ops,
            prepare_ops: self.prepare_ops,
        }
    }
}

/// Writes `p` as Rust ([`Program::to_rust`], [`Program::to_tokens`]).
pub(super) fn write<'a>(p: &'a Program, g: &'a Graph, o: &'a EmitOptions) -> Written<'a> {
    Writer::new(p, g, o).write()
}

/// Writes one [`Program`] as Rust fragments.
struct Writer<'a> {
    p: &'a Program,
    g: &'a Graph,
    o: &'a EmitOptions,
    /// Name of each instruction that is bound (`let`), a symbol or a constant.
    names: Vec<Option<String>>,
    used_names: BTreeSet<String>,
    hoisted: Vec<bool>,
}

impl<'a> Writer<'a> {
    fn new(p: &'a Program, g: &'a Graph, o: &'a EmitOptions) -> Writer<'a> {
        let n = p.insts.len();
        let mut used_names = BTreeSet::new();
        for (s, info) in g.symbols() {
            used_names.insert(o.symbol_text.get(&s).cloned().unwrap_or(info.name.clone()));
        }
        Writer {
            p,
            g,
            o,
            names: vec![None; n],
            used_names,
            hoisted: vec![false; n],
        }
    }

    fn symbol_text(&self, s: Symbol) -> String {
        self.o
            .symbol_text
            .get(&s)
            .cloned()
            .unwrap_or_else(|| self.g.symbol_name(s).to_string())
    }

    fn fresh(&mut self, wanted: String) -> String {
        let mut name = wanted.clone();
        let mut k = 2;
        while self.used_names.contains(&name) {
            name = format!("{wanted}_{k}");
            k += 1;
        }
        self.used_names.insert(name.clone());
        name
    }

    /// A readable name for a bound instruction when one is obvious.
    fn suggest(&self, i: usize) -> Option<String> {
        let leaf = |j: u32| -> Option<String> {
            match &self.p.insts[j as usize] {
                Inst::Symbol(s) => Some(self.symbol_text(*s)),
                _ => self.names[j as usize].clone(),
            }
        };
        let ident = |s: String| {
            (s.len() <= 24 && s.chars().all(|c| c.is_alphanumeric() || c == '_')).then_some(s)
        };
        match self.p.insts[i] {
            Inst::Call(f, a) => ident(format!("{}_{}", f.name(), leaf(a)?)),
            Inst::Mul(a, b) if a == b => ident(format!("{}_sq", leaf(a)?)),
            Inst::Atan2(y, x) => ident(format!("atan2_{}_{}", leaf(y)?, leaf(x)?)),
            _ => None,
        }
    }

    fn constant_name(n: Number) -> String {
        match n {
            Number::Rational { num, den: 1 } => format!("k{num}").replace('-', "m"),
            Number::Rational { num, den } => format!("k{num}_{den}").replace('-', "m"),
            // Floats get a short name; the literal is in the binding.
            Number::Float(_) => "kf".to_string(),
        }
    }

    /// The whole program as Rust: which instructions are hoisted and which
    /// bound, then the statements section by section, and the outputs.
    fn write(mut self) -> Written<'a> {
        let boundary = self.mark_hoisted();
        let bind = self.bindings(&boundary);
        let stage = self.stages();
        let stage_count = 1 + stage.iter().copied().max().unwrap_or(0);
        // Constants: bound once at the top of the section that first needs them.
        let const_names = self.name_constants();
        let (body_ops, prepare_ops) = self.count_ops(&bind);
        let mut s = Sections {
            staged: vec![Vec::new(); stage_count],
            ..Sections::default()
        };
        self.bind_statements(&bind, &boundary, &stage, &const_names, &mut s);
        let mut outputs = Vec::new();
        for k in 0..self.p.outputs.len() {
            let o = self.p.outputs[k] as usize;
            self.body_constants(self.constants_of(o, &bind), &const_names, &mut s);
            outputs.push(self.expr(o).0);
        }
        // Constants first in each section (stable order by instruction):
        // the typed statements, which bind constants only.
        let split = |v: Vec<Let>| {
            let (mut c, rest): (Vec<Let>, Vec<Let>) = v.into_iter().partition(|s| s.typed);
            c.extend(rest);
            c
        };
        Written {
            o: self.o,
            prepare: split(s.prepare),
            hoisted: s.hoisted,
            body: split(s.body),
            stages: s.staged.into_iter().map(split).collect(),
            outputs,
            ops: body_ops,
            prepare_ops,
        }
    }

    /// Whether instruction `i` is an operation (not a constant or symbol).
    fn nontrivial(&self, i: usize) -> bool {
        !matches!(self.p.insts[i], Inst::Const(_) | Inst::Symbol(_))
    }

    /// Decides what is hoisted (into `self.hoisted`): the parameter-only
    /// operations, when [`EmitOptions::hoist_parameters`] is on. Returns the
    /// boundary: the instructions a per-call instruction or an output reads,
    /// of which the hoisted ones are handed to the body.
    fn mark_hoisted(&mut self) -> Vec<bool> {
        let p = self.p;
        let n = p.insts.len();
        let mut boundary = vec![false; n];
        if self.o.hoist_parameters {
            for i in 0..n {
                if !p.parameter_only[i] {
                    for op in p.insts[i].operands() {
                        boundary[op as usize] = true;
                    }
                }
            }
            for &o in &p.outputs {
                boundary[o as usize] = true;
            }
            let nontrivial = |i: usize| !matches!(p.insts[i], Inst::Const(_) | Inst::Symbol(_));
            for (i, h) in self.hoisted.iter_mut().enumerate() {
                *h = p.parameter_only[i] && nontrivial(i);
            }
        }
        boundary
    }

    /// Which instructions get a `let`: the shared ones (with CSE), the
    /// hoisted ones the body reads, and every few levels of a long chain.
    fn bindings(&self, boundary: &[bool]) -> Vec<bool> {
        let p = self.p;
        let n = p.insts.len();
        let mut bind = vec![false; n];
        for i in 0..n {
            if !self.nontrivial(i) {
                continue;
            }
            let shared = p.uses[i] >= 2;
            bind[i] = (self.o.cse && shared) || (self.hoisted[i] && boundary[i]);
        }
        // Long chains (a sum of hundreds of terms) are cut by a `let` every
        // few levels, so no written expression nests deeper than
        // MAX_INLINE_DEPTH (the writer recurses on nesting, and deep lines do
        // not read).
        let mut depth = vec![0usize; n];
        for i in 0..n {
            if !self.nontrivial(i) || bind[i] {
                continue;
            }
            let d = 1 + p.insts[i]
                .operands()
                .iter()
                .map(|&o| depth[o as usize])
                .max()
                .unwrap_or(0);
            if d > MAX_INLINE_DEPTH {
                bind[i] = true;
            } else {
                depth[i] = d;
            }
        }
        bind
    }

    /// The stage of each instruction: the latest of its symbols'
    /// ([`EmitOptions::symbol_stage`]).
    fn stages(&self) -> Vec<usize> {
        let p = self.p;
        let n = p.insts.len();
        let mut stage = vec![0usize; n];
        for i in 0..n {
            stage[i] = match p.insts[i] {
                Inst::Symbol(s) => self.o.symbol_stage.get(&s).copied().unwrap_or(0),
                ref other => other
                    .operands()
                    .iter()
                    .map(|&o| stage[o as usize])
                    .max()
                    .unwrap_or(0),
            };
        }
        stage
    }

    /// A name for each constant, by instruction.
    fn name_constants(&mut self) -> BTreeMap<usize, String> {
        let mut const_names: BTreeMap<usize, String> = BTreeMap::new();
        for i in 0..self.p.insts.len() {
            if let Inst::Const(c) = self.p.insts[i] {
                let name = self.fresh(Self::constant_name(c));
                const_names.insert(i, name.clone());
                self.names[i] = Some(name);
            }
        }
        const_names
    }

    /// The operations of the body and of `prepare`: bound instructions
    /// once; inlined ones once per inline use when CSE is off (their text
    /// is repeated).
    fn count_ops(&self, bind: &[bool]) -> (OpCount, OpCount) {
        let p = self.p;
        let mut body_ops = OpCount::default();
        let mut prepare_ops = OpCount::default();
        let mult = if self.o.cse {
            vec![1usize; p.insts.len()]
        } else {
            p.tree_multiplicity()
        };
        for (i, inst) in p.insts.iter().enumerate() {
            if self.hoisted[i] {
                prepare_ops.count(inst, if bind[i] { 1 } else { mult[i] });
            } else {
                body_ops.count(inst, if bind[i] { 1 } else { mult[i] });
            }
        }
        (body_ops, prepare_ops)
    }

    /// One `let` per bound instruction, in order, into `prepare` (hoisted)
    /// or the body and its stage, each section's constants bound before
    /// their first use.
    fn bind_statements(
        &mut self,
        bind: &[bool],
        boundary: &[bool],
        stage: &[usize],
        const_names: &BTreeMap<usize, String>,
        s: &mut Sections,
    ) {
        let mut counter_p = 0;
        let mut counter_t = 0;
        for i in 0..self.p.insts.len() {
            if !bind[i] {
                continue;
            }
            let wanted = self.suggest(i).unwrap_or_else(|| {
                if self.hoisted[i] {
                    counter_p += 1;
                    format!("p{}", counter_p - 1)
                } else {
                    counter_t += 1;
                    format!("t{}", counter_t - 1)
                }
            });
            let (text, _) = self.expr_inline(i);
            let name = self.fresh(wanted);
            let consts = self.constants_of(i, bind);
            if self.hoisted[i] {
                for c in consts {
                    if s.const_in_prepare.insert(c) {
                        s.prepare.push(self.const_stmt(c, const_names));
                    }
                }
                s.prepare.push(Let {
                    name: name.clone(),
                    typed: false,
                    value: text,
                });
                if boundary[i] {
                    s.hoisted.push(name.clone());
                }
            } else {
                self.body_constants(consts, const_names, s);
                let st = Let {
                    name: name.clone(),
                    typed: false,
                    value: text,
                };
                s.staged[stage[i]].push(st.clone());
                s.body.push(st);
            }
            self.names[i] = Some(name);
        }
    }

    /// Binds the constants `consts` in the body (and stage 0) unless bound
    /// there already.
    fn body_constants(
        &self,
        consts: Vec<usize>,
        const_names: &BTreeMap<usize, String>,
        s: &mut Sections,
    ) {
        for c in consts {
            if s.const_in_body.insert(c) {
                let st = self.const_stmt(c, const_names);
                s.staged[0].push(st.clone());
                s.body.push(st);
            }
        }
    }
    fn const_stmt(&self, i: usize, names: &BTreeMap<usize, String>) -> Let {
        let Inst::Const(c) = self.p.insts[i] else {
            unreachable!("constant")
        };
        Let {
            name: names[&i].clone(),
            typed: true,
            value: Frag::Constant(c.to_f64()),
        }
    }

    /// Constants read by the inline text of instruction `i`.
    fn constants_of(&self, i: usize, bind: &[bool]) -> Vec<usize> {
        let mut out = Vec::new();
        let mut stack = self.p.insts[i].operands();
        if matches!(self.p.insts[i], Inst::Const(_)) {
            out.push(i);
        }
        while let Some(j) = stack.pop() {
            let j = j as usize;
            match self.p.insts[j] {
                Inst::Const(_) => out.push(j),
                _ if bind[j] => {}
                Inst::Symbol(_) => {}
                _ => stack.extend(self.p.insts[j].operands()),
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    /// Instruction `i` as used by another (its name when bound).
    fn expr(&self, i: usize) -> (Frag, Prec) {
        if let Some(n) = &self.names[i] {
            return (Frag::Name(n.clone()), Prec::Atom);
        }
        if let Inst::Symbol(s) = self.p.insts[i] {
            return (Frag::Name(self.symbol_text(s)), Prec::Atom);
        }
        self.expr_inline(i)
    }

    /// The operands of a commutative operation, ordered so that a nested
    /// operation of the same level stands on the left, where it needs no
    /// parentheses (`a * b` and `b * a` are the same IEEE value).
    fn commuted(&self, a: u32, b: u32, level: Prec) -> ((Frag, Prec), (Frag, Prec)) {
        let (l, r) = (self.expr(a as usize), self.expr(b as usize));
        if r.1 == level && l.1 != level {
            (r, l)
        } else {
            (l, r)
        }
    }

    /// The factors of instruction `i` when it is a product written inline
    /// (not bound), so a sum reading it can fuse it.
    fn inline_product(&self, i: u32) -> Option<(u32, u32)> {
        match self.p.insts[i as usize] {
            Inst::Mul(a, b) if self.names[i as usize].is_none() => Some((a, b)),
            _ => None,
        }
    }

    /// `x.fma(y, z)` (the scalar trait's short name for `fused_mul_add`)
    /// for a sum or difference with an inline
    /// product operand: a + x·y, x·y + b, a − x·y as (−x)·y + a, and
    /// x·y − b as x·y + (−b).
    fn fused_inline(&self, i: usize) -> Option<Frag> {
        let atom = |j: u32| Frag::wrap(self.expr(j as usize), Prec::Atom);
        let arg = |j: u32| self.expr(j as usize).0;
        let fused = |x: Frag, y: u32, z: Frag| Frag::Method(Box::new(x), "fma", vec![arg(y), z]);
        let neg = |x: Frag| Frag::Neg(Box::new(x));
        match self.p.insts[i] {
            Inst::Add(a, b) => {
                if let Some((x, y)) = self.inline_product(b) {
                    Some(fused(atom(x), y, arg(a)))
                } else {
                    let (x, y) = self.inline_product(a)?;
                    Some(fused(atom(x), y, arg(b)))
                }
            }
            Inst::Sub(a, b) => {
                if let Some((x, y)) = self.inline_product(b) {
                    Some(fused(Frag::Paren(Box::new(neg(atom(x)))), y, arg(a)))
                } else {
                    let (x, y) = self.inline_product(a)?;
                    Some(fused(atom(x), y, neg(atom(b))))
                }
            }
            _ => None,
        }
    }

    /// Instruction `i` itself.
    fn expr_inline(&self, i: usize) -> (Frag, Prec) {
        // The right operand of a left-associative operation of `level` is
        // parenthesized at that level too.
        let right = |x: (Frag, Prec), level: Prec| {
            if x.1 <= level {
                Frag::Paren(Box::new(x.0))
            } else {
                x.0
            }
        };
        let binary = |l: (Frag, Prec), op: BinOp, r: (Frag, Prec), level: Prec| {
            (
                Frag::Binary(
                    Box::new(Frag::wrap(l, level)),
                    op,
                    Box::new(right(r, level)),
                ),
                level,
            )
        };
        let method = |x: usize, name: &'static str, args: Vec<Frag>| {
            (
                Frag::Method(Box::new(Frag::wrap(self.expr(x), Prec::Atom)), name, args),
                Prec::Atom,
            )
        };
        if self.o.fused {
            if let Some(f) = self.fused_inline(i) {
                return (f, Prec::Atom);
            }
        }
        match self.p.insts[i] {
            Inst::Const(_) | Inst::Symbol(_) => self.expr(i),
            Inst::Add(a, b) => {
                let (l, r) = self.commuted(a, b, Prec::Sum);
                binary(l, BinOp::Add, r, Prec::Sum)
            }
            Inst::Sub(a, b) => binary(
                self.expr(a as usize),
                BinOp::Sub,
                self.expr(b as usize),
                Prec::Sum,
            ),
            Inst::Mul(a, b) => {
                let (l, r) = self.commuted(a, b, Prec::Product);
                binary(l, BinOp::Mul, r, Prec::Product)
            }
            Inst::Div(a, b) => binary(
                self.expr(a as usize),
                BinOp::Div,
                self.expr(b as usize),
                Prec::Product,
            ),
            Inst::Neg(a) => (
                Frag::Neg(Box::new(Frag::wrap(self.expr(a as usize), Prec::Atom))),
                Prec::Unary,
            ),
            Inst::Powi(a, e) => method(a as usize, "powi", vec![Frag::Int(e)]),
            Inst::Call(f, a) => method(a as usize, f.name(), vec![]),
            Inst::Atan2(y, x) => method(y as usize, "atan2", vec![self.expr(x as usize).0]),
            Inst::Powf(x, y) => method(x as usize, "powf", vec![self.expr(y as usize).0]),
            Inst::Select(c, a, b) => method(
                c as usize,
                "select",
                vec![self.expr(a as usize).0, self.expr(b as usize).0],
            ),
        }
    }
}
#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::SymbolKind;

    #[test]
    fn statements_are_split_by_the_latest_stage_they_read() {
        let mut g = Graph::new();
        let _q = g.coordinate("q").unwrap();
        let x = g.declare("x", SymbolKind::Auxiliary).unwrap();
        let w = g.declare("w", SymbolKind::Auxiliary).unwrap();
        // sin(q)·cos(q) is shared by every stage; x·sin(q)·cos(q) by the
        // last two; w reads both.
        let a = g.parse("sin(q)*cos(q) + q").unwrap();
        let b = g.parse("sin(q)*cos(q)*x + x^2").unwrap();
        let c = g
            .parse("(sin(q)*cos(q)*x + x^2)*w + w^2 + sin(q)*cos(q)")
            .unwrap();
        let p = Program::lower(&g, &[a, b, c]);
        let mut o = EmitOptions::default();
        o.symbol_stage.insert(x, 1);
        o.symbol_stage.insert(w, 2);
        let code = p.to_rust(&g, &o);
        assert_eq!(code.stages.len(), 3);
        let mut all: Vec<String> = code.stages.concat();
        let mut body = code.body.clone();
        all.sort();
        body.sort();
        assert_eq!(all, body, "the stages hold exactly the body's statements");
        let mentions = |v: &[String], name: &str| {
            v.iter().any(|s| {
                s.split(|c: char| !c.is_alphanumeric() && c != '_')
                    .any(|t| t == name)
            })
        };
        assert!(!mentions(&code.stages[0], "x") && !mentions(&code.stages[0], "w"));
        assert!(!mentions(&code.stages[1], "w"));
        assert!(mentions(&code.stages[0], "q"));
        // Without stages, one stage holds everything.
        let plain = p.to_rust(&g, &EmitOptions::default());
        assert_eq!(plain.stages.len(), 1);
        assert_eq!(plain.stages[0], plain.body);
    }
}
