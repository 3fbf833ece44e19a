//! What the writer produces and the choices it takes: [`EmitOptions`],
//! [`RustCode`] (the text: hoisted statements, per-call statements by
//! stage, and one expression per output) and [`RustTokens`] (the same as
//! `proc_macro2` tokens, built without parsing).

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write;

use proc_macro2::{Ident, TokenStream};

use crate::graph::Symbol;

use super::inst::OpCount;
use super::syntax::{ConstantForm, RustPath, ScalarType};

/// Choices for [`Program::to_rust`](super::Program::to_rust) and
/// [`Program::to_tokens`](super::Program::to_tokens).
#[derive(Clone, Debug)]
pub struct EmitOptions {
    /// The scalar type in the emitted code (a generic parameter or a
    /// concrete type); constants are bound with it as type annotation.
    pub scalar: ScalarType,
    /// How an `f64` constant becomes a [`EmitOptions::scalar`].
    pub constant: ConstantForm,
    /// Share subexpressions used more than once through `let` bindings. Off,
    /// every use is written out (readable for very small problems only).
    pub cse: bool,
    /// Move parameter-only subexpressions into [`RustCode::prepare`].
    pub hoist_parameters: bool,
    /// How each symbol is read (default: its name, as a local binding).
    /// [`Program::to_tokens`](super::Program::to_tokens) needs every symbol read by an identifier.
    pub symbol_text: BTreeMap<Symbol, String>,
    /// The stage at which each symbol becomes available (default 0). A
    /// statement belongs to the latest stage of the symbols it reads, and
    /// [`RustCode::stages`] lists the statements stage by stage, so a caller
    /// can compute some values between stages (e.g. a numeric solve whose
    /// results are the symbols of the next stage) within one program that
    /// shares every common subexpression.
    pub symbol_stage: BTreeMap<Symbol, usize>,
    /// Write a product that feeds a sum or a difference, and is not shared,
    /// as `x.fma(y, z)` (a method the scalar trait must provide, equal to
    /// `x * y + z`; appell's `Scalar::fma` calls its `fused_mul_add`): one
    /// instruction where the target fuses them. A difference is written with the sign moved onto a factor or the
    /// addend, which IEEE arithmetic gives exactly, so an unfused
    /// `fma` gives the same values as the plain text.
    pub fused: bool,
}

/// The defaults: generic code over a scalar `T` implementing
/// `::appell_core::Scalar`, constants through its `from_f64`, shared
/// subexpressions bound once, parameter-only work hoisted, every symbol in
/// stage 0 and read by its name, no fused products.
///
/// ```
/// use appell_symbolic::{ConstantForm, EmitOptions, RustPath, ScalarType};
/// let o = EmitOptions::default();
/// assert_eq!(o.scalar, ScalarType::named("T"));
/// assert_eq!(
///     o.constant,
///     ConstantForm::FromF64 { scalar_trait: RustPath::absolute(&["appell_core", "Scalar"]) }
/// );
/// assert!(o.cse && o.hoist_parameters && !o.fused);
/// ```
impl Default for EmitOptions {
    fn default() -> Self {
        EmitOptions {
            scalar: ScalarType::named("T"),
            constant: ConstantForm::FromF64 {
                scalar_trait: RustPath::absolute(&["appell_core", "Scalar"]),
            },
            cse: true,
            hoist_parameters: true,
            symbol_text: BTreeMap::new(),
            symbol_stage: BTreeMap::new(),
            fused: false,
        }
    }
}

/// Emitted Rust code: statements and the expression of each output.
///
/// The statements use method-call syntax (`x.sin()`, `x.powi(20)`) on the
/// scalar, so the runtime's scalar trait must be in scope where they are
/// placed.
///
/// ```
/// use appell_symbolic::{EmitOptions, Graph, Program};
/// let mut g = Graph::new();
/// let m = g.parameter("m").unwrap();
/// let l = g.parameter("l").unwrap();
/// let e = g.parse("m*l^2*sin(q)*cos(q) + m*l^2*q").unwrap();
/// let program = Program::lower(&g, &[e]);
/// let code = program.to_rust(&g, &EmitOptions::default());
/// assert_eq!(code.hoisted, vec!["p0".to_string()]);      // m*l^2, once per parameter set
/// assert!(code.prepare.iter().any(|s| s.starts_with("let p0 = ")));
/// assert_eq!(code.outputs[0], "q.sin() * p0 * q.cos() + q * p0");
/// # let _ = (m, l);
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RustCode {
    /// Statements that compute the hoisted parameter-only values (they read
    /// parameters only).
    pub prepare: Vec<String>,
    /// Names bound by `prepare` that the body reads.
    pub hoisted: Vec<String>,
    /// Statements of the per-call body.
    pub body: Vec<String>,
    /// The same statements split by stage ([`EmitOptions::symbol_stage`]):
    /// `stages[s]` reads symbols of stages up to `s` only; constants are in
    /// stage 0. One entry when no symbol has a later stage.
    pub stages: Vec<Vec<String>>,
    /// One expression per root, valid after `body`.
    pub outputs: Vec<String>,
    /// Operations per call (body and outputs).
    pub ops: OpCount,
    /// Operations once per parameter set (prepare).
    pub prepare_ops: OpCount,
}

