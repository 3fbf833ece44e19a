//! The parsers of the items: frames, points, bodies, constraints, loads,
//! rolling contacts and scenes, each from its `name(...)` contents.

use proc_macro2::Span;
use syn::parse::{ParseStream, Parser};
use syn::punctuated::Punctuated;
use syn::spanned::Spanned;
use syn::{Ident, Token};

use super::expr::convert;
use super::{ident_list, Item};
use crate::ast::*;
use crate::parse::keywords as kw;

/// `A = P.rotate_z(a)`, or a chain `A = P.rotate_z(a).rotate_x(b)`: each
/// rotation but the last makes a frame named after the new one, `A_1`,
/// `A_2`, ... (usable like any frame), and the last makes `A`.
pub(super) fn parse_frame(s: ParseStream) -> syn::Result<Vec<FrameDef>> {
    let name: Ident = s.parse()?;
    s.parse::<Token![=]>()?;
    let e: syn::Expr = s.parse()?;
    // The calls of the chain, innermost (applied first) first.
    let mut calls = Vec::new();
    let mut at = &e;
    let parent = loop {
        match at {
            syn::Expr::MethodCall(call) => {
                calls.push(call);
                at = &call.receiver;
            }
            syn::Expr::Path(p) if calls.is_empty() => {
                // `A = P`: the same axes as P (a link welded to its parent).
                let parent = p.path.get_ident().cloned().ok_or_else(|| {
                    syn::Error::new(p.span(), "expected the name of the parent frame")
                })?;
                return Ok(vec![FrameDef {
                    name,
                    parent,
                    rotations: Vec::new(),
                    quaternion: None,
                }]);
            }
            syn::Expr::Path(p) => {
                break p.path.get_ident().cloned().ok_or_else(|| {
                    syn::Error::new(p.span(), "expected the name of the parent frame")
                })?;
            }
            other if calls.is_empty() => {
                return Err(syn::Error::new(
                    other.span(),
                    "a frame is a rotation of another frame: `A = N.rotate_z(angle)`, `A = N.rotate(axis, angle)`, or a chain `A = N.rotate_z(a).rotate_x(b)`",
                ))
            }
            other => {
                return Err(syn::Error::new(
                    other.span(),
                    "expected the name of the parent frame",
                ))
            }
        }
    };
    calls.reverse();
    let mut frames = Vec::with_capacity(calls.len());
    let mut from = parent;
    for (k, call) in calls.iter().enumerate() {
        let this = if k + 1 == calls.len() {
            name.clone()
        } else {
            Ident::new(&format!("{name}_{}", k + 1), name.span())
        };
        let (rotations, quaternion) = if call.method == "quaternion" {
            (Vec::new(), Some(quaternion_of(call)?))
        } else {
            (rotations_of(call)?, None)
        };
        frames.push(FrameDef {
            name: this.clone(),
            parent: from,
            rotations,
            quaternion,
        });
        from = this;
    }
    Ok(frames)
}

/// `quaternion(qw, qx, qy, qz)`: four scalars, the scalar part first.
fn quaternion_of(call: &syn::ExprMethodCall) -> syn::Result<Box<[Expr; 4]>> {
    let args: Vec<Expr> = call.args.iter().map(convert).collect::<syn::Result<_>>()?;
    let args: [Expr; 4] = args.try_into().map_err(|_| {
        syn::Error::new(
            call.span(),
            "`quaternion` takes four scalars, the scalar part first: `quaternion(qw, qx, qy, qz)`",
        )
    })?;
    Ok(Box::new(args))
}

