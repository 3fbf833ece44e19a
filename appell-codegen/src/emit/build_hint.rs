//! A warning for a derive that runs unoptimised: Cargo builds proc macros
//! and their dependencies at `opt-level = 0` unless the user's profile says
//! otherwise, which makes the derivation several times slower. Stable Rust
//! gives a proc macro no warning of its own, so the hint is the note of a
//! deprecated item that the expansion uses, spanned at the model's name.

use proc_macro2::{Span, TokenStream};
use quote::quote_spanned;

/// Expansions shorter than this (in seconds) get no hint, whatever the
/// optimisation level: the setting would save the user little.
pub const SLOW_EXPANSION_SECONDS: f64 = 0.5;

/// How the derive itself was compiled, as its build script saw it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DeriveBuild<'a> {
    /// Cargo's `OPT_LEVEL` of the derive ("0", "1", "2", "3", "s", "z").
    pub opt_level: &'a str,
    /// Cargo's `PROFILE` ("debug" for the dev and test profiles, "release").
    pub profile: &'a str,
}

/// The warning for a derivation of `model` that took `seconds` in a derive
/// built as `build`, or nothing when the derive was optimised or fast
/// enough.
///
/// ```
/// use appell_codegen::emit::{unoptimised_hint, DeriveBuild};
/// use proc_macro2::Span;
///
/// let unoptimised = DeriveBuild { opt_level: "0", profile: "release" };
/// let hint = unoptimised_hint("Panda", 2.6, unoptimised, Span::call_site()).to_string();
/// assert!(hint.contains("[profile.release.build-override]"), "{hint}");
/// assert!(hint.contains("deprecated"));
///
/// let optimised = DeriveBuild { opt_level: "3", profile: "release" };
/// assert!(unoptimised_hint("Panda", 2.6, optimised, Span::call_site()).is_empty());
/// assert!(unoptimised_hint("Panda", 0.1, unoptimised, Span::call_site()).is_empty());
/// ```
pub fn unoptimised_hint(
    model: &str,
    seconds: f64,
    build: DeriveBuild<'_>,
    span: Span,
) -> TokenStream {
    if build.opt_level != "0" || seconds < SLOW_EXPANSION_SECONDS {
        return TokenStream::new();
    }
    let section = match build.profile {
        "release" => "release",
        _ => "dev",
    };
    let note = format!(
        "deriving `{model}` took {seconds:.1} s because Cargo builds proc macros unoptimised \
         in this profile; add `[profile.{section}.build-override]` with `opt-level = 3` to \
         Cargo.toml to make the derive about 7x faster (appell's guide: docs/guide/building.md)"
    );
    quote_spanned! {span=>
        const _: () = {
            #[deprecated(note = #note)]
            #[allow(non_upper_case_globals)]
            const appell_derive_is_unoptimised: () = ();
            appell_derive_is_unoptimised
        };
    }
}
