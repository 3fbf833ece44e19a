//! Force elements: springs, dampers and friction between points or on a
//! joint, and a motor's saturation, written out as the loads they are
//! (`force(...)` and `torque(...)` items), each in an effect of its own so
//! that a scene may leave it out.

use syn::parse::ParseStream;
use syn::{Ident, Token};

use super::expr::convert;
use super::items::{expr_ident, key_values};
use crate::ast::*;
use crate::parse::keywords as kw;

impl JointElements {
    /// Takes `key = value` when it names an element.
    pub(super) fn set(&mut self, key: &Ident, value: &syn::Expr) -> syn::Result<bool> {
        let slot = match key.to_string().as_str() {
            kw::STIFFNESS => &mut self.stiffness,
            kw::REST => &mut self.rest,
            kw::DAMPING => &mut self.damping,
            kw::FRICTION => &mut self.friction,
            kw::FRICTION_SMOOTHING => &mut self.friction_smoothing,
            kw::SATURATION => &mut self.saturation,
            _ => return Ok(false),
        };
        *slot = Some(convert(value)?);
        Ok(true)
    }

    /// The joint's generalized torques (forces), each with its effect: the
    /// spring `springs`, the damper `dampers`, the friction `friction`.
    pub(super) fn torques(&self, coordinate: &Ident) -> Vec<(Expr, Ident)> {
        let span = coordinate.span();
        let q = Expr::Name(coordinate.clone());
        let rate = Expr::Call(Ident::new("dt", span), vec![q.clone()], span);
        let mut out = Vec::new();
        if let Some(k) = &self.stiffness {
            let stretch = match &self.rest {
                Some(r) => Expr::difference(q.clone(), r.clone()),
                None => q.clone(),
            };
            out.push((
                Expr::negated(Expr::product(k.clone(), stretch)),
                Ident::new("springs", span),
            ));
        }
        if let Some(c) = &self.damping {
            out.push((
                Expr::negated(Expr::product(c.clone(), rate.clone())),
                Ident::new("dampers", span),
            ));
        }
        if let Some(t) = &self.friction {
            let eps = self
                .friction_smoothing
                .clone()
                .unwrap_or(Expr::Float(1e-3, span));
            out.push((
                Expr::negated(Expr::product(t.clone(), smoothed_sign(rate, eps))),
                Ident::new("friction", span),
            ));
        }
        out
    }
}

/// v / √(v² + ε²): Coulomb's sign(v), regularised over |v| ≲ ε.
fn smoothed_sign(v: Expr, eps: Expr) -> Expr {
    let span = v.span();
    let sq = |e: Expr| Expr::product(e.clone(), e);
    let root = Expr::Call(
        Ident::new("sqrt", span),
        vec![Expr::sum(sq(v.clone()), sq(eps))],
        span,
    );
    Expr::Binary(BinOp::Div, Box::new(v), Box::new(root), span)
}

fn call(name: &str, args: Vec<Expr>, span: proc_macro2::Span) -> Expr {
    Expr::Call(Ident::new(name, span), args, span)
}

/// `spring(P, Q, stiffness = k, length = l0)` or `spring(P, Q, tension =
/// T)`: a tension T (k (|Q − P| − l0) for the linear spring) pulling P and
/// Q together, effect `springs`. `damper(P, Q, damping = c)`: the tension
/// c d|Q − P|/dt, effect `dampers`. `effect = name` replaces the effect.
pub(super) fn parse_two_point(s: ParseStream, kind: &str) -> syn::Result<Vec<LoadDef>> {
    let p: Ident = s.parse()?;
    s.parse::<Token![,]>()?;
    let q: Ident = s.parse()?;
    let span = q.span();
    let mut values = std::collections::BTreeMap::new();
    let mut effect = None;
    for (k, v) in key_values(s)? {
        let key = k.to_string();
        let allowed: &[&str] = match kind {
            kw::SPRING => &["stiffness", "length", "tension"],
            _ => &["damping"],
        };
        if key == "effect" {
            effect = Some(expr_ident(&v)?);
        } else if allowed.contains(&key.as_str()) {
            values.insert(key, (convert(&v)?, k));
        } else {
            return Err(syn::Error::new(
                k.span(),
                format!("a {kind} takes {} and `effect = name`", list(allowed)),
            ));
        }
    }
    if p == q {
        return Err(syn::Error::new(
            span,
            format!(
                "a {kind} between `{p}` and itself has no direction: name the two points it joins"
            ),
        ));
    }
    let d = Expr::difference(Expr::Name(q.clone()), Expr::Name(p.clone()));
    let direction = call("unit", vec![d.clone()], span);
    let tension = match kind {
        kw::SPRING => match (values.remove("tension"), values.remove("stiffness"), values.remove("length")) {
            (Some((t, _)), None, None) => t,
            (None, Some((k, _)), Some((l0, _))) => {
                Expr::product(k, Expr::difference(call("norm", vec![d], span), l0))
            }
            (None, Some((k, _)), None) => Expr::product(k, call("norm", vec![d], span)),
            _ => {
                return Err(syn::Error::new(
                    span,
                    "a spring takes `stiffness = k` (and `length = l0`, default 0) or `tension = T`, not both",
                ))
            }
        },
        _ => {
            let (c, _) = values.remove("damping").ok_or_else(|| {
                syn::Error::new(span, "a damper needs `damping = c`")
            })?;
            let rate = Expr::difference(
                call("velocity", vec![Expr::Name(q.clone())], span),
                call("velocity", vec![Expr::Name(p.clone())], span),
            );
            Expr::product(c, call("dot", vec![rate, direction.clone()], span))
        }
    };
    let effect = effect.unwrap_or_else(|| {
        Ident::new(
            if kind == "spring" {
                "springs"
            } else {
                "dampers"
            },
            span,
        )
    });
    let pull = Expr::product(tension, direction);
    Ok(vec![
        LoadDef {
            target: p,
            vector: pull.clone(),
            effect: effect.clone(),
        },
        LoadDef {
            target: q,
            vector: Expr::negated(pull),
            effect,
        },
    ])
}

