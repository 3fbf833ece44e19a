//! Straight-line programs from the engine, as tokens.
//!
//! Each numeric function of the generated implementation is one program the
//! engine lowers (shared subexpressions bound once) and writes: statements
//! computing parameter-only values (`prepare`), the per-call statements
//! (`body`, or split into `stages` around numeric solves) and one
//! expression per output. This module asks the engine for them with the
//! options the generated code needs and hands them on as tokens.

use appell_symbolic::{
    ConstantForm, EmitOptions, Graph, Id, OpCount, Program, RustPath, RustTokens, ScalarType,
};
use proc_macro2::TokenStream;

/// The scalar the program is written for.
#[derive(Clone, Copy)]
pub enum Target {
    /// The generic scalar `__T`, constants through `Scalar::from_f64`;
    /// `hoist` moves parameter-only work into `prepare`.
    Generic {
        /// Whether parameter-only work is hoisted.
        hoist: bool,
    },
    /// Plain `f64` (the mass properties), nothing hoisted.
    F64,
}

/// An engine program as tokens.
pub struct Code {
    /// Statements computing the hoisted values.
    pub prepare: Vec<TokenStream>,
    /// The hoisted values' names.
    pub hoisted: Vec<TokenStream>,
    /// The per-call statements.
    pub body: Vec<TokenStream>,
    /// The per-call statements by stage (see `EmitOptions::symbol_stage`).
    pub stages: Vec<Vec<TokenStream>>,
    /// One expression per root.
    pub outputs: Vec<TokenStream>,
    /// Which roots are the constant 0.
    pub zero: Vec<bool>,
    /// Operations per call.
    pub ops: OpCount,
}

impl Code {
    /// `prepare` and `body`, in order, moved out (a long body is not
    /// copied token by token).
    pub fn take_statements(&mut self) -> TokenStream {
        let mut out = TokenStream::new();
        out.extend(std::mem::take(&mut self.prepare));
        out.extend(std::mem::take(&mut self.body));
        out
    }

    /// Stage `s`'s statements, moved out.
    pub fn take_stage(&mut self, s: usize) -> TokenStream {
        let mut out = TokenStream::new();
        if let Some(v) = self.stages.get_mut(s) {
            out.extend(std::mem::take(v));
        }
        out
    }
}

/// `{ parts }`, the parts moved in: interpolated into `quote!`, a group is
/// one token, where a long body would be copied token by token.
pub fn braced(parts: impl IntoIterator<Item = TokenStream>) -> proc_macro2::Group {
    let mut inner = TokenStream::new();
    inner.extend(parts);
    proc_macro2::Group::new(proc_macro2::Delimiter::Brace, inner)
}

/// The engine's options for `target`.
pub fn options(target: Target) -> EmitOptions {
    match target {
        Target::Generic { hoist } => EmitOptions {
            scalar: ScalarType::named("__T"),
            constant: ConstantForm::FromF64 {
                scalar_trait: RustPath::absolute(&["appell", "__private", "Scalar"]),
            },
            cse: true,
            hoist_parameters: hoist,
            symbol_text: Default::default(),
            symbol_stage: Default::default(),
            fused: true,
        },
        Target::F64 => EmitOptions {
            scalar: ScalarType::named("f64"),
            constant: ConstantForm::F64Literal,
            cse: true,
            hoist_parameters: false,
            symbol_text: Default::default(),
            symbol_stage: Default::default(),
            fused: false,
        },
    }
}

/// The program computing `roots`, written for `target`.
pub fn code(g: &Graph, roots: &[Id], target: Target) -> Code {
    code_with(g, roots, &options(target))
}

/// The program computing `roots`, written with `options`.
pub fn code_with(g: &Graph, roots: &[Id], options: &EmitOptions) -> Code {
    let zero = roots.iter().map(|&r| g.is_zero(r)).collect();
    from_tokens(Program::lower(g, roots).to_tokens(g, options), zero)
}

fn from_tokens(c: RustTokens, zero: Vec<bool>) -> Code {
    Code {
        zero,
        prepare: c.prepare,
        hoisted: c.hoisted.iter().map(|h| quote::quote!(#h)).collect(),
        body: c.body,
        stages: c.stages,
        outputs: c.outputs,
        ops: c.ops,
    }
}