/// The rotations of one call of a frame definition: `rotate_x/y/z(angle)`,
/// `rotate(axis, angle)` or a body sequence `body_zxy(a, b, c)`.
pub(super) fn rotations_of(call: &syn::ExprMethodCall) -> syn::Result<Vec<(RotationAxis, Expr)>> {
    let args: Vec<&syn::Expr> = call.args.iter().collect();
    let method = call.method.to_string();
    let axis_of = |c: char| match c {
        'x' => Some(0),
        'y' => Some(1),
        'z' => Some(2),
        _ => None,
    };
    Ok(match (method.as_str(), args.as_slice()) {
        ("rotate_x", [a]) => vec![(RotationAxis::Parent(0), convert(a)?)],
        ("rotate_y", [a]) => vec![(RotationAxis::Parent(1), convert(a)?)],
        ("rotate_z", [a]) => vec![(RotationAxis::Parent(2), convert(a)?)],
        ("rotate", [v, a]) => vec![(RotationAxis::Vector(convert(v)?), convert(a)?)],
        ("rotate_x" | "rotate_y" | "rotate_z", _) => {
            return Err(syn::Error::new(call.span(), format!("`{method}` takes one argument: the angle")))
        }
        ("rotate", _) => {
            return Err(syn::Error::new(call.span(), "`rotate` takes two arguments: the axis vector and the angle"))
        }
        (m, _) if m.starts_with("body_") && m.len() == 8 && m[5..].chars().all(|c| axis_of(c).is_some()) => {
            if args.len() != 3 {
                return Err(syn::Error::new(call.span(), format!("`{method}` takes three angles")));
            }
            let axes: Vec<usize> = m[5..].chars().filter_map(axis_of).collect();
            if axes[0] == axes[1] || axes[1] == axes[2] {
                return Err(syn::Error::new(call.method.span(), "consecutive rotations of a body sequence must be about different axes"));
            }
            axes.into_iter()
                .zip(args)
                .map(|(k, a)| Ok((RotationAxis::Parent(k), convert(a)?)))
                .collect::<syn::Result<_>>()?
        }
        _ => {
            return Err(syn::Error::new(
                call.method.span(),
                format!("unknown rotation `{method}`; use rotate_x, rotate_y, rotate_z, rotate(axis, angle) a body sequence such as body_zxy(a, b, c), or quaternion(qw, qx, qy, qz)"),
            ))
        }
    })
}

/// One scene output: `energies`, `contact_forces` or `quadrature(x1, y1)`.
struct OutputItem {
    name: Ident,
    args: Vec<Ident>,
}

impl syn::parse::Parse for OutputItem {
    fn parse(input: ParseStream) -> syn::Result<OutputItem> {
        let name: Ident = input.parse()?;
        let args = if input.peek(syn::token::Paren) {
            let content;
            syn::parenthesized!(content in input);
            ident_list(content.parse()?)?
        } else {
            Vec::new()
        };
        Ok(OutputItem { name, args })
    }
}

pub(super) fn parse_scene(s: ParseStream) -> syn::Result<SceneDef> {
    let name: Ident = s.parse()?;
    let mut effects = Vec::new();
    let mut outputs = Vec::new();
    let mut speeds = None;
    while !s.is_empty() {
        s.parse::<Token![,]>()?;
        if s.is_empty() {
            break;
        }
        let item: Item = s.parse()?;
        match item.name.to_string().as_str() {
            kw::EFFECTS => effects.extend(ident_list(item.content)?),
            kw::SPEEDS => speeds = Some((ident_list(item.content)?, item.all)),
            kw::OUTPUTS => {
                let list = Parser::parse2(
                    Punctuated::<OutputItem, Token![,]>::parse_terminated,
                    item.content,
                )?;
                for o in list {
                    outputs.push((o.name, o.args));
                }
            }
            other => {
                return Err(syn::Error::new(
                    item.name.span(),
                    format!(
                    "unknown scene part `{other}`; a scene has `effects(...)`, `outputs(...)` and `speeds(...)`"
                ),
                ))
            }
        }
    }
    Ok(SceneDef {
        name,
        effects,
        outputs,
        speeds,
    })
}

