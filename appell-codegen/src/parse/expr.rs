//! The model language's expressions, from syn's.

use syn::spanned::Spanned;

use crate::ast::*;

/// syn's expression to the model language's, rejecting what it lacks.
pub fn convert(e: &syn::Expr) -> syn::Result<Expr> {
    Ok(match e {
        syn::Expr::Lit(lit) => match &lit.lit {
            syn::Lit::Int(i) => Expr::Int(i.base10_parse()?, i.span()),
            syn::Lit::Float(f) => Expr::Float(f.base10_parse()?, f.span()),
            other => return Err(syn::Error::new(other.span(), "expected a number")),
        },
        syn::Expr::Path(p) => Expr::Name(
            p.path
                .get_ident()
                .cloned()
                .ok_or_else(|| syn::Error::new(p.span(), "expected a name"))?,
        ),
        syn::Expr::Paren(p) => convert(&p.expr)?,
        syn::Expr::Group(g) => convert(&g.expr)?,
        syn::Expr::Unary(u) if matches!(u.op, syn::UnOp::Neg(_)) => {
            Expr::Neg(Box::new(convert(&u.expr)?), u.span())
        }
        syn::Expr::Binary(b) => {
            let op = match b.op {
                syn::BinOp::Add(_) => BinOp::Add,
                syn::BinOp::Sub(_) => BinOp::Sub,
                syn::BinOp::Mul(_) => BinOp::Mul,
                syn::BinOp::Div(_) => BinOp::Div,
                _ => {
                    return Err(syn::Error::new(
                        b.op.span(),
                        "only `+ - * /` (and `==` in constraints) are allowed here",
                    ))
                }
            };
            Expr::Binary(
                op,
                Box::new(convert(&b.left)?),
                Box::new(convert(&b.right)?),
                b.span(),
            )
        }
        syn::Expr::Call(c) => {
            let func = match &*c.func {
                syn::Expr::Path(p) => p.path.get_ident().cloned(),
                _ => None,
            }
            .ok_or_else(|| syn::Error::new(c.func.span(), "expected a function name"))?;
            let args = c.args.iter().map(convert).collect::<syn::Result<_>>()?;
            Expr::Call(func, args, c.span())
        }
        syn::Expr::MethodCall(m) => {
            // `x.sin()`, `x.powi(2)`: method syntax for scalar functions.
            let mut args = vec![convert(&m.receiver)?];
            for a in &m.args {
                args.push(convert(a)?);
            }
            Expr::Call(m.method.clone(), args, m.span())
        }
        syn::Expr::Field(f) => {
            let frame = match &*f.base {
                syn::Expr::Path(p) => p.path.get_ident().cloned(),
                _ => None,
            }
            .ok_or_else(|| {
                syn::Error::new(
                    f.base.span(),
                    "expected a frame name before `.x`, `.y` or `.z`",
                )
            })?;
            let axis = match &f.member {
                syn::Member::Named(m) if m == "x" => 0,
                syn::Member::Named(m) if m == "y" => 1,
                syn::Member::Named(m) if m == "z" => 2,
                other => {
                    return Err(syn::Error::new(
                        other.span(),
                        "a frame's unit vectors are `.x`, `.y` and `.z`",
                    ))
                }
            };
            Expr::Axis(frame, axis, f.span())
        }
        other => {
            return Err(syn::Error::new(
                other.span(),
                "this is not part of the model language",
            ))
        }
    })
}
