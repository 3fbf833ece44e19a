//! What `urdf(...)` says beside the path: `weld(...)`, `parameters(...)`,
//! `parent = A`, `at = P`, `base = free | planar | fixed`,
//! `unchecked_inertia(link, ...)`, `mimic = true | false` and
//! `right_angles = tolerance`.

use syn::parse::ParseStream;
use syn::punctuated::Punctuated;
use syn::spanned::Spanned;
use syn::{Ident, LitStr, Token};

use crate::ast::Expr;
use crate::ctxt::did_you_mean;
use crate::parse::convert;
use crate::parse::keywords as kw;

/// The options of `urdf(...)`.
const OPTIONS: &[&str] = &[
    "weld",
    "parameters",
    "parent",
    "at",
    "base",
    "unchecked_inertia",
    "mimic",
    "right_angles",
];

/// The kinds of `base = ...`.
const BASES: &[&str] = &["free", "floating", "planar", "fixed"];

/// How the root link is held: `base = ...`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Base {
    /// Fixed in the parent frame (the default).
    Fixed,
    /// A free joint `root_joint` (unit quaternion and translation).
    Free,
    /// A planar joint `root_joint` about the parent's z axis.
    Planar,
}

/// `urdf("path", options...)` as written.
pub(super) struct Spec {
    /// The file, as written.
    pub path: LitStr,
    /// Movable joints welded at 0.
    pub welds: Vec<Ident>,
    /// Numbers of the file replaced by expressions of the model.
    pub parameters: Vec<Promotion>,
    /// The frame the root link is fixed in (N when absent).
    pub parent: Option<Ident>,
    /// The point the root link's origin is at (the parent's origin when
    /// absent).
    pub at: Option<Ident>,
    /// How the root link is held.
    pub base: Base,
    /// Links whose inertia is taken as written, physical or not (the rigid
    /// body each belongs to is not checked).
    pub unchecked_inertia: Vec<Ident>,
    /// Whether mimic joints are tied to the joints they mimic (`true`, the
    /// default) or independent joints (`mimic = false`, Pinocchio's
    /// default).
    pub mimic: bool,
    /// `right_angles = tolerance`: every rpy angle of the file within
    /// `tolerance` radians of a multiple of π/2 is read as that multiple.
    pub right_angles: Option<f64>,
}

/// `element.field = expression` or `element.field.component = expression`
/// in `parameters(...)`.
pub(super) struct Promotion {
    /// The link or joint, by its model name.
    pub element: Ident,
    /// The field and, for `xyz` and `rpy`, the component.
    pub field: Vec<Ident>,
    /// What stands for the number.
    pub value: Expr,
}

impl Promotion {
    /// `xyz.z`: the field as written after the element.
    pub(super) fn field_text(&self) -> String {
        let parts: Vec<String> = self.field.iter().map(|f| f.to_string()).collect();
        parts.join(".")
    }
}