pub(super) fn parse_rolls(s: ParseStream, at: proc_macro2::TokenStream) -> syn::Result<RollsDef> {
    let body: Ident = s.parse()?;
    let (mut contact, mut along, mut effect) = (None, None, None);
    let (mut slides, mut friction) = (None, std::collections::BTreeMap::new());
    let mut first_friction_key = None;
    for (k, v) in key_values(s)? {
        match k.to_string().as_str() {
            kw::CONTACT => contact = Some(expr_ident(&v)?),
            kw::EFFECT => effect = Some(expr_ident(&v)?),
            kw::SLIDES => slides = Some(expr_ident(&v)?),
            key @ (kw::MU | kw::NORMAL | kw::SMOOTHING | kw::VISCOUS | kw::PLANE) => {
                first_friction_key.get_or_insert(k.clone());
                if friction.insert(key.to_string(), convert(&v)?).is_some() {
                    return Err(syn::Error::new(k.span(), format!("`{key}` is given twice")));
                }
            }
            kw::ALONG => match &v {
                syn::Expr::Array(a) => along = Some(a.elems.iter().map(convert).collect::<syn::Result<Vec<_>>>()?),
                other => return Err(syn::Error::new(other.span(), "`along` takes a list of directions: `along = [A.x, A.y]`")),
            },
            other => {
                return Err(syn::Error::new(k.span(), format!("unknown rolling property `{other}`; use `contact = P` and optionally `along = [u, v]`, `effect = name` and the sliding friction `slides = name, mu = μ, normal = N` (`smoothing`, `viscous`, `plane`)")))
            }
        }
    }
    let contact = contact.ok_or_else(|| {
        syn::Error::new(
            body.span(),
            "`rolls` needs `contact = P`, the contact point",
        )
    })?;
    let slides = match (slides, first_friction_key) {
        (Some(slides), _) if effect.is_none() => {
            return Err(syn::Error::new(
                slides.span(),
                "a contact that slides where a scene drops its rolling needs that rolling to belong to an effect: add `effect = rolling`",
            ))
        }
        (Some(effect), _) => Some(SlidesDef {
            effect,
            values: friction,
        }),
        (None, Some(key)) => {
            return Err(syn::Error::new(
                key.span(),
                format!("`{key}` is a property of the contact's sliding friction: name its effect with `slides = name` (the effect a scene names where it drops the rolling)"),
            ))
        }
        (None, None) => None,
    };
    Ok(RollsDef {
        body,
        contact,
        along,
        effect,
        slides,
        at,
    })
}

pub(super) fn parse_point(s: ParseStream) -> syn::Result<PointDef> {
    let name: Ident = s.parse()?;
    s.parse::<Token![=]>()?;
    let e: syn::Expr = s.parse()?;
    Ok(PointDef {
        name,
        location: convert(&e)?,
    })
}

/// `key = value` pairs after the leading positional arguments.
pub(super) fn key_values(s: ParseStream) -> syn::Result<Vec<(Ident, syn::Expr)>> {
    let mut out = Vec::new();
    while !s.is_empty() {
        s.parse::<Token![,]>()?;
        if s.is_empty() {
            break;
        }
        let key: Ident = s.parse()?;
        s.parse::<Token![=]>()?;
        let value: syn::Expr = s.parse()?;
        out.push((key, value));
    }
    Ok(out)
}

pub(super) fn parse_particle(s: ParseStream, span: Span) -> syn::Result<BodyDef> {
    let point: Ident = s.parse()?;
    let mut mass = None;
    for (k, v) in key_values(s)? {
        match k.to_string().as_str() {
            kw::MASS => mass = Some(convert(&v)?),
            other => {
                return Err(syn::Error::new(
                    k.span(),
                    format!("unknown particle property `{other}`; a particle has `mass`"),
                ))
            }
        }
    }
    let mass = mass.ok_or_else(|| syn::Error::new(span, "a particle needs `mass = ...`"))?;
    Ok(BodyDef {
        name: point.clone(),
        center: point,
        frame: None,
        mass,
        inertia: None,
        span,
    })
}

/// A body, and the point its `center` declares when it is an expression
/// rather than a point's name (`center = L1_origin + 0.25 * L1.z` declares
/// `{body}_center`).
pub(super) fn parse_body(s: ParseStream, span: Span) -> syn::Result<(BodyDef, Option<PointDef>)> {
    let name: Ident = s.parse()?;
    let (mut center, mut frame, mut mass, mut inertia) = (None, None, None, None);
    let mut center_point = None;
    for (k, v) in key_values(s)? {
        match k.to_string().as_str() {
            kw::CENTER => match &v {
                syn::Expr::Path(_) => center = Some(expr_ident(&v)?),
                other => {
                    let point = Ident::new(&format!("{name}_center"), other.span());
                    center_point = Some(PointDef {
                        name: point.clone(),
                        location: convert(other)?,
                    });
                    center = Some(point);
                }
            },
            kw::FRAME => frame = Some(expr_ident(&v)?),
            kw::MASS => mass = Some(convert(&v)?),
            kw::INERTIA => inertia = Some(parse_inertia(&v)?),
            other => {
                return Err(syn::Error::new(
                    k.span(),
                    format!("unknown body property `{other}`; a body has `center`, `frame`, `mass` and `inertia`"),
                ))
            }
        }
    }
    let missing =
        |what: &str| syn::Error::new(span, format!("body `{name}` has no `{what} = ...`"));
    let body = BodyDef {
        center: center.ok_or_else(|| missing("center"))?,
        frame: Some(frame.ok_or_else(|| missing("frame"))?),
        mass: mass.ok_or_else(|| missing("mass"))?,
        inertia: Some(inertia.ok_or_else(|| missing("inertia"))?),
        name,
        span,
    };
    Ok((body, center_point))
}

