//! `#[derive(Appell)]`: see the `appell` crate for the model language.
//!
//! The macro is a thin shell: all work happens in `appell-codegen`, where it
//! can be unit-tested.

use appell_codegen::emit::{unoptimised_hint, DeriveBuild};
use proc_macro::TokenStream;

/// Derives Appell's equations of motion for the model described by the
/// `#[appell(...)]` attributes and implements `appell::Model`.
#[proc_macro_derive(Appell, attributes(appell))]
pub fn derive_appell(input: TokenStream) -> TokenStream {
    let input = syn::parse_macro_input!(input as syn::DeriveInput);
    // A bug in the derivation must not crash the user's build with a bare
    // panic: report it as a compile error on the struct.
    let span = input.ident.span();
    let start = std::time::Instant::now();
    // Files the model names are looked for from the crate's directory, then
    // beside the source file that holds the model (as `include_str!`).
    let source_file = proc_macro::Span::call_site().local_file();
    let roots = appell_codegen::FileRoots::from_env().beside(source_file.as_deref());
    let options = appell_codegen::derivation::Options::default();
    match std::panic::catch_unwind(|| appell_codegen::expand_with(&input, &roots, &options)) {
        Ok(mut tokens) => {
            let build = DeriveBuild {
                opt_level: env!("APPELL_DERIVE_OPT_LEVEL"),
                profile: env!("APPELL_DERIVE_PROFILE"),
            };
            let seconds = start.elapsed().as_secs_f64();
            let model = input.ident.to_string();
            tokens.extend(unoptimised_hint(&model, seconds, build, span));
            tokens.into()
        }
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            syn::Error::new(
                span,
                format!(
                    "appell internal error while deriving this model: {what}; please report it"
                ),
            )
            .to_compile_error()
            .into()
        }
    }
}
