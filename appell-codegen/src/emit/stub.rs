//! The stub emitted beside errors (thiserror's fallback): an
//! implementation whose methods panic, and the scene types, so that code
//! using the model sees only the real errors.

use proc_macro2::TokenStream;
use quote::{format_ident, quote};

use super::{camel, p};

/// A stub implementation emitted beside errors, so the user sees only the
/// real ones (thiserror's fallback). The scene types are declared too, so
/// code using them sees only the real errors.
pub fn stub(name: &syn::Ident, scenes: &[syn::Ident], vis: &syn::Visibility) -> TokenStream {
    let p = p();
    // Raw scene names are an error, reported elsewhere; the stub still
    // declares a type for them, from the name without `r#`.
    let scene_types = scenes.iter().map(|sc| {
        let bare = syn::ext::IdentExt::unraw(sc);
        format_ident!("{}{}", name, camel(&bare.to_string()))
    });
    let name_str = name.to_string();
    let fail = quote!(::core::panic!(
        "the model failed to derive; see the compile errors"
    ));
    quote! {
        #(
            #[allow(dead_code)]
            #vis struct #scene_types(pub #name);
        )*
        const _: () = {
            static __INFO: #p::ModelInfo = #p::ModelInfo {
                name: #name_str, parameters: &[], coordinates: &[], speeds: &[], dependent: &[], cyclic: &[],
                ignorable: &[], retained: &[], inputs: &[], effects: &[], outputs: &[], holonomic: 0, constraints: 0,
                row_sources: &[], contacts: &[],
                bodies: &[], force_points: 0, torques: 0, form: "closed form", symbolic_elimination: true,
                rhs_ops: #p::OpCounts { add: 0, mul: 0, div: 0, calls: 0, total: 0 }, jacobian: None, equations: "",
            };
            #[allow(unused_variables, clippy::all)]
            impl #p::Model for #name {
                type Prepared<__T: #p::Scalar> = [__T; 0];
                fn info() -> &'static #p::ModelInfo { &__INFO }
                fn parameter_values(&self, __out: &mut [f64]) -> #p::Result<(), #p::ModelError> { #fail }
                fn set_parameter(&mut self, __name: &str, __value: f64) -> bool { #fail }
                fn prepare<__T: #p::Scalar>(&self) -> [__T; 0] { #fail }
                fn rhs<__T: #p::Scalar>(&self, __p: &[__T; 0], t: __T, __s: &[__T], __i: &[__T], __d: &mut [__T]) -> #p::Result<(), #p::ModelError> { #fail }
                fn mass_matrix_and_forcing<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __u: &[__T], __i: &[__T], __m: &mut [__T], __f: &mut [__T]) -> #p::Result<(), #p::ModelError> { #fail }
                fn speed_transform<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __c: &mut [__T], __c0: &mut [__T]) -> #p::Result<(), #p::ModelError> { #fail }
                fn coordinate_rates<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __u: &[__T], __qd: &mut [__T]) -> #p::Result<(), #p::ModelError> { #fail }
                fn constraint_residuals<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __qd: &[__T], __h: &mut [__T], __v: &mut [__T]) -> #p::Result<(), #p::ModelError> { #fail }
                fn kinetic_energy<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __u: &[__T]) -> #p::Result<__T, #p::ModelError> { #fail }
                fn mass_properties(&self, __m: &mut [f64], __i: &mut [[f64; 9]]) -> #p::Result<(), #p::ModelError> { #fail }
                fn body_poses<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __p: &mut [[__T; 3]], __r: &mut [[__T; 9]]) -> #p::Result<(), #p::ModelError> { #fail }
                fn constraint_rows<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __d: &mut [__T], __d0: &mut [__T]) -> #p::Result<(), #p::ModelError> { #fail }
                fn load_geometry<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __p: &mut [[__T; 3]], __f: &mut [[__T; 9]]) -> #p::Result<(), #p::ModelError> { #fail }
                fn load_values<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __qd: &[__T], __i: &[__T], __f: &mut [[__T; 3]], __t: &mut [[__T; 3]]) -> #p::Result<(), #p::ModelError> { #fail }
            }
        };
    }
}
