//! Expressions: names (parameters, coordinates, inputs, time, frames'
//! axes, points), arithmetic on scalars, vectors and points, with their
//! kinds checked (a point minus a point is a vector; a point plus a point
//! is an error).

use proc_macro2::Span;
use syn::Ident;

use appell_symbolic::{Graph, Id, SymbolicError};

use super::builder::{engine_error, hint, Builder};
use super::Vec3;
use crate::ast::*;

/// A value of an expression.
#[derive(Clone, Copy)]
pub(super) enum Val {
    Scalar(Id),
    Vector(Vec3),
    Point(Vec3),
}

impl Val {
    /// "scalar", "vector" or "point", for messages.
    pub(super) fn kind(&self) -> &'static str {
        match self {
            Val::Scalar(_) => "scalar",
            Val::Vector(_) => "vector",
            Val::Point(_) => "point",
        }
    }
}

impl Builder<'_> {
    /// Checks a divisor: one that is identically zero is an error at
    /// `span` (returns false); one of parameters alone is recorded for
    /// `validate`, which names them when it is zero at run time.
    fn divisor(&mut self, d: Id, span: Span) -> bool {
        if self.g.is_zero(d) {
            self.cx.error_at(
                span,
                format!(
                    "division by zero in {}: this divisor is identically zero",
                    self.context
                ),
            );
            return false;
        }
        if self.g.is_parameter_only(d) && self.g.as_number(d).is_none() {
            self.divisors.push((d, self.context.clone()));
        }
        true
    }

    pub(super) fn scalar(&mut self, e: &Expr) -> Option<Id> {
        match self.eval(e)? {
            Val::Scalar(s) => Some(s),
            Val::Vector(_) => {
                self.cx.error_at(
                    e.span(),
                    "expected a scalar, found a vector; `dot(u, v)` or `norm(v)` makes a scalar of it, and a constraint may equate two vectors",
                );
                None
            }
            Val::Point(_) => {
                self.cx.error_at(
                    e.span(),
                    "expected a scalar, found a point; a point's coordinates are `dot(P - O, N.x)` and so on, and a constraint may equate two points (`P == Q`)",
                );
                None
            }
        }
    }

    pub(super) fn vector(&mut self, e: &Expr) -> Option<Vec3> {
        match self.eval(e)? {
            Val::Vector(v) => Some(v),
            Val::Scalar(_) => {
                self.cx.error_at(
                    e.span(),
                    "expected a vector (e.g. `m * g * N.x`), found a scalar",
                );
                None
            }
            Val::Point(_) => {
                self.cx.error_at(
                    e.span(),
                    "expected a vector, found a point (subtract another point to get a vector)",
                );
                None
            }
        }
    }

    pub(super) fn scale3(&mut self, v: Vec3, k: Id) -> Option<Vec3> {
        let mut out = v;
        for i in 0..3 {
            out[i] = self.g.mul(v[i], k).ok()?;
        }
        Some(out)
    }

    pub(super) fn eval(&mut self, e: &Expr) -> Option<Val> {
        let span = e.span();
        let r: Result<Option<Val>, SymbolicError> = (|| {
            Ok(Some(match e {
                Expr::Int(n, _) => Val::Scalar(self.g.int(*n)?),
                Expr::Float(x, _) => Val::Scalar(self.g.float(*x)?),
                Expr::Name(ident) => return Ok(self.name(ident)),
                Expr::Axis(frame, k, _) => {
                    let Some(fi) = self.frame_named(frame) else {
                        return Ok(None);
                    };
                    let r = self.frames[fi].rot;
                    Val::Vector([r[0][*k], r[1][*k], r[2][*k]])
                }
                Expr::Neg(a, _) => match self.eval(a) {
                    Some(Val::Scalar(s)) => Val::Scalar(self.g.neg(s)?),
                    Some(Val::Vector(v)) => {
                        let mut out = v;
                        for i in 0..3 {
                            out[i] = self.g.neg(v[i])?;
                        }
                        Val::Vector(out)
                    }
                    Some(Val::Point(_)) => {
                        self.cx.error_at(span, "a point cannot be negated");
                        return Ok(None);
                    }
                    None => return Ok(None),
                },
                Expr::Binary(op, a, b, _) => {
                    let (Some(x), Some(y)) = (self.eval(a), self.eval(b)) else {
                        return Ok(None);
                    };
                    if let (BinOp::Div, Val::Scalar(d)) = (op, y) {
                        if !self.divisor(d, b.span()) {
                            return Ok(None);
                        }
                    }
                    return self.binary(*op, x, y, span);
                }
                Expr::Call(f, args, _) => return self.call(f, args, span),
            }))
        })();
        match r {
            Ok(v) => v,
            Err(err) => {
                engine_error(self.cx, span, err);
                None
            }
        }
    }

    pub(super) fn name(&mut self, ident: &Ident) -> Option<Val> {
        let name = ident.to_string();
        let g = &mut self.g;
        if name == "t" {
            return g.sym(self.time).ok().map(Val::Scalar);
        }
        if let Some(p) = self.params.iter().find(|p| p.ident == name) {
            return g.sym(p.symbol).ok().map(Val::Scalar);
        }
        if let Some((_, c)) = self.coords.iter().find(|(c, _)| c == &name) {
            return g.sym(c.q).ok().map(Val::Scalar);
        }
        if let Some((_, s)) = self.inputs.iter().find(|(c, _)| c == &name) {
            return g.sym(*s).ok().map(Val::Scalar);
        }
        if let Some(p) = self.points.iter().find(|p| p.name == name) {
            return Some(Val::Point(p.pos));
        }
        if self.poisoned.contains(&name) {
            return None;
        }
        if self.points.iter().all(|p| p.name != name)
            && self.frames.iter().all(|f| f.name != name)
            && self.declared_below(ident)
        {
            return None;
        }
        if self.frames.iter().any(|f| f.name == name) {
            self.cx.error_spanned_by(
                ident,
                format!(
                    "`{name}` is a frame; its unit vectors are `{name}.x`, `{name}.y`, `{name}.z`"
                ),
            );
            return None;
        }
        let h = hint(&name, self.all_names());
        self.cx
            .error_spanned_by(ident, format!("unknown name `{name}`{h}"));
        None
    }

    pub(super) fn binary(
        &mut self,
        op: BinOp,
        x: Val,
        y: Val,
        span: Span,
    ) -> Result<Option<Val>, SymbolicError> {
        use Val::*;
        let g = &mut self.g;
        let each = |g: &mut Graph,
                    a: Vec3,
                    b: Vec3,
                    f: fn(&mut Graph, Id, Id) -> Result<Id, SymbolicError>|
         -> Result<Vec3, SymbolicError> {
            Ok([f(g, a[0], b[0])?, f(g, a[1], b[1])?, f(g, a[2], b[2])?])
        };
        let scaled = |g: &mut Graph, v: Vec3, k: Id| -> Result<Vec3, SymbolicError> {
            Ok([g.mul(v[0], k)?, g.mul(v[1], k)?, g.mul(v[2], k)?])
        };
        Ok(Some(match (op, x, y) {
            (BinOp::Add, Scalar(a), Scalar(b)) => Scalar(g.add(a, b)?),
            (BinOp::Sub, Scalar(a), Scalar(b)) => Scalar(g.sub(a, b)?),
            (BinOp::Mul, Scalar(a), Scalar(b)) => Scalar(g.mul(a, b)?),
            (BinOp::Div, Scalar(a), Scalar(b)) => Scalar(g.div(a, b)?),
            (BinOp::Add, Vector(a), Vector(b)) => Vector(each(g, a, b, Graph::add)?),
            (BinOp::Sub, Vector(a), Vector(b)) => Vector(each(g, a, b, Graph::sub)?),
            (BinOp::Add, Point(a), Vector(b)) | (BinOp::Add, Vector(b), Point(a)) => {
                Point(each(g, a, b, Graph::add)?)
            }
            (BinOp::Sub, Point(a), Vector(b)) => Point(each(g, a, b, Graph::sub)?),
            (BinOp::Sub, Point(a), Point(b)) => Vector(each(g, a, b, Graph::sub)?),
            (BinOp::Mul, Scalar(k), Vector(v)) | (BinOp::Mul, Vector(v), Scalar(k)) => {
                Vector(scaled(g, v, k)?)
            }
            (BinOp::Div, Vector(v), Scalar(k)) => {
                let inv = g.recip(k).map_err(|_| SymbolicError::DivisionByZero {
                    expr: "a vector".into(),
                })?;
                Vector(scaled(g, v, inv)?)
            }
            _ => {
                let kind = |v: &Val| match v {
                    Scalar(_) => "a scalar",
                    Vector(_) => "a vector",
                    Point(_) => "a point",
                };
                let sym = match op {
                    BinOp::Add => "+",
                    BinOp::Sub => "-",
                    BinOp::Mul => "*",
                    BinOp::Div => "/",
                };
                self.cx.error_at(
                    span,
                    format!("cannot apply `{sym}` to {} and {}", kind(&x), kind(&y)),
                );
                return Ok(None);
            }
        }))
    }
}