/// `friction(P, normal = N, mu = μ, plane = n, smoothing = ε, viscous =
/// b)`: sliding friction at point P against a fixed surface of unit normal
/// n (default N.z), −μ N v_t / √(|v_t|² + ε²) − b v_t with v_t the
/// velocity of P across the surface, effect `friction`. The normal force
/// N is given (an expression), not computed: a contact whose normal force
/// the motion decides is a constraint (`rolls`), or a scene switch.
///
/// With `frame = B, center = C` (C a point fixed in B), P is a contact
/// point that moves over the body (a wheel's): the slip is the velocity of
/// the body's material point at P, v_C + ω_B × (P − C), and the friction
/// acts on the body there, as the same force at C and its moment
/// (P − C) × F on B: the loads returned are that force and that torque.
pub(super) fn parse_friction(s: ParseStream) -> syn::Result<(LoadDef, Option<LoadDef>)> {
    let p: Ident = s.parse()?;
    let mut values = std::collections::BTreeMap::new();
    let mut effect = None;
    let allowed = [
        "normal",
        "mu",
        "plane",
        "smoothing",
        "viscous",
        "frame",
        "center",
    ];
    for (k, v) in key_values(s)? {
        let key = k.to_string();
        if key == "effect" {
            effect = Some(expr_ident(&v)?);
        } else if allowed.contains(&key.as_str()) {
            values.insert(key, convert(&v)?);
        } else {
            return Err(syn::Error::new(
                k.span(),
                format!("friction takes {} and `effect = name`", list(&allowed)),
            ));
        }
    }
    friction_loads(p, values, effect)
}

/// The loads of a friction at `p` with `values` (`normal`, `mu`, `plane`,
/// `smoothing`, `viscous`, `frame`, `center`) in `effect` (default
/// `friction`): a force at P, or a force at the centre and its moment on
/// the frame.
pub(super) fn friction_loads(
    p: Ident,
    mut values: std::collections::BTreeMap<String, Expr>,
    effect: Option<Ident>,
) -> syn::Result<(LoadDef, Option<LoadDef>)> {
    let span = p.span();
    let n = values
        .remove("plane")
        .unwrap_or_else(|| Expr::Axis(Ident::new("N", span), 2, span));
    let on_body = match (values.remove("frame"), values.remove("center")) {
        (Some(Expr::Name(frame)), Some(Expr::Name(center))) => Some((frame, center)),
        (None, None) => None,
        (Some(other), _) | (_, Some(other)) => {
            return Err(syn::Error::new(
                other.span(),
                "a contact on a body takes both `frame = B` and `center = C`, a frame and a point fixed in it, by name",
            ))
        }
    };
    let v = match &on_body {
        None => call("velocity", vec![Expr::Name(p.clone())], span),
        Some((frame, center)) => {
            let arm = Expr::difference(Expr::Name(p.clone()), Expr::Name(center.clone()));
            let spin = call(
                "cross",
                vec![call("omega", vec![Expr::Name(frame.clone())], span), arm],
                span,
            );
            Expr::sum(
                call("velocity", vec![Expr::Name(center.clone())], span),
                spin,
            )
        }
    };
    let v_t = Expr::difference(
        v.clone(),
        Expr::product(call("dot", vec![v, n.clone()], span), n),
    );
    let mut force = None;
    match (values.remove("mu"), values.remove("normal")) {
        (Some(mu), Some(normal)) => {
            let eps = values
                .remove("smoothing")
                .unwrap_or(Expr::Float(1e-3, span));
            let speed2 = call("dot", vec![v_t.clone(), v_t.clone()], span);
            let root = call(
                "sqrt",
                vec![Expr::sum(speed2, Expr::product(eps.clone(), eps))],
                span,
            );
            let scale = Expr::Binary(
                BinOp::Div,
                Box::new(Expr::product(mu, normal)),
                Box::new(root),
                span,
            );
            force = Some(Expr::negated(Expr::product(scale, v_t.clone())));
        }
        (None, None) => {}
        _ => {
            return Err(syn::Error::new(
                span,
                "Coulomb friction needs both `mu = μ` and `normal = N` (the normal force)",
            ))
        }
    }
    if let Some(b) = values.remove("viscous") {
        let viscous = Expr::negated(Expr::product(b, v_t));
        force = Some(match force {
            Some(f) => Expr::sum(f, viscous),
            None => viscous,
        });
    }
    let vector = force
        .ok_or_else(|| syn::Error::new(span, "friction needs `mu` and `normal`, or `viscous`"))?;
    let effect = effect.unwrap_or_else(|| Ident::new("friction", span));
    Ok(match on_body {
        None => (
            LoadDef {
                target: p,
                vector,
                effect,
            },
            None,
        ),
        Some((frame, center)) => {
            let arm = Expr::difference(Expr::Name(p), Expr::Name(center.clone()));
            let moment = call("cross", vec![arm, vector.clone()], span);
            (
                LoadDef {
                    target: center,
                    vector,
                    effect: effect.clone(),
                },
                Some(LoadDef {
                    target: frame,
                    vector: moment,
                    effect,
                }),
            )
        }
    })
}

fn list(keys: &[&str]) -> String {
    keys.iter()
        .map(|k| format!("`{k}`"))
        .collect::<Vec<_>>()
        .join(", ")
}
