//! Function calls in expressions: `dt`, the elementary functions, `atan2`,
//! `powi`, `dot`, `cross`, `norm`, `unit`, `omega`, `velocity` and
//! `origin`. Norms of vectors made of frame axes are taken by Lagrange's
//! identity and the vector triple product, which keep their square roots
//! short.

use proc_macro2::Span;
use syn::Ident;

use appell_symbolic::{Func, Id, Number, SymbolicError};

use super::builder::{hint, Builder};
use super::expr::Val;
use super::Vec3;
use crate::algebra::{cross, dot};
use crate::ast::*;

impl Builder<'_> {
    /// |v|² of a vector expression by the identities of its construction,
    /// so that `norm` and `unit` of vectors made of frame axes stay small
    /// (differentiated twice, they reach the accelerations): |e|² = 1 for a
    /// frame's axis and for `unit(v)`, |k v|² = k²|v|²,
    /// |a ± b|² = |a|² ± 2 a·b + |b|², and Lagrange's identity |a × b|² = |a|²|b|² − (a·b)². `None`
    /// where no identity applies (the caller takes v·v).
    pub(super) fn norm_sq(&mut self, e: &Expr) -> Result<Option<Id>, SymbolicError> {
        Ok(match e {
            Expr::Axis(..) => Some(self.g.int(1)?),
            Expr::Neg(a, _) => self.norm_sq(a)?,
            Expr::Call(f, args, _) if f == "unit" && args.len() == 1 => Some(self.g.int(1)?),
            Expr::Call(f, args, _) if f == "cross" && args.len() == 2 => {
                let (Some(na), Some(nb)) = (
                    self.norm_sq_or_dot(&args[0])?,
                    self.norm_sq_or_dot(&args[1])?,
                ) else {
                    return Ok(None);
                };
                let Some(ab) = self.dot_exprs(&args[0], &args[1])? else {
                    return Ok(None);
                };
                let g = &mut self.g;
                let nn = g.mul(na, nb)?;
                let ab2 = g.mul(ab, ab)?;
                Some(g.sub(nn, ab2)?)
            }
            Expr::Binary(op @ (BinOp::Add | BinOp::Sub), a, b, _) => {
                let (Some(na), Some(nb)) = (self.norm_sq_or_dot(a)?, self.norm_sq_or_dot(b)?)
                else {
                    return Ok(None);
                };
                let Some(ab) = self.dot_exprs(a, b)? else {
                    return Ok(None);
                };
                let g = &mut self.g;
                let two_ab = g.scale(ab, Number::int(2))?;
                let cross_term = if *op == BinOp::Add {
                    two_ab
                } else {
                    g.neg(two_ab)?
                };
                Some(g.sum(&[na, nb, cross_term])?)
            }
            Expr::Binary(op @ (BinOp::Mul | BinOp::Div), a, b, _) => {
                let (k, v) = match (self.eval(a), self.eval(b)) {
                    (Some(Val::Scalar(_)), Some(Val::Vector(_))) if *op == BinOp::Mul => (a, b),
                    (Some(Val::Vector(_)), Some(Val::Scalar(_))) => (b, a),
                    _ => return Ok(None),
                };
                let (Some(Val::Scalar(k)), Some(nv)) = (self.eval(k), self.norm_sq_or_dot(v)?)
                else {
                    return Ok(None);
                };
                let g = &mut self.g;
                let k2 = g.mul(k, k)?;
                Some(if *op == BinOp::Mul {
                    g.mul(k2, nv)?
                } else {
                    g.div(nv, k2)?
                })
            }
            _ => None,
        })
    }

    /// A double cross product by the vector triple product identity,
    /// (x × y) × c = y (x·c) − x (y·c) and a × (x × y) = x (a·y) − y (a·x),
    /// with the dot products by [`Self::dot_exprs`] (so (e × f) × e = f − (e·f) e
    /// for a unit e). `None` when neither argument is a cross product.
    pub(super) fn double_cross(
        &mut self,
        a: &Expr,
        b: &Expr,
    ) -> Result<Option<Vec3>, SymbolicError> {
        let as_cross = |e: &Expr| match e {
            Expr::Call(f, args, _) if f == "cross" && args.len() == 2 => {
                Some((args[0].clone(), args[1].clone()))
            }
            _ => None,
        };
        // (p, q, r): the result is p (q·r)... written as y (x·c) − x (y·c).
        let (x, y, c, sign) = if let Some((x, y)) = as_cross(a) {
            (x, y, b.clone(), false)
        } else if let Some((x, y)) = as_cross(b) {
            // a × (x × y) = −(x × y) × a
            (x, y, a.clone(), true)
        } else {
            return Ok(None);
        };
        let (Some(xc), Some(yc)) = (self.dot_exprs(&x, &c)?, self.dot_exprs(&y, &c)?) else {
            return Ok(None);
        };
        let (Some(Val::Vector(vx)), Some(Val::Vector(vy))) = (self.eval(&x), self.eval(&y)) else {
            return Ok(None);
        };
        let g = &mut self.g;
        let mut out = [vx[0]; 3];
        for i in 0..3 {
            let p = g.mul(vy[i], xc)?;
            let q = g.mul(vx[i], yc)?;
            out[i] = if sign { g.sub(q, p)? } else { g.sub(p, q)? };
        }
        Ok(Some(out))
    }

    /// [`Self::norm_sq`], or v·v by components.
    pub(super) fn norm_sq_or_dot(&mut self, e: &Expr) -> Result<Option<Id>, SymbolicError> {
        if let Some(n) = self.norm_sq(e)? {
            return Ok(Some(n));
        }
        let Some(Val::Vector(v)) = self.eval(e) else {
            return Ok(None);
        };
        Ok(Some(dot(&mut self.g, v, v)?))
    }

    /// a·b of two vector expressions; a triple product with a repeated
    /// vector, (x × y)·x or (x × y)·y, is zero.
    pub(super) fn dot_exprs(&mut self, a: &Expr, b: &Expr) -> Result<Option<Id>, SymbolicError> {
        let (Some(Val::Vector(va)), Some(Val::Vector(vb))) = (self.eval(a), self.eval(b)) else {
            return Ok(None);
        };
        if va == vb {
            return self.norm_sq_or_dot(a);
        }
        for (c, other) in [(a, vb), (b, va)] {
            if let Expr::Call(f, args, _) = c {
                if f == "cross" && args.len() == 2 {
                    for x in args {
                        if let Some(Val::Vector(vx)) = self.eval(x) {
                            if vx == other {
                                return Ok(Some(self.g.int(0)?));
                            }
                        }
                    }
                }
            }
        }
        Ok(Some(dot(&mut self.g, va, vb)?))
    }

    /// A call `f(args)`: a function of this list, with its arity checked.
    pub(super) fn call(
        &mut self,
        f: &Ident,
        args: &[Expr],
        span: Span,
    ) -> Result<Option<Val>, SymbolicError> {
        let name = f.to_string();
        let Some(&(_, arity)) = FUNCTIONS.iter().find(|(n, _)| *n == name) else {
            let h = hint(&name, FUNCTIONS.iter().map(|(n, _)| n.to_string()));
            let all: Vec<&str> = FUNCTIONS.iter().map(|(n, _)| *n).collect();
            self.cx.error_spanned_by(
                f,
                format!(
                    "unknown function `{name}`{h} (the functions: {})",
                    all.join(", ")
                ),
            );
            return Ok(None);
        };
        if args.len() != arity {
            self.cx.error_spanned_by(
                f,
                format!("`{name}` takes {arity} argument(s), found {}", args.len()),
            );
            return Ok(None);
        }
        match name.as_str() {
            "dt" => self.call_dt(&args[0]),
            "atan2" => {
                let (Some(y), Some(x)) = (self.scalar(&args[0]), self.scalar(&args[1])) else {
                    return Ok(None);
                };
                Ok(Some(Val::Scalar(self.g.atan2(y, x)?)))
            }
            "powi" => self.call_powi(args),
            "powf" | "min" | "max" => {
                let (Some(a), Some(b)) = (self.scalar(&args[0]), self.scalar(&args[1])) else {
                    return Ok(None);
                };
                let v = match name.as_str() {
                    "powf" => self.g.powf(a, b)?,
                    "min" => self.g.min(a, b)?,
                    _ => self.g.max(a, b)?,
                };
                Ok(Some(Val::Scalar(v)))
            }
            "select" => {
                let (Some(c), Some(a), Some(b)) = (
                    self.scalar(&args[0]),
                    self.scalar(&args[1]),
                    self.scalar(&args[2]),
                ) else {
                    return Ok(None);
                };
                Ok(Some(Val::Scalar(self.g.select(c, a, b)?)))
            }
            "omega" | "velocity" => self.call_motion(&name, &args[0]),
            "origin" => Ok(self.call_origin(&args[0])),
            "dot" | "cross" => self.call_product(&name, args),
            "norm" | "unit" => self.call_norm(&name, &args[0], span),
            _ => {
                // The elementary functions of one argument (FUNCTIONS lists
                // nothing else of arity 1 that reaches here).
                let (Some(f), Some(x)) = (Func::from_name(&name), self.scalar(&args[0])) else {
                    return Ok(None);
                };
                Ok(Some(Val::Scalar(self.g.func(f, x)?)))
            }
        }
    }

    /// `dt(q)` is q's rate symbol; `dt(e)` the time derivative of e.
    fn call_dt(&mut self, arg: &Expr) -> Result<Option<Val>, SymbolicError> {
        if let Expr::Name(i) = arg {
            if let Some((_, c)) = self.coords.iter().find(|(c, _)| c == i) {
                return Ok(Some(Val::Scalar(self.g.sym(c.rate)?)));
            }
        }
        let Some(x) = self.scalar(arg) else {
            return Ok(None);
        };
        let d = self.g.time_derivative(x, &self.rules)?;
        Ok(Some(Val::Scalar(d)))
    }

    /// `powi(x, n)` with n an integer literal.
    fn call_powi(&mut self, args: &[Expr]) -> Result<Option<Val>, SymbolicError> {
        let Some(x) = self.scalar(&args[0]) else {
            return Ok(None);
        };
        let n = match &args[1] {
            Expr::Int(n, _) => *n,
            Expr::Neg(inner, _) => match **inner {
                Expr::Int(n, _) => -n,
                _ => {
                    self.cx.error_at(
                        args[1].span(),
                        "the exponent of `powi` is an integer literal",
                    );
                    return Ok(None);
                }
            },
            other => {
                self.cx
                    .error_at(other.span(), "the exponent of `powi` is an integer literal");
                return Ok(None);
            }
        };
        Ok(Some(Val::Scalar(self.g.powi(x, n)?)))
    }

    /// `omega(F)`, a frame's angular velocity, or `velocity(P)`, a point's.
    fn call_motion(&mut self, name: &str, arg: &Expr) -> Result<Option<Val>, SymbolicError> {
        let Expr::Name(target) = arg else {
            let what = if name == "omega" {
                "a frame"
            } else {
                "a point"
            };
            self.cx
                .error_at(arg.span(), format!("`{name}` takes the name of {what}"));
            return Ok(None);
        };
        if name == "omega" {
            let Some(fi) = self.frame_named(target) else {
                return Ok(None);
            };
            return Ok(Some(Val::Vector(self.frames[fi].omega)));
        }
        let Some(p) = self.point_named(target) else {
            return Ok(None);
        };
        let v = [
            self.g.time_derivative(p[0], &self.rules)?,
            self.g.time_derivative(p[1], &self.rules)?,
            self.g.time_derivative(p[2], &self.rules)?,
        ];
        Ok(Some(Val::Vector(v)))
    }

    /// `origin(F)`: the origin point of a frame a joint made (`F_origin`),
    /// O for N.
    fn call_origin(&mut self, arg: &Expr) -> Option<Val> {
        let Expr::Name(frame) = arg else {
            self.cx
                .error_at(arg.span(), "`origin` takes the name of a frame");
            return None;
        };
        if frame == "N" {
            return Some(Val::Point(self.points[0].pos));
        }
        let point = self
            .origins
            .iter()
            .find(|(f, _)| f == frame)
            .map(|(_, p)| p.clone());
        match point {
            Some(p) => self.point_named(&p).map(Val::Point),
            None => {
                if self.frame_named(frame).is_some() {
                    self.cx.error_spanned_by(
                        frame,
                        format!("frame `{frame}` was not made by a joint, so it has no origin; name a point instead"),
                    );
                }
                None
            }
        }
    }

    /// `dot(a, b)` or `cross(a, b)`; a cross product of a cross product
    /// by the triple product rule.
    fn call_product(&mut self, name: &str, args: &[Expr]) -> Result<Option<Val>, SymbolicError> {
        let (Some(a), Some(b)) = (self.vector(&args[0]), self.vector(&args[1])) else {
            return Ok(None);
        };
        if name == "dot" {
            Ok(Some(Val::Scalar(dot(&mut self.g, a, b)?)))
        } else if let Some(v) = self.double_cross(&args[0], &args[1])? {
            Ok(Some(Val::Vector(v)))
        } else {
            Ok(Some(Val::Vector(cross(&mut self.g, a, b)?)))
        }
    }

    /// `norm(v)` or `unit(v)`; the squared length is recorded so that the
    /// generated code can name a zero-length argument at run time.
    fn call_norm(
        &mut self,
        name: &str,
        arg: &Expr,
        span: Span,
    ) -> Result<Option<Val>, SymbolicError> {
        let Some(v) = self.vector(arg) else {
            return Ok(None);
        };
        let n2 = match self.norm_sq(arg)? {
            Some(n2) => n2,
            None => dot(&mut self.g, v, v)?,
        };
        if self.g.is_zero(n2) {
            self.cx.error_at(
                span,
                format!("`{name}` of a vector that is identically zero"),
            );
            return Ok(None);
        }
        self.norms.push((
            n2,
            format!("the argument of `{name}(...)` in {}", self.context),
        ));
        let n = self.g.sqrt(n2)?;
        if name == "norm" {
            return Ok(Some(Val::Scalar(n)));
        }
        let inv = self.g.recip(n)?;
        Ok(Some(Val::Vector([
            self.g.mul(v[0], inv)?,
            self.g.mul(v[1], inv)?,
            self.g.mul(v[2], inv)?,
        ])))
    }
}

/// The functions expressions may call, with their arity.
const FUNCTIONS: &[(&str, usize)] = &[
    ("dt", 1),
    ("sin", 1),
    ("cos", 1),
    ("tan", 1),
    ("exp", 1),
    ("ln", 1),
    ("sqrt", 1),
    ("abs", 1),
    ("sinh", 1),
    ("cosh", 1),
    ("tanh", 1),
    ("asin", 1),
    ("acos", 1),
    ("atan", 1),
    ("sign", 1),
    ("atan2", 2),
    ("powi", 2),
    ("powf", 2),
    ("min", 2),
    ("max", 2),
    ("select", 3),
    ("dot", 2),
    ("cross", 2),
    ("norm", 1),
    ("unit", 1),
    ("omega", 1),
    ("velocity", 1),
    ("origin", 1),
];
