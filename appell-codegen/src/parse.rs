//! Stage 1: `#[appell(...)]` attributes (syn) to [`ModelAst`]. Only syntax
//! is checked here; names are resolved by [`crate::model`].

use proc_macro2::Span;
use syn::parse::{ParseStream, Parser};
use syn::punctuated::Punctuated;
use syn::spanned::Spanned;
use syn::{Ident, Token};

use crate::ast::*;
use crate::ctxt::Ctxt;

/// Parses the derive input; errors go to `cx`.
pub fn parse(cx: &Ctxt, input: &syn::DeriveInput) -> ModelAst {
    let mut ast = ModelAst {
        name: input.ident.clone(),
        fields: Vec::new(),
        coordinates: Vec::new(),
        speeds: None,
        inputs: Vec::new(),
        positive: Vec::new(),
        frames: Vec::new(),
        points: Vec::new(),
        bodies: Vec::new(),
        holonomic: Vec::new(),
        nonholonomic: Vec::new(),
        forces: Vec::new(),
        torques: Vec::new(),
        gravity: None,
        rolls: Vec::new(),
        scenes: Vec::new(),
        vis: input.vis.clone(),
    };
    match &input.data {
        syn::Data::Struct(s) => match &s.fields {
            syn::Fields::Named(named) => {
                for f in &named.named {
                    let is_f64 = matches!(&f.ty, syn::Type::Path(p) if p.path.is_ident("f64"));
                    if !is_f64 {
                        cx.error_spanned_by(&f.ty, "model parameters must be `f64` fields");
                    }
                    ast.fields
                        .push((f.ident.clone().expect("named field"), is_f64));
                }
            }
            syn::Fields::Unit => {}
            other => cx.error_spanned_by(
                other,
                "a model is a struct with named `f64` fields (its parameters)",
            ),
        },
        _ => cx.error_at(
            input.ident.span(),
            "#[derive(Appell)] works on structs whose fields are the model's parameters",
        ),
    }
    if !input.generics.params.is_empty() {
        cx.error_spanned_by(&input.generics, "a model struct cannot be generic");
    }
    for attr in &input.attrs {
        if !attr.path().is_ident("appell") {
            continue;
        }
        let parser = |stream: ParseStream| {
            let items = Punctuated::<Item, Token![,]>::parse_terminated(stream)?;
            Ok(items)
        };
        match attr.parse_args_with(parser) {
            Ok(items) => {
                for item in items {
                    add_item(cx, &mut ast, item);
                }
            }
            Err(e) => cx.syn_error(e),
        }
    }
    ast
}

/// One `name(...)` entry of an `#[appell(...)]` attribute, kept raw.
struct Item {
    name: Ident,
    content: proc_macro2::TokenStream,
    /// The whole `name(...)`, for errors.
    all: proc_macro2::TokenStream,
    span: Span,
}