/// The same program as [`RustCode`], as tokens: every statement and
/// expression built token by token from the writer's fragments (nothing is
/// parsed), for code generators that assemble Rust with `quote!`.
///
/// The tokens are those of the text form, except float literals: they are
/// built from their value, so they are spelled without exponent and with the
/// suffix `f64` rather than `_f64` (same values).
///
/// ```
/// use appell_symbolic::{EmitOptions, Graph, Program};
/// let mut g = Graph::new();
/// let m = g.parameter("m").unwrap();
/// let l = g.parameter("l").unwrap();
/// let e = g.parse("m*l^2*sin(q)*cos(q) + m*l^2*q").unwrap();
/// let program = Program::lower(&g, &[e]);
/// let tokens = program.to_tokens(&g, &EmitOptions::default());
/// assert_eq!(tokens.prepare[0].to_string(), "let p0 = l * l * m ;");
/// assert_eq!(tokens.hoisted[0], "p0");
/// assert_eq!(tokens.outputs[0].to_string(), "q . sin () * p0 * q . cos () + q * p0");
/// # let _ = (m, l);
/// ```
#[derive(Clone, Debug)]
pub struct RustTokens {
    /// Statements that compute the hoisted parameter-only values
    /// ([`RustCode::prepare`]).
    pub prepare: Vec<TokenStream>,
    /// Names bound by `prepare` that the body reads.
    pub hoisted: Vec<Ident>,
    /// Statements of the per-call body.
    pub body: Vec<TokenStream>,
    /// The same statements split by stage ([`RustCode::stages`]).
    pub stages: Vec<Vec<TokenStream>>,
    /// One expression per root, valid after `body`.
    pub outputs: Vec<TokenStream>,
    /// Operations per call (body and outputs).
    pub ops: OpCount,
    /// Operations once per parameter set (prepare).
    pub prepare_ops: OpCount,
}

impl RustCode {
    /// A complete generic function computing all outputs at once (prepare and
    /// body together), for tests and small tools:
    /// `fn name<T: Trait>(symbols…) -> [T; N]`.
    pub fn function(&self, name: &str, scalar_trait: &str, args: &[String]) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "#[allow(clippy::all, unused_variables, unused_parens, non_snake_case)]\n\
             pub fn {name}<T: {scalar_trait}>({}) -> [T; {}] {{",
            args.iter()
                .map(|a| format!("{a}: T"))
                .collect::<Vec<_>>()
                .join(", "),
            self.outputs.len()
        );
        let mut seen = BTreeSet::new();
        for st in self.prepare.iter().chain(&self.body) {
            // A constant both sections bind is written once.
            if seen.insert(st.as_str()) {
                let _ = writeln!(s, "    {st}");
            }
        }
        let _ = writeln!(s, "    [{}]\n}}", self.outputs.join(", "));
        s
    }
}

impl RustCode {
    /// Two functions that keep the hoisting visible: `{name}_prepare(params)`
    /// returns the hoisted values, and `{name}(hoisted, params, state)`
    /// computes the outputs reading only those, the parameters and the state.
    /// A body that used a value internal to the preparation would not compile.
    pub fn split_functions(
        &self,
        name: &str,
        scalar_trait: &str,
        params: &[String],
        state: &[String],
    ) -> String {
        let h = self.hoisted.len();
        let typed = |v: &[String]| {
            v.iter()
                .map(|a| format!("{a}: T"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let mut s = String::new();
        let _ = writeln!(
            s,
            "#[allow(clippy::all, unused_variables, unused_parens, non_snake_case)]\n\
             pub fn {name}_prepare<T: {scalar_trait}>({}) -> [T; {h}] {{",
            typed(params)
        );
        for st in &self.prepare {
            let _ = writeln!(s, "    {st}");
        }
        let _ = writeln!(s, "    [{}]\n}}", self.hoisted.join(", "));
        let mut args = vec![format!("hoisted: &[T; {h}]")];
        if !params.is_empty() {
            args.push(typed(params));
        }
        if !state.is_empty() {
            args.push(typed(state));
        }
        let _ = writeln!(
            s,
            "#[allow(clippy::all, unused_variables, unused_parens, non_snake_case)]\n\
             pub fn {name}<T: {scalar_trait}>({}) -> [T; {}] {{",
            args.join(", "),
            self.outputs.len()
        );
        let _ = writeln!(s, "    let [{}] = *hoisted;", self.hoisted.join(", "));
        for st in &self.body {
            let _ = writeln!(s, "    {st}");
        }
        let _ = writeln!(s, "    [{}]\n}}", self.outputs.join(", "));
        s
    }
}