/// The contents of `urdf(...)`, or of `urdf = "path"`.
pub(super) fn parse_spec(s: ParseStream) -> syn::Result<Spec> {
    let path: LitStr = s.parse().map_err(|e| {
        syn::Error::new(
            e.span(),
            "`urdf` starts with the file's path, relative to the crate's directory: `urdf(\"robots/arm.urdf\")`",
        )
    })?;
    let mut spec = Spec {
        path,
        welds: Vec::new(),
        parameters: Vec::new(),
        parent: None,
        at: None,
        base: Base::Fixed,
        unchecked_inertia: Vec::new(),
        mimic: true,
        right_angles: None,
    };
    while !s.is_empty() {
        s.parse::<Token![,]>()?;
        if s.is_empty() {
            break;
        }
        let key: Ident = s.parse()?;
        match key.to_string().as_str() {
            kw::WELD | kw::UNCHECKED_INERTIA => {
                let content;
                syn::parenthesized!(content in s);
                let list = Punctuated::<Ident, Token![,]>::parse_terminated(&content)?;
                if key == "weld" {
                    spec.welds.extend(list);
                } else {
                    spec.unchecked_inertia.extend(list);
                }
            }
            kw::MIMIC => {
                s.parse::<Token![=]>()?;
                let value: syn::LitBool = s.parse().map_err(|e| {
                    syn::Error::new(
                        e.span(),
                        "`mimic = true` ties each mimic joint to the joint it mimics (the default); `mimic = false` makes it an independent joint, as Pinocchio's default",
                    )
                })?;
                spec.mimic = value.value;
            }
            kw::RIGHT_ANGLES => {
                s.parse::<Token![=]>()?;
                spec.right_angles = Some(right_angles(s)?);
            }
            kw::PARAMETERS => {
                let content;
                syn::parenthesized!(content in s);
                let list = Punctuated::<syn::Expr, Token![,]>::parse_terminated(&content)?;
                for e in &list {
                    spec.parameters.push(promotion(e)?);
                }
            }
            kw::PARENT | kw::AT => {
                s.parse::<Token![=]>()?;
                let value: Ident = s.parse()?;
                if key == "parent" {
                    spec.parent = Some(value);
                } else {
                    spec.at = Some(value);
                }
            }
            kw::BASE => {
                s.parse::<Token![=]>()?;
                let value: Ident = s.parse()?;
                spec.base = match value.to_string().as_str() {
                    kw::FREE | kw::FLOATING => Base::Free,
                    kw::PLANAR => Base::Planar,
                    kw::FIXED => Base::Fixed,
                    other => {
                        let hint = did_you_mean(other, BASES.iter().copied())
                            .map(|s| format!(" (did you mean `{s}`?)"))
                            .unwrap_or_default();
                        return Err(syn::Error::new(
                            value.span(),
                            format!("unknown base `{other}`{hint}; a URDF's root link is `base = free` (a floating base), `base = planar` or `base = fixed` (the default)"),
                        ));
                    }
                };
            }
            other => {
                let hint = did_you_mean(other, OPTIONS.iter().copied())
                    .map(|s| format!(" (did you mean `{s}`?)"))
                    .unwrap_or_default();
                return Err(syn::Error::new(
                    key.span(),
                    format!("unknown `urdf` option `{other}`{hint}; the options are `weld(joint, ...)`, `parameters(element.field = name, ...)`, `parent = A`, `at = P`, `base = free | planar | fixed`, `unchecked_inertia(link, ...)`, `mimic = true | false` and `right_angles = 1e-10`"),
                ));
            }
        }
    }
    Ok(spec)
}

/// The largest tolerance `right_angles` takes: a file's right angles are
/// written to 5 digits or more, 3.7e-6 rad off at 5.
const MAX_RIGHT_ANGLE_TOLERANCE: f64 = 1e-3;

/// The tolerance of `right_angles = 1e-10`: a positive number, at most
/// [`MAX_RIGHT_ANGLE_TOLERANCE`].
fn right_angles(s: ParseStream) -> syn::Result<f64> {
    let form = "`right_angles = 1e-10` reads every rpy angle of the file within 1e-10 rad of a multiple of π/2 as that multiple (files write π/2 as 1.57079632679 or 1.5708); the tolerance is a positive number of radians, at most 1e-3";
    let value: syn::Lit = s.parse().map_err(|e| syn::Error::new(e.span(), form))?;
    let x = match &value {
        syn::Lit::Float(f) => f.base10_parse::<f64>()?,
        syn::Lit::Int(i) => i.base10_parse::<f64>()?,
        other => return Err(syn::Error::new(other.span(), form)),
    };
    if x > 0.0 && x <= MAX_RIGHT_ANGLE_TOLERANCE {
        Ok(x)
    } else {
        Err(syn::Error::new(value.span(), form))
    }
}

/// `wrist_3_link.mass = payload`.
fn promotion(e: &syn::Expr) -> syn::Result<Promotion> {
    let form = "expected `element.field = parameter`, such as `wrist_3_link.mass = payload` or `elbow_joint.xyz.z = forearm`";
    let syn::Expr::Assign(assign) = e else {
        return Err(syn::Error::new(e.span(), form));
    };
    let mut field = Vec::new();
    let mut at = &*assign.left;
    let element = loop {
        match at {
            syn::Expr::Field(f) => {
                let syn::Member::Named(name) = &f.member else {
                    return Err(syn::Error::new(f.member.span(), form));
                };
                field.insert(0, name.clone());
                at = &f.base;
            }
            syn::Expr::Path(p) if !field.is_empty() => match p.path.get_ident() {
                Some(id) => break id.clone(),
                None => return Err(syn::Error::new(p.span(), form)),
            },
            other => return Err(syn::Error::new(other.span(), form)),
        }
    };
    Ok(Promotion {
        element,
        field,
        value: convert(&assign.right)?,
    })
}
