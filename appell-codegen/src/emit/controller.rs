//! The controller functions: inverse dynamics, M alone, the bias h and
//! the gravity term. A tree of joints computes them from its structured
//! form (recursive Newton–Euler, composite-rigid-body); every other model
//! from its `mass_matrix_and_forcing` with the inputs at zero, in
//! fixed-size arrays on the stack.

use appell_symbolic::Id;
use proc_macro2::TokenStream;
use quote::quote;

use super::code::{code, Target};
use super::functions::Common;
use super::{int, p, Emitter};

impl Emitter<'_> {
    /// `inverse_dynamics`, `mass_matrix`, `bias_forces`, `gravity_forces`.
    pub(super) fn controller_functions(&self, c: &Common) -> TokenStream {
        match (&self.d.structured, self.scene) {
            (Ok(s), None) => {
                let inverse = self.structured_function(c, "inverse_dynamics", &s.inverse);
                let mass = self.structured_function(c, "mass_matrix", &s.mass);
                let bias = self.structured_function(c, "bias_forces", &s.bias);
                let gravity = self.structured_function(c, "gravity_forces", &s.gravity);
                quote!(#inverse #mass #bias #gravity)
            }
            _ => self.closed_form_controller(),
        }
    }

    /// One function from the structured form's expressions.
    fn structured_function(&self, c: &Common, name: &str, roots: &[Id]) -> TokenStream {
        let p = p();
        let g = &self.model.g;
        let (n, l) = (self.d.n, self.d.l);
        let mut program = code(g, roots, Target::Generic { hoist: false });
        let body = program.take_statements();
        let out_name = match name {
            "inverse_dynamics" => "__forces",
            "mass_matrix" => "__m",
            "bias_forces" => "__bias",
            _ => "__gravity",
        };
        let out = self.ident(out_name);
        let writes = program.outputs.iter().enumerate().map(|(k, v)| {
            let k = int(k);
            quote!(#out[#k] = #v;)
        });
        let (params_t, pos) = (&c.params_t, &c.positivity);
        let (chk_q, chk_out) = (self.check("__q", n), self.check(out_name, roots.len()));
        let bind_q = self.bind_q("__q");
        let speeds = matches!(name, "inverse_dynamics" | "bias_forces");
        let (chk_u, bind_u) = if speeds {
            (self.check("__u", l), self.bind_u("__u"))
        } else {
            (TokenStream::new(), TokenStream::new())
        };
        let (chk_a, bind_a) = if name == "inverse_dynamics" {
            let binds = self.model.speed_specs.iter().enumerate().map(|(k, spec)| {
                let (a, k) = (self.ident(g.symbol_name(spec.accel)), int(k));
                quote!(let #a = __accel[#k];)
            });
            (self.check("__accel", l), quote!(#(#binds)*))
        } else {
            (TokenStream::new(), TokenStream::new())
        };
        let fn_name = self.ident(name);
        let args = match name {
            "inverse_dynamics" => {
                quote!(__q: &[__T], __u: &[__T], __accel: &[__T], #out: &mut [__T])
            }
            "bias_forces" => quote!(__q: &[__T], __u: &[__T], #out: &mut [__T]),
            _ => quote!(__q: &[__T], #out: &mut [__T]),
        };
        quote! {
            fn #fn_name<__T: #p::Scalar>(&self, t: __T, #args) -> #p::Result<(), #p::ModelError> {
                #chk_q #chk_u #chk_a #chk_out #pos #params_t #bind_q #bind_u #bind_a
                #body
                #(#writes)*
                #p::Ok(())
            }
        }
    }

    /// The four functions through `mass_matrix_and_forcing`.
    fn closed_form_controller(&self) -> TokenStream {
        let p = p();
        let (l, ni) = (int(self.d.l), int(self.model.inputs.len()));
        let ll = int(self.d.l * self.d.l);
        let chk = |arg: &str, len: usize| self.check(arg, len);
        let (chk_accel, chk_forces) = (chk("__accel", self.d.l), chk("__forces", self.d.l));
        let (chk_bias, chk_gravity) = (chk("__bias", self.d.l), chk("__gravity", self.d.l));
        let chk_m = chk("__m", self.d.l * self.d.l);
        let zero = quote!(<__T as #p::Scalar>::zero());
        let setup = quote! {
            let __zero_inputs = [#zero; #ni];
            let mut __mm = [#zero; #ll];
            let mut __ff = [#zero; #l];
        };
        quote! {
            fn inverse_dynamics<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __u: &[__T], __accel: &[__T], __forces: &mut [__T]) -> #p::Result<(), #p::ModelError> {
                #chk_accel #chk_forces #setup
                self.mass_matrix_and_forcing(t, __q, __u, &__zero_inputs, &mut __mm, &mut __ff)?;
                for __i in 0..#l {
                    let mut __s = -__ff[__i];
                    for __j in 0..#l {
                        __s = __s + __mm[__i * #l + __j] * __accel[__j];
                    }
                    __forces[__i] = __s;
                }
                #p::Ok(())
            }
            fn mass_matrix<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __m: &mut [__T]) -> #p::Result<(), #p::ModelError> {
                #chk_m #setup
                let __u = [#zero; #l];
                self.mass_matrix_and_forcing(t, __q, &__u, &__zero_inputs, __m, &mut __ff)
            }
            fn bias_forces<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __u: &[__T], __bias: &mut [__T]) -> #p::Result<(), #p::ModelError> {
                #chk_bias #setup
                self.mass_matrix_and_forcing(t, __q, __u, &__zero_inputs, &mut __mm, &mut __ff)?;
                for __i in 0..#l {
                    __bias[__i] = -__ff[__i];
                }
                #p::Ok(())
            }
            fn gravity_forces<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __gravity: &mut [__T]) -> #p::Result<(), #p::ModelError> {
                #chk_gravity #setup
                let __u = [#zero; #l];
                self.mass_matrix_and_forcing(t, __q, &__u, &__zero_inputs, &mut __mm, &mut __ff)?;
                for __i in 0..#l {
                    __gravity[__i] = -__ff[__i];
                }
                #p::Ok(())
            }
        }
    }
}
