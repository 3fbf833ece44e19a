//! `contact_links` and `contact_points`: the links of the model's
//! `contact(...)` declarations and where their origins are, for the guards
//! of a hybrid run (a foot's height at touchdown). Nothing (the trait's
//! defaults) for a model without such contacts.

use proc_macro2::TokenStream;
use quote::quote;

use super::code::{code, Target};
use super::functions::Common;
use super::{int, p, Emitter};

impl Emitter<'_> {
    /// The two methods, or nothing.
    pub(super) fn contact_functions(&self, c: &Common) -> TokenStream {
        let model = self.model;
        if model.contacts.is_empty() {
            return TokenStream::new();
        }
        let p = p();
        let links = model.contacts.iter().map(|k| k.link.to_string());
        let roots: Vec<_> = model.contacts.iter().flat_map(|k| k.origin).collect();
        let mut points = code(&model.g, &roots, Target::Generic { hoist: false });
        let out = (0..model.contacts.len())
            .map(|k| {
                let position = &points.outputs[3 * k..3 * k + 3];
                let k = int(k);
                quote!(__points[#k] = [#(#position),*];)
            })
            .collect::<Vec<_>>();
        let body = points.take_statements();
        let (chk_q, chk_points) = (
            self.check("__q", self.d.n),
            self.check("__points", model.contacts.len()),
        );
        let (params_t, bind_q) = (&c.params_t, &c.bind_q);
        quote! {
            fn contact_links() -> &'static [&'static str] { &[#(#links),*] }
            fn contact_points<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __points: &mut [[__T; 3]]) -> #p::Result<(), #p::ModelError> {
                #chk_q #chk_points #params_t #bind_q #body #(#out)*
                #p::Ok(())
            }
        }
    }
}
