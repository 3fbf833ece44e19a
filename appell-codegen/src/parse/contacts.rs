//! `contact(link, point | flat, effect = name)`: a foot on the ground,
//! written out as the velocity constraints it holds (the origin's velocity,
//! and for a flat foot the frame's angular velocity, both zero in N).

use syn::parse::ParseStream;
use syn::{Ident, Token};

use super::items::{expr_ident, key_values};
use crate::ast::*;
use crate::parse::keywords as kw;

/// Parses the inside of `contact(...)`; `at` is the whole item's tokens.
pub(super) fn parse_contact(
    s: ParseStream,
    at: proc_macro2::TokenStream,
) -> syn::Result<ContactDef> {
    let link: Ident = s.parse()?;
    if s.is_empty() {
        return Err(syn::Error::new(
            link.span(),
            format!("say how `{link}` touches the ground: `contact({link}, point)` holds its origin still (three rows), `contact({link}, flat)` the whole frame (six)"),
        ));
    }
    s.parse::<Token![,]>()?;
    let kind: Ident = s.parse()?;
    let flat = match kind.to_string().as_str() {
        kw::POINT => false,
        kw::FLAT => true,
        other => {
            let hint = crate::ctxt::did_you_mean(other, ["point", "flat"])
                .map(|s| format!("; did you mean `{s}`?"))
                .unwrap_or_default();
            return Err(syn::Error::new(
                kind.span(),
                format!("a contact is `point` (its origin held still) or `flat` (the whole frame held still), not `{other}`{hint}"),
            ));
        }
    };
    let mut effect = None;
    for (k, v) in key_values(s)? {
        match k.to_string().as_str() {
            kw::EFFECT => effect = Some(expr_ident(&v)?),
            other => {
                return Err(syn::Error::new(
                    k.span(),
                    format!("unknown contact property `{other}`; a contact takes `effect = name` (the scenes that name it hold it)"),
                ))
            }
        }
    }
    let effect = effect.unwrap_or_else(|| link.clone());
    Ok(ContactDef {
        link,
        flat,
        effect,
        at,
    })
}
