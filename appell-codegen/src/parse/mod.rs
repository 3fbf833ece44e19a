//! Stage 1: `#[appell(...)]` attributes (syn) to [`ModelAst`]. Only syntax
//! is checked here; names are resolved by [`crate::model`].

use proc_macro2::Span;
use syn::parse::{ParseStream, Parser};
use syn::punctuated::Punctuated;
use syn::{Ident, Token};

use crate::ast::*;
use crate::ctxt::Ctxt;

mod contacts;
mod elements;
mod expr;
mod files;
mod items;
pub mod joints;
mod keywords;
mod repeat;
pub mod urdf;

pub use expr::convert;
pub use files::FileRoots;
use items::*;

/// Parses the derive input; errors go to `cx`. Files a model reads
/// (`urdf(...)`) are found relative to the directory in the environment's
/// `CARGO_MANIFEST_DIR`, the crate being compiled.
pub fn parse(cx: &Ctxt, input: &syn::DeriveInput) -> ModelAst {
    parse_in(cx, input, &FileRoots::from_env())
}

/// [`parse`], with files looked for from `roots` (none: a model that reads
/// a file is an error).
pub fn parse_in(cx: &Ctxt, input: &syn::DeriveInput, roots: &FileRoots) -> ModelAst {
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
        jacobian: None,
        rolls: Vec::new(),
        contacts: Vec::new(),
        joint_limits: Vec::new(),
        scenes: Vec::new(),
        origins: Vec::new(),
        joints: Vec::new(),
        joint_speeds: Vec::new(),
        vis: input.vis.clone(),
        files: Vec::new(),
        urdf_names: Vec::new(),
        massless_links: Vec::new(),
        unchecked_inertia: Vec::new(),
    };
    match &input.data {
        syn::Data::Struct(s) => match &s.fields {
            syn::Fields::Named(named) => {
                for f in &named.named {
                    let field = f.ident.clone().expect("named field");
                    match parameter_elements(&f.ty) {
                        Some(None) => ast.fields.push(ParamDef {
                            name: field.clone(),
                            field,
                            index: None,
                        }),
                        Some(Some(n)) => ast.fields.extend((0..n).map(|k| ParamDef {
                            name: Ident::new(&format!("{field}_{k}"), field.span()),
                            field: field.clone(),
                            index: Some(k),
                        })),
                        None => cx.error_spanned_by(
                            &f.ty,
                            "model parameters are `f64` fields or arrays `[f64; N]` with a literal N",
                        ),
                    }
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
        let expanded = match &attr.meta {
            syn::Meta::List(list) => repeat::expand(list.tokens.clone()),
            other => Err(syn::Error::new_spanned(
                other,
                "expected `#[appell(item, item, ...)]`",
            )),
        };
        match expanded.and_then(|tokens| Parser::parse2(parser, tokens)) {
            Ok(items) => {
                for item in items {
                    add_item(cx, &mut ast, item, roots);
                }
            }
            Err(e) => cx.syn_error(e),
        }
    }
    add_joint_speeds(&mut ast);
    add_rolling_friction(cx, &mut ast);
    ast
}

/// Each rolling contact's sliding friction (`slides = effect, ...`) as
/// `friction(P, ..., frame = B, center = C, effect)` on the rolling body,
/// across the surface the contact's `along` directions span (N.z unless
/// `plane` or `along` says otherwise). A body not declared is left to
/// resolution to report.
fn add_rolling_friction(cx: &Ctxt, ast: &mut ModelAst) {
    for r in &ast.rolls {
        let Some(slides) = &r.slides else { continue };
        let Some(body) = ast.bodies.iter().find(|b| b.name == r.body) else {
            continue;
        };
        let Some(frame) = &body.frame else {
            cx.error_at(
                r.body.span(),
                "a sliding contact needs a rigid body (with a frame), not a particle",
            );
            continue;
        };
        let mut values = slides.values.clone();
        let span = r.contact.span();
        values.insert("frame".into(), Expr::Name(frame.clone()));
        values.insert("center".into(), Expr::Name(body.center.clone()));
        let pair = r
            .along
            .as_deref()
            .and_then(|a| <&[Expr; 2]>::try_from(a).ok());
        if let (false, Some([e1, e2])) = (values.contains_key("plane"), pair) {
            // The unit normal e1 × e2 / |e1 × e2|.
            let call = |f: &str, args: Vec<Expr>| Expr::Call(Ident::new(f, span), args, span);
            let n = call("cross", vec![e1.clone(), e2.clone()]);
            let length = call("sqrt", vec![call("dot", vec![n.clone(), n.clone()])]);
            let inverse = Expr::Binary(
                crate::ast::BinOp::Div,
                Box::new(Expr::Int(1, span)),
                Box::new(length),
                span,
            );
            let unit = Expr::Binary(crate::ast::BinOp::Mul, Box::new(inverse), Box::new(n), span);
            values.insert("plane".into(), unit);
        }
        match elements::friction_loads(r.contact.clone(), values, Some(slides.effect.clone())) {
            Ok((force, torque)) => {
                ast.forces.push(force);
                ast.torques.extend(torque);
            }
            Err(e) => cx.syn_error(e),
        }
    }
}

/// The joints' coordinates' rates as privileged speeds, after those of
/// `speeds(...)`, each once.
fn add_joint_speeds(ast: &mut ModelAst) {
    if ast.joint_speeds.is_empty() {
        return;
    }
    let (list, _) = ast
        .speeds
        .get_or_insert_with(|| (Vec::new(), proc_macro2::TokenStream::new()));
    for q in ast.joint_speeds.clone() {
        if !list.iter().any(|s| s.name == q) {
            list.push(SpeedDef {
                name: q,
                definition: None,
            });
        }
    }
}

/// An error at `parent` when it names no frame declared so far (N or a
/// frame above), with the nearest names; `None` when it is one.
pub(super) fn unknown_parent(ast: &ModelAst, parent: &Ident) -> Option<syn::Error> {
    if *parent == "N" || ast.frames.iter().any(|f| f.name == *parent) {
        return None;
    }
    let names: Vec<String> = ast
        .frames
        .iter()
        .map(|f| f.name.to_string())
        .chain(std::iter::once("N".to_string()))
        .collect();
    let hint = crate::ctxt::suggest(&parent.to_string(), names.iter().map(String::as_str))
        .map(|s| format!("; did you mean `{s}`?"))
        .unwrap_or_default();
    Some(syn::Error::new(
        parent.span(),
        format!("unknown frame `{parent}`: a parent is N or a frame declared above{hint}"),
    ))
}

/// Adds a joint's frames, points, coordinates, speeds, inputs, loads and
/// constraints.
pub(super) fn add_joint(ast: &mut ModelAst, joint: &JointDef) -> syn::Result<()> {
    let parent_origin = if joint.parent == "N" {
        Some(Ident::new("O", joint.parent.span()))
    } else {
        ast.origins
            .iter()
            .find(|(f, _)| *f == joint.parent)
            .map(|(_, p)| Ident::new(&p.to_string(), joint.parent.span()))
    };
    if parent_origin.is_none() && joint.at.is_none() {
        if let Some(e) = unknown_parent(ast, &joint.parent) {
            return Err(e);
        }
    }
    let lowered = joints::lower(joint, parent_origin)?;
    ast.joints.push(joint.clone());
    ast.origins
        .push((joint.child.clone(), lowered.points[0].name.clone()));
    ast.frames.extend(lowered.frames);
    ast.points.extend(lowered.points);
    ast.coordinates.extend(lowered.coordinates);
    ast.joint_speeds.extend(lowered.speeds);
    ast.inputs.extend(lowered.inputs);
    ast.forces.extend(lowered.forces);
    ast.torques.extend(lowered.torques);
    ast.holonomic.extend(lowered.holonomic);
    ast.nonholonomic.extend(lowered.nonholonomic);
    if !lowered.speed_definitions.is_empty() {
        let (list, _) = ast
            .speeds
            .get_or_insert_with(|| (Vec::new(), proc_macro2::TokenStream::new()));
        list.extend(lowered.speed_definitions);
    }
    Ok(())
}

/// `f64`: Some(None); `[f64; N]`: Some(Some(N)); anything else: None.
fn parameter_elements(ty: &syn::Type) -> Option<Option<usize>> {
    match ty {
        syn::Type::Path(p) if p.path.is_ident("f64") => Some(None),
        syn::Type::Array(a) => match (&*a.elem, &a.len) {
            (
                syn::Type::Path(p),
                syn::Expr::Lit(syn::ExprLit {
                    lit: syn::Lit::Int(n),
                    ..
                }),
            ) if p.path.is_ident("f64") => n.base10_parse().ok().map(Some),
            _ => None,
        },
        _ => None,
    }
}

/// One `name(...)` entry of an `#[appell(...)]` attribute, kept raw.
pub(super) struct Item {
    name: Ident,
    content: proc_macro2::TokenStream,
    /// The whole `name(...)`, for errors.
    all: proc_macro2::TokenStream,
    span: Span,
}

impl syn::parse::Parse for Item {
    fn parse(input: ParseStream) -> syn::Result<Item> {
        let name: Ident = input.parse()?;
        if input.peek(Token![=]) && name == "urdf" {
            // `urdf = "path"`: the same as `urdf("path")`.
            input.parse::<Token![=]>()?;
            let path: syn::LitStr = input.parse()?;
            let content = quote::quote!(#path);
            let all = quote::quote!(#name = #path);
            let span = name.span();
            return Ok(Item {
                name,
                content,
                all,
                span,
            });
        }
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

/// `on` or `off`, as in `jacobian(off)`.
fn parse_switch(tokens: proc_macro2::TokenStream) -> syn::Result<bool> {
    let word: Ident = syn::parse2(tokens.clone()).map_err(|_| {
        syn::Error::new_spanned(&tokens, "expected `on` or `off`, as in `jacobian(off)`")
    })?;
    match word.to_string().as_str() {
        keywords::ON => Ok(true),
        keywords::OFF => Ok(false),
        other => Err(syn::Error::new(
            word.span(),
            format!("expected `on` or `off`, found `{other}`, as in `jacobian(off)`"),
        )),
    }
}

fn add_item(cx: &Ctxt, ast: &mut ModelAst, item: Item, roots: &FileRoots) {
    let name = item.name.to_string();
    let tokens = item.content.clone();
    let result: syn::Result<()> = (|| {
        match name.as_str() {
            keywords::COORDINATES => ast.coordinates.extend(ident_list(tokens)?),
            keywords::INPUTS => ast.inputs.extend(ident_list(tokens)?),
            keywords::POSITIVE => ast.positive.extend(ident_list(tokens)?),
            keywords::SPEEDS => {
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
                // Several `speeds(...)` (a repeat writes one per link)
                // add up, in order; errors point at the first.
                match &mut ast.speeds {
                    Some((all, _)) => all.extend(list),
                    None => ast.speeds = Some((list, item.all.clone())),
                }
            }
            keywords::FRAME => ast.frames.extend(Parser::parse2(parse_frame, tokens)?),
            keywords::POINT => ast.points.push(Parser::parse2(parse_point, tokens)?),
            keywords::PARTICLE => {
                let span = item.span;
                ast.bodies.push(Parser::parse2(
                    move |s: ParseStream| parse_particle(s, span),
                    tokens,
                )?)
            }
            keywords::BODY => {
                let span = item.span;
                let (body, center) =
                    Parser::parse2(move |s: ParseStream| parse_body(s, span), tokens)?;
                ast.points.extend(center);
                ast.bodies.push(body)
            }
            keywords::JOINT => {
                let span = item.span;
                let joint =
                    Parser::parse2(move |s: ParseStream| joints::parse_joint(s, span), tokens)?;
                add_joint(ast, &joint)?
            }
            keywords::URDF => urdf::add(cx, ast, &item, roots)?,
            keywords::HOLONOMIC | keywords::NONHOLONOMIC => {
                let at = item.content.clone();
                let c = Parser::parse2(move |s: ParseStream| parse_constraint(s, at), tokens)?;
                if name == keywords::HOLONOMIC {
                    ast.holonomic.push(c)
                } else {
                    ast.nonholonomic.push(c)
                }
            }
            keywords::FORCE => ast.forces.push(Parser::parse2(parse_load, tokens)?),
            keywords::TORQUE => ast.torques.push(Parser::parse2(parse_load, tokens)?),
            keywords::SPRING | keywords::DAMPER => {
                let kind = name.clone();
                ast.forces.extend(Parser::parse2(
                    move |s: ParseStream| elements::parse_two_point(s, &kind),
                    tokens,
                )?)
            }
            keywords::FRICTION => {
                let (force, torque) = Parser::parse2(elements::parse_friction, tokens)?;
                ast.forces.push(force);
                ast.torques.extend(torque);
            }
            keywords::SCENE => ast.scenes.push(Parser::parse2(parse_scene, tokens)?),
            keywords::ROLLS => {
                let at = item.all.clone();
                ast.rolls.push(Parser::parse2(
                    move |s: ParseStream| parse_rolls(s, at),
                    tokens,
                )?)
            }
            keywords::CONTACT => {
                let at = item.all.clone();
                ast.contacts.push(Parser::parse2(
                    move |s: ParseStream| contacts::parse_contact(s, at),
                    tokens,
                )?)
            }
            keywords::JACOBIAN => ast.jacobian = Some(parse_switch(tokens)?),
            keywords::GRAVITY => {
                let e: syn::Expr = syn::parse2(tokens)?;
                if ast.gravity.is_some() {
                    cx.error_at(item.span, "`gravity` is given twice");
                }
                ast.gravity = Some(convert(&e)?);
            }
            _ => {
                let hint = crate::ctxt::did_you_mean(&name, keywords::ITEMS.iter().copied())
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

pub(super) fn ident_list(tokens: proc_macro2::TokenStream) -> syn::Result<Vec<Ident>> {
    let list = Parser::parse2(Punctuated::<Ident, Token![,]>::parse_terminated, tokens)?;
    Ok(list.into_iter().collect())
}
