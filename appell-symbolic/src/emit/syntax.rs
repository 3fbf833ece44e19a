//! The pieces of Rust the writer puts together: the typed choices of
//! [`EmitOptions`](super::EmitOptions) ([`RustPath`], [`ScalarType`],
//! [`ConstantForm`]) and the fragments of written code ([`Frag`], [`Let`]).
//!
//! The writer decides everything (names, what is bound, parentheses, fused
//! products) once, as a fragment tree; a fragment only knows how it reads.
//! It renders to text ([`Frag::write_text`], the spacing of
//! [`RustCode`](super::RustCode)) and to tokens ([`Frag::tokens`],
//! [`RustTokens`](super::RustTokens)) by the same tree, so the two forms
//! cannot disagree on the code, and neither is parsed from the other.

use std::fmt::{self, Write};

use proc_macro2::{Delimiter, Group, Ident, Literal, Punct, Spacing, Span, TokenStream, TokenTree};
use quote::{quote, ToTokens, TokenStreamExt};

use super::EmitOptions;

/// Whether `s` reads as one Rust identifier (keywords included).
fn is_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    let Some(first) = chars.next() else {
        return false;
    };
    (first == '_' || first.is_alphabetic())
        && chars.all(|c| c == '_' || c.is_alphanumeric())
        && s != "_"
}

/// The identifier `name` with the call site's span.
///
/// # Panics
///
/// If `name` is not a Rust identifier.
fn ident(name: &str) -> Ident {
    assert!(
        is_identifier(name),
        "`{name}` is not a Rust identifier, so it cannot be written as a token"
    );
    Ident::new(name, Span::call_site())
}

/// A path to a type or trait, such as `T`, `f64` or
/// `::appell_core::Scalar`: identifiers separated by `::`, optionally
/// starting at the crate root.
///
/// ```
/// use appell_symbolic::RustPath;
/// assert_eq!(RustPath::local("T").to_string(), "T");
/// let scalar = RustPath::absolute(&["appell_core", "Scalar"]);
/// assert_eq!(scalar.to_string(), "::appell_core::Scalar");
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct RustPath {
    /// Whether the path starts with `::`.
    absolute: bool,
    /// The identifiers, outermost first (at least one).
    segments: Vec<String>,
}

impl RustPath {
    /// A one-identifier path, resolved where the code is placed (`T`,
    /// `f64`).
    ///
    /// # Panics
    ///
    /// If `name` is not a Rust identifier.
    pub fn local(name: &str) -> RustPath {
        RustPath::new(false, &[name])
    }

    /// A path from the crate root: `::a::b::c` for `["a", "b", "c"]`.
    ///
    /// # Panics
    ///
    /// If `segments` is empty or one is not a Rust identifier.
    pub fn absolute(segments: &[&str]) -> RustPath {
        RustPath::new(true, segments)
    }

    fn new(absolute: bool, segments: &[&str]) -> RustPath {
        assert!(!segments.is_empty(), "a path has at least one segment");
        for s in segments {
            assert!(is_identifier(s), "`{s}` is not a Rust identifier");
        }
        RustPath {
            absolute,
            segments: segments.iter().map(|s| s.to_string()).collect(),
        }
    }
}

impl fmt::Display for RustPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (k, s) in self.segments.iter().enumerate() {
            if self.absolute || k > 0 {
                f.write_str("::")?;
            }
            f.write_str(s)?;
        }
        Ok(())
    }
}

impl ToTokens for RustPath {
    fn to_tokens(&self, out: &mut TokenStream) {
        for (k, s) in self.segments.iter().enumerate() {
            if self.absolute || k > 0 {
                out.append(Punct::new(':', Spacing::Joint));
                out.append(Punct::new(':', Spacing::Alone));
            }
            out.append(ident(s));
        }
    }
}

/// The scalar type of the emitted code: a generic parameter (`T`) or a
/// concrete type (`f64`). Constants are bound with this type annotation.
///
/// ```
/// use appell_symbolic::{RustPath, ScalarType};
/// assert_eq!(ScalarType::named("__T").to_string(), "__T");
/// let f = ScalarType::path(RustPath::absolute(&["core", "primitive", "f64"]));
/// assert_eq!(f.to_string(), "::core::primitive::f64");
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct ScalarType(RustPath);

