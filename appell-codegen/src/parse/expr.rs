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
                syn::BinOp::BitXor(_) => {
                    return Err(syn::Error::new(
                        b.op.span(),
                        "`^` is not a power here: write `powi(x, 3)` for an integer power \
                         or `powf(x, y)` for a real one",
                    ))
                }
                _ => {
                    return Err(syn::Error::new(
                        b.op.span(),
                        "only `+ - * /` (and `==` in constraints, `>` `<` in an `if`) \
                         are allowed here",
                    ))
                }
            };
            if let syn::Expr::Unary(u) = &*b.right {
                if matches!(u.op, syn::UnOp::Deref(_)) && matches!(b.op, syn::BinOp::Mul(_)) {
                    return Err(syn::Error::new(
                        b.op.span(),
                        "`**` is not a power here: write `powi(x, 3)` for an integer power \
                         or `powf(x, y)` for a real one",
                    ));
                }
            }
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
        syn::Expr::If(i) => conditional(i)?,
        syn::Expr::Block(b) => block_value(&b.block)?,
        other => {
            return Err(syn::Error::new(
                other.span(),
                "this is not part of the model language",
            ))
        }
    })
}

/// `if a > b { x } else { y }` (also `<`, `>=`, `<=`, and `else if`) as
/// `select(a − b, x, y)`. `>=` and `<=` are `>` and `<`: at a = b exactly
/// the `else` branch is taken.
fn conditional(i: &syn::ExprIf) -> syn::Result<Expr> {
    let syn::Expr::Binary(cmp) = &*i.cond else {
        return Err(syn::Error::new(
            i.cond.span(),
            "the condition is a comparison: `a > b`, `a < b`, `a >= b` or `a <= b`",
        ));
    };
    let (left, right) = (convert(&cmp.left)?, convert(&cmp.right)?);
    let span = cmp.span();
    let difference = match cmp.op {
        syn::BinOp::Gt(_) | syn::BinOp::Ge(_) => {
            Expr::Binary(BinOp::Sub, Box::new(left), Box::new(right), span)
        }
        syn::BinOp::Lt(_) | syn::BinOp::Le(_) => {
            Expr::Binary(BinOp::Sub, Box::new(right), Box::new(left), span)
        }
        _ => {
            return Err(syn::Error::new(
                cmp.op.span(),
                "the condition is a comparison: `>`, `<`, `>=` or `<=`",
            ))
        }
    };
    let then = block_value(&i.then_branch)?;
    let Some((_, otherwise)) = &i.else_branch else {
        return Err(syn::Error::new(
            i.span(),
            "an `if` in an expression needs an `else` branch",
        ));
    };
    let otherwise = convert(otherwise)?;
    let select = syn::Ident::new("select", i.if_token.span);
    Ok(Expr::Call(
        select,
        vec![difference, then, otherwise],
        i.span(),
    ))
}

/// The value of a block holding one expression.
fn block_value(b: &syn::Block) -> syn::Result<Expr> {
    match b.stmts.as_slice() {
        [syn::Stmt::Expr(e, None)] => convert(e),
        _ => Err(syn::Error::new(
            b.span(),
            "a branch holds one expression, without `;`",
        )),
    }
}
