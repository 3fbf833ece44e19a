//! # appell-codegen
//!
//! Everything `#[derive(Appell)]` does, as a plain library so each stage can
//! be tested on its own:
//!
//! 1. [`parse`]: `#[appell(...)]` attributes → [`ast::ModelAst`] (syntax only);
//! 2. [`model`]: names resolved, kinematics built in the symbolic engine
//!    ([`model::Kinematics`]: the model and its twin);
//! 3. [`derivation`]: Appell's equations, one module per stage of the
//!    method (Wang & Pao 2003, Secs. III B-C, IV B) → [`derivation::Derivation`];
//! 4. [`emit`]: the `Model` implementation as tokens, built with `quote!`.
//!
//! Errors are collected with spans ([`ctxt::Ctxt`]) and reported together;
//! on error a stub implementation is emitted beside `compile_error!` so the
//! user sees only the real errors.
#![warn(missing_docs)]
// The derivation indexes rows, columns and speeds (k, l, r as in the paper);
// index loops keep the formulas recognisable.
#![allow(clippy::needless_range_loop)]

pub mod algebra;
pub mod ast;
pub mod ctxt;
pub mod derivation;
pub mod emit;
pub mod model;
pub mod parse;
pub(crate) mod physical;
pub mod probe;

pub use parse::FileRoots;

use proc_macro2::TokenStream;

/// Expands `#[derive(Appell)]` on `input`: the `Model` implementation, or
/// the errors (each spanned by the attribute at fault) beside a stub.
///
/// ```
/// let input: syn::DeriveInput = syn::parse_str(r#"
///     #[appell(coordinates(q), speeds(q))]
///     #[appell(point(P = O + l * sin(q) * N.x - l * cos(q) * N.y), particle(P, mass = m))]
///     #[appell(gravity(-g * N.y))]
///     struct Pendulum { m: f64, l: f64, g: f64 }
/// "#).unwrap();
/// let out = appell_codegen::expand(&input).to_string();
/// assert!(out.contains("impl :: appell :: __private :: Model for Pendulum"));
/// assert!(!out.contains("compile_error"));
///
/// // A misspelled coordinate is an error at the attribute, with a hint.
/// let input: syn::DeriveInput = syn::parse_str(r#"
///     #[appell(coordinates(q), speeds(q))]
///     #[appell(point(P = O + l * sin(qq) * N.x), particle(P, mass = m))]
///     struct Pendulum { m: f64, l: f64 }
/// "#).unwrap();
/// let out = appell_codegen::expand(&input).to_string();
/// assert!(out.contains("compile_error"));
/// assert!(out.contains("did you mean `q`?"), "{out}");
/// ```
pub fn expand(input: &syn::DeriveInput) -> TokenStream {
    expand_with(
        input,
        &FileRoots::from_env(),
        &derivation::Options::default(),
    )
}

/// [`expand`], reading the files a model names (`urdf(...)`) relative to
/// `manifest_dir` instead of the environment's `CARGO_MANIFEST_DIR` (tools
/// that expand models of several crates, such as the snapshot test).
pub fn expand_in(input: &syn::DeriveInput, manifest_dir: Option<&std::path::Path>) -> TokenStream {
    let roots = FileRoots::new(manifest_dir, None);
    expand_with(input, &roots, &derivation::Options::default())
}

/// [`expand`] with the files a model names looked for from `roots` (the
/// derive adds the directory of the model's source file) and the
/// derivation's cost-driven choices forced by `options` (tests that compare
/// forms: a model written with joints is the model written with frames once
/// the structured form is left out).
///
/// ```
/// use appell_codegen::{derivation::Options, expand_with, FileRoots};
///
/// let input: syn::DeriveInput = syn::parse_str(r#"
///     #[appell(joint(j, revolute(z), parent = N, child = A))]
///     #[appell(body(a, frame = A, mass = 1, center = origin(A) + 0.2 * A.x, inertia = principal(1, 1, 1)))]
///     struct Arm;
/// "#).unwrap();
/// let closed = Options { closed_form_only: true, ..Options::default() };
/// let out = expand_with(&input, &FileRoots::default(), &closed).to_string();
/// assert!(out.contains("form : \"closed form\""), "{out}");
/// ```
pub fn expand_with(
    input: &syn::DeriveInput,
    roots: &FileRoots,
    options: &derivation::Options,
) -> TokenStream {
    let cx = ctxt::Ctxt::new();
    let ast = parse::parse_in(&cx, input, roots);
    let model = if cx.has_errors() {
        None
    } else {
        model::build(&cx, &ast)
    };
    // The full derivation, then each scene's from it (its effects' loads
    // only: kinematics, M and the elimination are shared).
    let derived = model.and_then(|k| derivation::derive_with(&cx, k, options));
    let tokens = derived.map(|d| emit::emit(&d, &ast.vis));
    match cx.check() {
        Ok(()) => tokens.expect("no errors means a derivation"),
        Err(err) => {
            let mut out = err.to_compile_error();
            let scenes: Vec<syn::Ident> = ast.scenes.iter().map(|s| s.name.clone()).collect();
            out.extend(emit::stub(&input.ident, &scenes, &ast.vis));
            out
        }
    }
}
