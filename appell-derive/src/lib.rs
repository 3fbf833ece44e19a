//! `#[derive(Appell)]`: see the `appell` crate for the model language.
//!
//! The macro is a thin shell: all work happens in `appell-codegen`, where it
//! can be unit-tested.

use proc_macro::TokenStream;

/// Derives Appell's equations of motion for the model described by the
/// `#[appell(...)]` attributes and implements `appell::Model`.
#[proc_macro_derive(Appell, attributes(appell))]
pub fn derive_appell(input: TokenStream) -> TokenStream {
    let input = syn::parse_macro_input!(input as syn::DeriveInput);
    appell_codegen::expand(&input).into()
}