impl ScalarType {
    /// The type named by one identifier.
    ///
    /// # Panics
    ///
    /// If `name` is not a Rust identifier.
    pub fn named(name: &str) -> ScalarType {
        ScalarType(RustPath::local(name))
    }

    /// The type at `path`.
    pub fn path(path: RustPath) -> ScalarType {
        ScalarType(path)
    }

    /// The type's path.
    pub fn as_path(&self) -> &RustPath {
        &self.0
    }
}

impl fmt::Display for ScalarType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.fmt(f)
    }
}

impl ToTokens for ScalarType {
    fn to_tokens(&self, out: &mut TokenStream) {
        self.0.to_tokens(out);
    }
}

/// How a constant becomes a value of the scalar type.
///
/// ```
/// use appell_symbolic::{ConstantForm, RustPath};
/// // Generic code converts through the scalar trait:
/// // `<T as ::appell_core::Scalar>::from_f64(0.5)`.
/// let generic = ConstantForm::FromF64 {
///     scalar_trait: RustPath::absolute(&["appell_core", "Scalar"]),
/// };
/// // Code over plain `f64` writes the literal with its type: `0.5_f64`.
/// let concrete = ConstantForm::F64Literal;
/// # let _ = (generic, concrete);
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum ConstantForm {
    /// `<S as scalar_trait>::from_f64(lit)`, where `S` is the scalar type:
    /// for a generic scalar whose trait converts from `f64`.
    FromF64 {
        /// The trait providing `from_f64`.
        scalar_trait: RustPath,
    },
    /// The `f64` literal itself, suffixed (`lit_f64`): for a scalar that is
    /// `f64`. In the token form the suffix is written without the
    /// underscore (`0.5f64`), the spelling `proc_macro2` builds.
    F64Literal,
}

/// How tightly an expression binds, loosest first: an operand of a
/// tighter operation is parenthesized.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(super) enum Prec {
    Sum = 0,
    Product = 1,
    Unary = 2,
    Atom = 3,
}

/// A binary operator.
#[derive(Clone, Copy)]
pub(super) enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
}

impl BinOp {
    fn symbol(self) -> char {
        match self {
            BinOp::Add => '+',
            BinOp::Sub => '-',
            BinOp::Mul => '*',
            BinOp::Div => '/',
        }
    }
}

/// A fragment of an expression, as the writer decided it (parentheses
/// included: a fragment adds none of its own).
#[derive(Clone)]
pub(super) enum Frag {
    /// A binding or a symbol: `name`.
    Name(String),
    /// An integer argument (`powi`'s exponent).
    Int(i32),
    /// A constant converted to the scalar ([`EmitOptions::constant`]).
    Constant(f64),
    /// `l op r`.
    Binary(Box<Frag>, BinOp, Box<Frag>),
    /// `-x`.
    Neg(Box<Frag>),
    /// `(x)`.
    Paren(Box<Frag>),
    /// `receiver.method(args, …)`.
    Method(Box<Frag>, &'static str, Vec<Frag>),
}

impl Frag {
    /// `(x)` when `x` binds looser than `min`, else `x`.
    pub(super) fn wrap((x, p): (Frag, Prec), min: Prec) -> Frag {
        if p < min {
            Frag::Paren(Box::new(x))
        } else {
            x
        }
    }

    /// The text of the fragment, appended to `out`.
    pub(super) fn write_text(&self, o: &EmitOptions, out: &mut String) {
        match self {
            Frag::Name(n) => out.push_str(n),
            Frag::Int(e) => {
                let _ = write!(out, "{e}");
            }
            Frag::Constant(x) => match &o.constant {
                ConstantForm::FromF64 { scalar_trait } => {
                    let _ = write!(out, "<{} as {scalar_trait}>::from_f64({x:?})", o.scalar);
                }
                ConstantForm::F64Literal => {
                    let _ = write!(out, "{x:?}_f64");
                }
            },
            Frag::Binary(l, op, r) => {
                l.write_text(o, out);
                let _ = write!(out, " {} ", op.symbol());
                r.write_text(o, out);
            }
            Frag::Neg(x) => {
                out.push('-');
                x.write_text(o, out);
            }
            Frag::Paren(x) => {
                out.push('(');
                x.write_text(o, out);
                out.push(')');
            }
            Frag::Method(recv, m, args) => {
                recv.write_text(o, out);
                out.push('.');
                out.push_str(m);
                out.push('(');
                for (k, a) in args.iter().enumerate() {
                    if k > 0 {
                        out.push_str(", ");
                    }
                    a.write_text(o, out);
                }
                out.push(')');
            }
        }
    }