pub(super) fn parse_inertia(e: &syn::Expr) -> syn::Result<Inertia> {
    let syn::Expr::Call(call) = e else {
        return Err(syn::Error::new(
            e.span(),
            "expected `principal(i1, i2, i3)` or `matrix(ixx, iyy, izz, ixy, iyz, izx)`",
        ));
    };
    let name = match &*call.func {
        syn::Expr::Path(p) => p.path.get_ident().map(|i| i.to_string()),
        _ => None,
    };
    let args: Vec<Expr> = call.args.iter().map(convert).collect::<syn::Result<_>>()?;
    match (name.as_deref(), args.len()) {
        (Some("principal"), 3) => Ok(Inertia::Principal(args.try_into().expect("3"))),
        (Some("matrix"), 6) => Ok(Inertia::Matrix(args.try_into().expect("6"))),
        (Some("principal"), n) => Err(syn::Error::new(
            call.span(),
            format!("`principal` takes 3 moments of inertia, found {n}"),
        )),
        (Some("matrix"), n) => Err(syn::Error::new(
            call.span(),
            format!("`matrix` takes 6 entries (ixx, iyy, izz, ixy, iyz, izx), found {n}"),
        )),
        _ => Err(syn::Error::new(
            call.func.span(),
            "expected `principal(...)` or `matrix(...)`",
        )),
    }
}

pub(super) fn parse_constraint(
    s: ParseStream,
    at: proc_macro2::TokenStream,
) -> syn::Result<ConstraintDef> {
    let e: syn::Expr = s.parse()?;
    let (mut along, mut effect) = (None, None);
    for (k, v) in key_values(s)? {
        match (k.to_string().as_str(), &v) {
            ("along", syn::Expr::Array(a)) => {
                along = Some(a.elems.iter().map(convert).collect::<syn::Result<Vec<_>>>()?)
            }
            ("effect", _) => effect = Some(expr_ident(&v)?),
            ("along", other) => {
                return Err(syn::Error::new(
                    other.span(),
                    "`along` takes a list of directions: `along = [N.x, N.y]`",
                ))
            }
            (other, _) => {
                return Err(syn::Error::new(
                    k.span(),
                    format!("unknown constraint property `{other}`; a constraint takes `effect = name`, and an equation between points or vectors `along = [u, v]`"),
                ))
            }
        }
    }
    match &e {
        syn::Expr::Binary(b) if matches!(b.op, syn::BinOp::Eq(_)) => Ok(ConstraintDef {
            lhs: convert(&b.left)?,
            rhs: convert(&b.right)?,
            along,
            effect,
            at,
        }),
        _ => Err(syn::Error::new(
            e.span(),
            "a constraint is an equation `lhs == rhs`",
        )),
    }
}

pub(super) fn parse_load(s: ParseStream) -> syn::Result<LoadDef> {
    let target: Ident = s.parse()?;
    s.parse::<Token![,]>()?;
    let vector: syn::Expr = s.parse()?;
    let mut effect = None;
    for (k, v) in key_values(s)? {
        if k == "effect" {
            effect = Some(expr_ident(&v)?);
        } else {
            return Err(syn::Error::new(k.span(), "a load takes `effect = name`"));
        }
    }
    let effect = effect.unwrap_or_else(|| Ident::new("load", target.span()));
    Ok(LoadDef {
        target,
        vector: convert(&vector)?,
        effect,
    })
}

pub(super) fn expr_ident(e: &syn::Expr) -> syn::Result<Ident> {
    match e {
        syn::Expr::Path(p) => p
            .path
            .get_ident()
            .cloned()
            .ok_or_else(|| syn::Error::new(e.span(), "expected a name")),
        _ => Err(syn::Error::new(e.span(), "expected a name")),
    }
}
