//! What a robot's description adds to the model: `contact_links` and
//! `contact_points` (the links of the model's `contact(...)` declarations
//! and where their origins are, for the guards of a hybrid run: a foot's
//! height at touchdown), and `joint_limits` (its URDF's `<limit>`s).
//! Nothing (the trait's defaults) for a model without them.

use proc_macro2::{Literal, TokenStream};
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

impl Emitter<'_> {
    /// `joint_limits`, or nothing.
    pub(super) fn limit_function(&self) -> TokenStream {
        let limits = &self.model.joint_limits;
        if limits.is_empty() {
            return TokenStream::new();
        }
        let p = p();
        let number = |x: f64| {
            if x == f64::INFINITY {
                quote!(f64::INFINITY)
            } else if x == f64::NEG_INFINITY {
                quote!(f64::NEG_INFINITY)
            } else {
                let lit = Literal::f64_suffixed(x);
                quote!(#lit)
            }
        };
        let entries = limits.iter().map(|(joint, [lower, upper, velocity, effort])| {
            let (lower, upper, velocity, effort) =
                (number(*lower), number(*upper), number(*velocity), number(*effort));
            quote!(#p::JointLimit { joint: #joint, lower: #lower, upper: #upper, velocity: #velocity, effort: #effort })
        });
        quote! {
            fn joint_limits() -> &'static [#p::JointLimit] { &[#(#entries),*] }
        }
    }
}