    /// The tokens of the fragment, appended to `out`.
    pub(super) fn tokens(&self, o: &EmitOptions, out: &mut TokenStream) {
        match self {
            Frag::Name(n) => out.append(ident(n)),
            Frag::Int(e) => {
                if *e < 0 {
                    out.append(Punct::new('-', Spacing::Alone));
                }
                out.append(Literal::u32_unsuffixed(e.unsigned_abs()));
            }
            Frag::Constant(x) => {
                let lit = float_tokens(*x, &o.constant);
                match &o.constant {
                    ConstantForm::FromF64 { scalar_trait } => {
                        let ty = &o.scalar;
                        out.extend(quote!(<#ty as #scalar_trait>::from_f64(#lit)));
                    }
                    ConstantForm::F64Literal => out.extend(lit),
                }
            }
            Frag::Binary(l, op, r) => {
                l.tokens(o, out);
                out.append(Punct::new(op.symbol(), Spacing::Alone));
                r.tokens(o, out);
            }
            Frag::Neg(x) => {
                out.append(Punct::new('-', Spacing::Alone));
                x.tokens(o, out);
            }
            Frag::Paren(x) => {
                let mut inner = TokenStream::new();
                x.tokens(o, &mut inner);
                out.append(Group::new(Delimiter::Parenthesis, inner));
            }
            Frag::Method(recv, m, args) => {
                recv.tokens(o, out);
                out.append(Punct::new('.', Spacing::Alone));
                out.append(ident(m));
                let mut inner = TokenStream::new();
                for (k, a) in args.iter().enumerate() {
                    if k > 0 {
                        inner.append(Punct::new(',', Spacing::Alone));
                    }
                    a.tokens(o, &mut inner);
                }
                out.append(Group::new(Delimiter::Parenthesis, inner));
            }
        }
    }
}

/// A float literal as tokens: a `-` for a negative value, then the
/// magnitude (suffixed for [`ConstantForm::F64Literal`]). The literal is
/// built from the value, so it reads back as exactly that `f64`; its
/// spelling is the shortest decimal that does: unsuffixed `0.5`, `2.0`,
/// suffixed `0.5f64`, `2f64`, `0f64`; very small and very large magnitudes
/// in positional notation, where the text form writes an exponent.
fn float_tokens(x: f64, form: &ConstantForm) -> TokenStream {
    let mut out = TokenStream::new();
    if x.is_sign_negative() {
        out.append(Punct::new('-', Spacing::Alone));
    }
    let lit = match form {
        ConstantForm::FromF64 { .. } => Literal::f64_unsuffixed(x.abs()),
        ConstantForm::F64Literal => Literal::f64_suffixed(x.abs()),
    };
    out.append(TokenTree::Literal(lit));
    out
}

/// One statement: `let name = value;`, or `let name: S = value;` with the
/// scalar type `S` when `typed`.
#[derive(Clone)]
pub(super) struct Let {
    pub(super) name: String,
    pub(super) typed: bool,
    pub(super) value: Frag,
}

impl Let {
    /// The statement as text.
    pub(super) fn text(&self, o: &EmitOptions) -> String {
        let mut s = format!("let {}", self.name);
        if self.typed {
            let _ = write!(s, ": {}", o.scalar);
        }
        s.push_str(" = ");
        self.value.write_text(o, &mut s);
        s.push(';');
        s
    }

    /// The statement as tokens.
    pub(super) fn tokens(&self, o: &EmitOptions) -> TokenStream {
        let name = ident(&self.name);
        let mut value = TokenStream::new();
        self.value.tokens(o, &mut value);
        if self.typed {
            let ty = &o.scalar;
            quote!(let #name: #ty = #value;)
        } else {
            quote!(let #name = #value;)
        }
    }

    /// The name bound, as a token.
    pub(super) fn name_token(name: &str) -> Ident {
        ident(name)
    }
}

/// An expression as text.
pub(super) fn text(f: &Frag, o: &EmitOptions) -> String {
    let mut s = String::new();
    f.write_text(o, &mut s);
    s
}

/// An expression as tokens.
pub(super) fn tokens(f: &Frag, o: &EmitOptions) -> TokenStream {
    let mut t = TokenStream::new();
    f.tokens(o, &mut t);
    t
}
