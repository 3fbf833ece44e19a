//! The controller functions: inverse dynamics, M alone, the bias h and
//! the gravity term. A tree of joints computes them from its structured
//! form (recursive Newton–Euler, composite-rigid-body); every other model
//! from its `mass_matrix_and_forcing` with the inputs at zero, in
//! fixed-size arrays on the stack.

use appell_symbolic::Id;
use proc_macro2::TokenStream;
use quote::quote;

use super::code::{braced, code, Target};
use super::functions::Common;
use super::{int, p, Emitter};
use crate::derivation::jacobian::SIZE_LIMIT;
use crate::derivation::tree::Structured;

impl Emitter<'_> {
    /// `inverse_dynamics`, `mass_matrix`, `bias_forces`, `gravity_forces`
    /// and `inverse_dynamics_derivatives`.
    pub(super) fn controller_functions(&self, c: &Common) -> TokenStream {
        let functions = match (&self.d.structured, self.scene) {
            (Ok(s), None) => {
                let inverse = self.structured_function(c, "inverse_dynamics", &s.inverse);
                let mass = self.structured_function(c, "mass_matrix", &s.mass);
                let bias = self.bias_through_inverse();
                let gravity = self.structured_function(c, "gravity_forces", &s.gravity);
                quote!(#inverse #mass #bias #gravity)
            }
            _ => self.closed_form_controller(),
        };
        let derivatives = self.inverse_derivatives(c);
        let forward = self.forward_derivatives();
        quote!(#functions #derivatives #forward)
    }

    /// `forward_dynamics_derivatives`: the rows of `rhs_jacobian` that
    /// give the accelerations, with its retained coordinates' columns put
    /// back among all the coordinates (zero for the ignorable ones), as
    /// Pinocchio's `computeABADerivatives` returns them; nothing with
    /// `jacobian(off)`.
    fn forward_derivatives(&self) -> TokenStream {
        if self.model.jacobian == Some(false) {
            return TokenStream::new();
        }
        let p = p();
        let (n, l, ni) = (self.d.n, self.d.l, self.inputs().len());
        let retained = &self.d.reduction.retained;
        let (nr, s) = (retained.len(), retained.len() + l);
        let checks = [
            self.check("__q", n),
            self.check("__u", l),
            self.check("__inputs", ni),
            self.check("__accel", l),
            self.check("__dq", l * n),
            self.check("__du", l * l),
            self.check("__dinputs", l * ni),
        ];
        let kept = retained.iter().map(|&r| int(r));
        let zero = quote!(<__T as #p::Scalar>::zero());
        let (n, l, ni, nr, s) = (int(n), int(l), int(ni), int(nr), int(s));
        quote! {
            fn forward_dynamics_derivatives<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __u: &[__T], __inputs: &[__T], __accel: &mut [__T], __dq: &mut [__T], __du: &mut [__T], __dinputs: &mut [__T]) -> #p::Result<(), #p::ModelError> {
                #(#checks)*
                const __KEPT: [usize; #nr] = [#(#kept),*];
                let mut __x = [#zero; #s];
                for (__r, &__c) in __KEPT.iter().enumerate() {
                    __x[__r] = __q[__c];
                }
                __x[#nr..].copy_from_slice(__u);
                let mut __rates = [#zero; #s];
                let mut __a = [#zero; #s * #s];
                let mut __b = [#zero; #s * #ni];
                self.rhs_jacobian(t, &__x, __inputs, &mut __rates, &mut __a, &mut __b)?;
                for __k in 0..#l {
                    let __row = #nr + __k;
                    __accel[__k] = __rates[__row];
                    for __c in 0..#n {
                        __dq[__k * #n + __c] = #zero;
                    }
                    for (__r, &__c) in __KEPT.iter().enumerate() {
                        __dq[__k * #n + __c] = __a[__row * #s + __r];
                    }
                    for __j in 0..#l {
                        __du[__k * #l + __j] = __a[__row * #s + #nr + __j];
                    }
                    for __i in 0..#ni {
                        __dinputs[__k * #ni + __i] = __b[__row * #ni + __i];
                    }
                }
                #p::Ok(())
            }
        }
    }

    /// `inverse_dynamics_derivatives`: a tree's recursive Newton–Euler
    /// differentiated, or its world frame's derivatives (stage 14's
    /// `inverse`, whichever has fewer expressions) when it has at most
    /// [`SIZE_LIMIT`] times the expressions of the recursion (any size with
    /// `jacobian(on)`), else the inverse dynamics in dual numbers; nothing
    /// with `jacobian(off)`.
    fn inverse_derivatives(&self, c: &Common) -> TokenStream {
        if self.model.jacobian == Some(false) {
            return TokenStream::new();
        }
        let symbolic = match (&self.d.structured, self.scene, &self.d.jacobians) {
            (Ok(s), None, Some(j)) => j.inverse.as_ref().ok().map(|partials| (s, partials)),
            _ => None,
        };
        if let Some((s, partials)) = symbolic {
            let g = &self.model.g;
            let mut roots = s.inverse.clone();
            roots.extend(partials);
            let (total, values) = (g.dag_size(&roots), g.dag_size(&s.inverse).max(1));
            if self.model.jacobian == Some(true) || total <= SIZE_LIMIT * values {
                return self.symbolic_inverse_derivatives(c, &roots);
            }
        }
        let p = p();
        let (n, l) = (self.d.n, self.d.l);
        let (width, _) = super::jacobian::dual_width(n + l);
        let (n, l, w) = (int(n), int(l), int(width));
        quote! {
            fn inverse_dynamics_derivatives<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __u: &[__T], __accel: &[__T], __forces: &mut [__T], __dq: &mut [__T], __du: &mut [__T], __m: &mut [__T]) -> #p::Result<(), #p::ModelError> {
                #p::inverse_dynamics_derivatives_by_duals::<Self, __T, #n, #l, #w>(self, t, __q, __u, __accel, __forces, __dq, __du, __m)
            }
        }
    }

    /// The symbolic `inverse_dynamics_derivatives`: one program for Q,
    /// ∂Q/∂q and ∂Q/∂u (`roots`, in that order), M from `mass_matrix`.
    fn symbolic_inverse_derivatives(&self, c: &Common, roots: &[Id]) -> TokenStream {
        let p = p();
        let g = &self.model.g;
        let (n, l) = (self.d.n, self.d.l);
        let mut program = code(g, roots, Target::Generic { hoist: false });
        let body = program.take_statements();
        // The partials come row by row, each row's coordinates then speeds.
        let writes = program.outputs.iter().enumerate().map(|(k, v)| {
            let (row, column) = (k.wrapping_sub(l) / (n + l), k.wrapping_sub(l) % (n + l));
            let (out, at) = if k < l {
                (quote!(__forces), k)
            } else if column < n {
                (quote!(__dq), row * n + column)
            } else {
                (quote!(__du), row * l + column - n)
            };
            let at = int(at);
            quote!(#out[#at] = #v;)
        });
        let checks = [
            self.check("__q", n),
            self.check("__u", l),
            self.check("__accel", l),
            self.check("__forces", l),
            self.check("__dq", l * n),
            self.check("__du", l * l),
            self.check("__m", l * l),
        ];
        let (params_t, pos) = (&c.params_t, &c.positivity);
        let (bind_q, bind_u) = (self.bind_q("__q"), self.bind_u("__u"));
        let bind_a = self.bind_accel("__accel");
        let body = braced([quote! {
            #params_t #bind_q #bind_u #bind_a
            #body
            #(#writes)*
        }]);
        quote! {
            fn inverse_dynamics_derivatives<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __u: &[__T], __accel: &[__T], __forces: &mut [__T], __dq: &mut [__T], __du: &mut [__T], __m: &mut [__T]) -> #p::Result<(), #p::ModelError> {
                #(#checks)* #pos
                #body
                self.mass_matrix(t, __q, __m)?;
                if !__dq.iter().chain(__du.iter()).all(|__v| #p::Scalar::re(*__v).is_finite()) {
                    return #p::Err(#p::ModelError::NonFinite { what: "the inverse dynamics' Jacobian" });
                }
                #p::Ok(())
            }
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
            (self.check("__accel", l), self.bind_accel("__accel"))
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

    /// h as the inverse dynamics at zero accelerations: the same
    /// recursion but for one addition per link, emitted once.
    fn bias_through_inverse(&self) -> TokenStream {
        let p = p();
        let l = int(self.d.l);
        let checks = [
            self.check("__q", self.d.n),
            self.check("__u", self.d.l),
            self.check("__bias", self.d.l),
        ];
        quote! {
            fn bias_forces<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __u: &[__T], __bias: &mut [__T]) -> #p::Result<(), #p::ModelError> {
                #(#checks)*
                let __accel = [<__T as #p::Scalar>::zero(); #l];
                self.inverse_dynamics(t, __q, __u, &__accel, __bias)
            }
        }
    }

    /// The body of a large tree's `mass_matrix_and_forcing`: M from
    /// `mass_matrix`, h from `bias_forces`, f = τ − h, so that the
    /// recursions are emitted once.
    pub(super) fn structured_mass_and_forcing(
        &self,
        c: &Common,
        s: &Structured,
    ) -> proc_macro2::Group {
        let p = p();
        let (n, l, ni) = (self.d.n, self.d.l, self.inputs().len());
        let checks = [
            self.check("__q", n),
            self.check("__u", l),
            self.check("__inputs", ni),
            self.check("__m", l * l),
            self.check("__f", l),
        ];
        let mut program = code(&self.model.g, &s.inputs, Target::Generic { hoist: false });
        let body = program.take_statements();
        let stores = program.outputs.iter().enumerate().map(|(k, tau)| {
            let k = int(k);
            quote!(__f[#k] = #tau - __f[#k];)
        });
        let (params_t, bind_inputs) = (&c.params_t, &c.bind_inputs);
        braced([quote! {
            #(#checks)*
            self.mass_matrix(t, __q, __m)?;
            self.bias_forces(t, __q, __u, __f)?;
            #params_t #bind_inputs #body
            #(#stores)*
            #p::Ok(())
        }])
    }

    /// The body of a large tree's `kinetic_energy`: ½ uᵀ M u with M from
    /// `mass_matrix`, rather than a second copy of the velocity recursion.
    pub(super) fn kinetic_through_mass(&self) -> proc_macro2::Group {
        let p = p();
        let (n, l) = (self.d.n, self.d.l);
        let checks = [self.check("__q", n), self.check("__u", l)];
        let (li, ll) = (int(l), int(l * l));
        let zero = quote!(<__T as #p::Scalar>::zero());
        braced([quote! {
            #(#checks)*
            let mut __m = [#zero; #ll];
            self.mass_matrix(t, __q, &mut __m)?;
            let mut __twice = #zero;
            for __i in 0..#li {
                let mut __row = #zero;
                for __j in 0..#li {
                    __row = __m[__i * #li + __j].fma(__u[__j], __row);
                }
                __twice = __u[__i].fma(__row, __twice);
            }
            #p::Ok(__twice * <__T as #p::Scalar>::from_f64(0.5))
        }])
    }

    /// The four functions through `mass_matrix_and_forcing`.
    fn closed_form_controller(&self) -> TokenStream {
        let p = p();
        let (l, ni) = (int(self.d.l), int(self.inputs().len()));
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