impl syn::parse::Parse for Item {
    fn parse(input: ParseStream) -> syn::Result<Item> {
        let name: Ident = input.parse()?;
        let content;
        let paren = syn::parenthesized!(content in input);
        let content: proc_macro2::TokenStream = content.parse()?;
        let span = name.span();
        let mut all = quote::quote!(#name);
        let group = proc_macro2::Group::new(proc_macro2::Delimiter::Parenthesis, content.clone());
        let mut group = group;
        group.set_span(paren.span.join());
        all.extend(std::iter::once(proc_macro2::TokenTree::Group(group)));
        Ok(Item {
            name,
            content,
            all,
            span,
        })
    }
}

const ITEMS: &[&str] = &[
    "coordinates",
    "speeds",
    "inputs",
    "positive",
    "frame",
    "point",
    "particle",
    "body",
    "holonomic",
    "nonholonomic",
    "force",
    "torque",
    "gravity",
    "rolls",
    "scene",
];

fn add_item(cx: &Ctxt, ast: &mut ModelAst, item: Item) {
    let name = item.name.to_string();
    let tokens = item.content.clone();
    let result: syn::Result<()> = (|| {
        match name.as_str() {
            "coordinates" => ast.coordinates.extend(ident_list(tokens)?),
            "inputs" => ast.inputs.extend(ident_list(tokens)?),
            "positive" => ast.positive.extend(ident_list(tokens)?),
            "speeds" => {
                let list =
                    Parser::parse2(Punctuated::<SpeedItem, Token![,]>::parse_terminated, tokens)?;
                let list: Vec<SpeedDef> = list
                    .into_iter()
                    .map(|i| {
                        Ok(SpeedDef {
                            name: i.name,
                            definition: i.definition.as_ref().map(convert).transpose()?,
                        })
                    })
                    .collect::<syn::Result<_>>()?;
                if ast.speeds.is_some() {
                    cx.error_spanned_by(&item.all, "`speeds` is given twice");
                }
                ast.speeds = Some((list, item.all.clone()));
            }
            "frame" => ast.frames.extend(Parser::parse2(parse_frame, tokens)?),
            "point" => ast.points.push(Parser::parse2(parse_point, tokens)?),
            "particle" => {
                let span = item.span;
                ast.bodies.push(Parser::parse2(
                    move |s: ParseStream| parse_particle(s, span),
                    tokens,
                )?)
            }
            "body" => {
                let span = item.span;
                ast.bodies.push(Parser::parse2(
                    move |s: ParseStream| parse_body(s, span),
                    tokens,
                )?)
            }
            "holonomic" | "nonholonomic" => {
                let at = item.content.clone();
                let c = Parser::parse2(move |s: ParseStream| parse_constraint(s, at), tokens)?;
                if name == "holonomic" {
                    ast.holonomic.push(c)
                } else {
                    ast.nonholonomic.push(c)
                }
            }
            "force" => ast.forces.push(Parser::parse2(parse_load, tokens)?),
            "torque" => ast.torques.push(Parser::parse2(parse_load, tokens)?),
            "scene" => ast.scenes.push(Parser::parse2(parse_scene, tokens)?),
            "rolls" => {
                let at = item.all.clone();
                ast.rolls.push(Parser::parse2(
                    move |s: ParseStream| parse_rolls(s, at),
                    tokens,
                )?)
            }
            "gravity" => {
                let e: syn::Expr = syn::parse2(tokens)?;
                if ast.gravity.is_some() {
                    cx.error_at(item.span, "`gravity` is given twice");
                }
                ast.gravity = Some(convert(&e)?);
            }
            _ => {
                let hint = crate::ctxt::did_you_mean(&name, ITEMS.iter().copied())
                    .map(|s| format!("; did you mean `{s}`?"))
                    .unwrap_or_default();
                return Err(syn::Error::new(
                    item.name.span(),
                    format!("unknown model item `{name}`{hint}"),
                ));
            }
        }
        Ok(())
    })();
    if let Err(e) = result {
        cx.syn_error(e);
    }
}

/// `name` or `name = expression` inside `speeds(...)`.
struct SpeedItem {
    name: Ident,
    definition: Option<syn::Expr>,
}

impl syn::parse::Parse for SpeedItem {
    fn parse(input: ParseStream) -> syn::Result<SpeedItem> {
        let name: Ident = input.parse()?;
        let definition = if input.peek(Token![=]) {
            input.parse::<Token![=]>()?;
            Some(input.parse()?)
        } else {
            None
        };
        Ok(SpeedItem { name, definition })
    }
}

fn ident_list(tokens: proc_macro2::TokenStream) -> syn::Result<Vec<Ident>> {
    let list = Parser::parse2(Punctuated::<Ident, Token![,]>::parse_terminated, tokens)?;
    Ok(list.into_iter().collect())
}

/// `A = P.rotate_z(a)`, or a chain `A = P.rotate_z(a).rotate_x(b)`: each
/// rotation but the last makes a frame named after the new one, `A_1`,
/// `A_2`, ... (usable like any frame), and the last makes `A`.
fn parse_frame(s: ParseStream) -> syn::Result<Vec<FrameDef>> {
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
            syn::Expr::Path(p) if !calls.is_empty() => {
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
        frames.push(FrameDef {
            name: this.clone(),
            parent: from,
            rotations: rotations_of(call)?,
        });
        from = this;
    }
    Ok(frames)
}

/// The rotations of one call of a frame definition: `rotate_x/y/z(angle)`,
/// `rotate(axis, angle)` or a body sequence `body_zxy(a, b, c)`.
fn rotations_of(call: &syn::ExprMethodCall) -> syn::Result<Vec<(RotationAxis, Expr)>> {
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
                format!("unknown rotation `{method}`; use rotate_x, rotate_y, rotate_z, rotate(axis, angle) or a body sequence such as body_zxy(a, b, c)"),
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

fn parse_scene(s: ParseStream) -> syn::Result<SceneDef> {
    let name: Ident = s.parse()?;
    let mut effects = Vec::new();
    let mut outputs = Vec::new();
    while !s.is_empty() {
        s.parse::<Token![,]>()?;
        if s.is_empty() {
            break;
        }
        let item: Item = s.parse()?;
        match item.name.to_string().as_str() {
            "effects" => effects.extend(ident_list(item.content)?),
            "outputs" => {
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
                    "unknown scene part `{other}`; a scene has `effects(...)` and `outputs(...)`"
                ),
                ))
            }
        }
    }
    Ok(SceneDef {
        name,
        effects,
        outputs,
    })
}

fn parse_rolls(s: ParseStream, at: proc_macro2::TokenStream) -> syn::Result<RollsDef> {
    let body: Ident = s.parse()?;
    let (mut contact, mut along) = (None, None);
    for (k, v) in key_values(s)? {
        match k.to_string().as_str() {
            "contact" => contact = Some(expr_ident(&v)?),
            "along" => match &v {
                syn::Expr::Array(a) => along = Some(a.elems.iter().map(convert).collect::<syn::Result<Vec<_>>>()?),
                other => return Err(syn::Error::new(other.span(), "`along` takes a list of directions: `along = [A.x, A.y]`")),
            },
            other => {
                return Err(syn::Error::new(k.span(), format!("unknown rolling property `{other}`; use `contact = P` and optionally `along = [u, v]`")))
            }
        }
    }
    let contact = contact.ok_or_else(|| {
        syn::Error::new(
            body.span(),
            "`rolls` needs `contact = P`, the contact point",
        )
    })?;
    Ok(RollsDef {
        body,
        contact,
        along,
        at,
    })
}

fn parse_point(s: ParseStream) -> syn::Result<PointDef> {
    let name: Ident = s.parse()?;
    s.parse::<Token![=]>()?;
    let e: syn::Expr = s.parse()?;
    Ok(PointDef {
        name,
        location: convert(&e)?,
    })
}

/// `key = value` pairs after the leading positional arguments.
fn key_values(s: ParseStream) -> syn::Result<Vec<(Ident, syn::Expr)>> {
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

fn parse_particle(s: ParseStream, span: Span) -> syn::Result<BodyDef> {
    let point: Ident = s.parse()?;
    let mut mass = None;
    for (k, v) in key_values(s)? {
        match k.to_string().as_str() {
            "mass" => mass = Some(convert(&v)?),
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

fn parse_body(s: ParseStream, span: Span) -> syn::Result<BodyDef> {
    let name: Ident = s.parse()?;
    let (mut center, mut frame, mut mass, mut inertia) = (None, None, None, None);
    for (k, v) in key_values(s)? {
        match k.to_string().as_str() {
            "center" => center = Some(expr_ident(&v)?),
            "frame" => frame = Some(expr_ident(&v)?),
            "mass" => mass = Some(convert(&v)?),
            "inertia" => inertia = Some(parse_inertia(&v)?),
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
    Ok(BodyDef {
        center: center.ok_or_else(|| missing("center"))?,
        frame: Some(frame.ok_or_else(|| missing("frame"))?),
        mass: mass.ok_or_else(|| missing("mass"))?,
        inertia: Some(inertia.ok_or_else(|| missing("inertia"))?),
        name,
        span,
    })
}

fn parse_inertia(e: &syn::Expr) -> syn::Result<Inertia> {
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

fn parse_constraint(s: ParseStream, at: proc_macro2::TokenStream) -> syn::Result<ConstraintDef> {
    let e: syn::Expr = s.parse()?;
    let mut along = None;
    for (k, v) in key_values(s)? {
        match (k.to_string().as_str(), &v) {
            ("along", syn::Expr::Array(a)) => {
                along = Some(a.elems.iter().map(convert).collect::<syn::Result<Vec<_>>>()?)
            }
            ("along", other) => {
                return Err(syn::Error::new(
                    other.span(),
                    "`along` takes a list of directions: `along = [N.x, N.y]`",
                ))
            }
            (other, _) => {
                return Err(syn::Error::new(
                    k.span(),
                    format!("unknown constraint property `{other}`; an equation between points or vectors takes `along = [u, v]`"),
                ))
            }
        }
    }
    match &e {
        syn::Expr::Binary(b) if matches!(b.op, syn::BinOp::Eq(_)) => Ok(ConstraintDef {
            lhs: convert(&b.left)?,
            rhs: convert(&b.right)?,
            along,
            at,
        }),
        _ => Err(syn::Error::new(
            e.span(),
            "a constraint is an equation `lhs == rhs`",
        )),
    }
}

fn parse_load(s: ParseStream) -> syn::Result<LoadDef> {
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

fn expr_ident(e: &syn::Expr) -> syn::Result<Ident> {
    match e {
        syn::Expr::Path(p) => p
            .path
            .get_ident()
            .cloned()
            .ok_or_else(|| syn::Error::new(e.span(), "expected a name")),
        _ => Err(syn::Error::new(e.span(), "expected a name")),
    }
}

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
