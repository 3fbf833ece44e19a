//! The `Model` trait's methods.
//!
//! `prepare` and `rhs` carry the reduced equations (see the `rhs` module);
//! the other methods each evaluate one group of the derivation's
//! expressions at a full state: M and f, C and c, q̇, the constraint
//! residuals and rows, W and w, the energies and input power, and the
//! kinematic description the multiplier oracle and the constraint-force
//! outputs read (mass properties, body poses, load geometry and values,
//! contact geometry). Every slice argument's length is checked first.

use appell_symbolic::{Id, Symbol, SymbolKind};
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

use super::code::{braced, code, Code, Target};
use super::solve::matrix;
use super::{int, p, Emitter};
use crate::derivation::RowSource;

/// `target[i] = output_i;` for the outputs `range`, from index 0. Where
/// most of them are 0 (C of a tree is the identity), the slice is filled
/// with zeros first and only the others are stored.
fn outputs_into(c: &Code, target: &str, range: std::ops::Range<usize>) -> TokenStream {
    let p = p();
    let target = format_ident!("{}", target);
    let zeros = c.zero[range.clone()].iter().filter(|z| **z).count();
    let sparse = zeros > 8 && 2 * zeros > range.len();
    let fill = if sparse {
        let len = int(range.len());
        quote!(#target[..#len].fill(<__T as #p::Scalar>::zero());)
    } else {
        TokenStream::new()
    };
    let skip = &c.zero[range.clone()];
    let stores = c.outputs[range].iter().enumerate().filter_map(|(i, o)| {
        let k = int(i);
        (!(sparse && skip[i])).then(|| quote!(#target[#k] = #o;))
    });
    quote!(#fill #(#stores)*)
}

/// `target[k] = [outputs...];` for `count` groups of `width` outputs from
/// `offset`.
fn groups_into(c: &Code, target: &str, offset: usize, count: usize, width: usize) -> TokenStream {
    let target = format_ident!("{}", target);
    let stores = (0..count).map(|k| {
        let items = &c.outputs[offset + k * width..offset + (k + 1) * width];
        let k = int(k);
        quote!(#target[#k] = [#(#items),*];)
    });
    quote!(#(#stores)*)
}

/// Statements every method's body shares.
pub(super) struct Common {
    pub(super) params_t: TokenStream,
    params_f: TokenStream,
    pub(super) positivity: TokenStream,
    pub(super) bind_q: TokenStream,
    bind_qdot: TokenStream,
    bind_u: TokenStream,
    pub(super) bind_inputs: TokenStream,
    /// S X = R and S w = … solved (M and f need w).
    solve_x_and_w: TokenStream,
    /// S X = R solved.
    solve_x: TokenStream,
}

/// The programs of the equations' functions, lowered: each one's
/// statements with its stores, or (the energies) its statements and value.
struct EquationPrograms {
    speed_transform: TokenStream,
    coordinate_rates: TokenStream,
    residuals: TokenStream,
    speed_definitions: TokenStream,
    input_power: (TokenStream, TokenStream),
    potential: (TokenStream, TokenStream),
    kinetic: (TokenStream, TokenStream),
}

impl Emitter<'_> {
    /// The `ModelInfo` static and the `Model` implementation.
    pub(super) fn implementation(&self) -> TokenStream {
        let p = p();
        let common = Common {
            params_t: self.params_as(true),
            params_f: self.params_as(false),
            positivity: self.positivity(),
            bind_q: self.bind_q("__q"),
            bind_qdot: self.bind_qdot("__qdot"),
            bind_u: self.bind_u("__u"),
            bind_inputs: self.bind_inputs("__inputs"),
            solve_x_and_w: self.elimination(true),
            solve_x: self.elimination(false),
        };
        let (rhs, form, articulated) = self.rhs(&common);
        let jacobian = self.jacobian(&common, articulated);
        let rhs = self.rhs_info(rhs, &form, &jacobian);
        let jacobian_fn = &jacobian.function;
        let info = &rhs.info;
        let (info_ident, name) = (&self.info_ident, &self.type_name);
        let (scene_infos, scene_rhs) = (&self.scene_infos, &self.scene_rhs);
        let h = int(rhs.hoisted);
        let (prepare, rhs_fn) = (&rhs.prepare, &rhs.rhs);
        let parameters = self.parameter_access();
        let equations = self.equations_functions(&common);
        let kinematics = self.kinematics_functions(&common);
        let contacts = self.contact_functions(&common);
        let limits = self.limit_function();
        let loads = self.load_functions(&common);
        let controller = self.controller_functions(&common);
        quote! {
            static #info_ident: #p::ModelInfo = #info;
            #[automatically_derived]
            #[allow(unused_variables, unused_parens, non_snake_case, clippy::all)]
            impl #p::Model for #name {
                type Prepared<__T: #p::Scalar> = [__T; #h];
                fn info() -> &'static #p::ModelInfo { &#info_ident }
                fn scene_infos() -> &'static [&'static #p::ModelInfo] { #scene_infos }
                #scene_rhs
                #parameters
                #prepare
                #rhs_fn
                #jacobian_fn
                #equations
                #kinematics
                #contacts
                #limits
                #loads
                #controller
            }
        }
    }

    /// `parameter_values` and `set_parameter`.
    fn parameter_access(&self) -> TokenStream {
        let p = p();
        let this = &self.this;
        let params = &self.model.params;
        let check = self.check("__out", params.len());
        let gets = params.iter().enumerate().map(|(k, prm)| {
            let (f, k) = (prm.place(), int(k));
            quote!(__out[#k] = #this.#f;)
        });
        let sets = params.iter().map(|prm| {
            let (f, name) = (prm.place(), prm.ident.to_string());
            quote!(#name => { #this.#f = __value; true })
        });
        quote! {
            fn parameter_values(&self, __out: &mut [f64]) -> #p::Result<(), #p::ModelError> {
                #check
                #(#gets)*
                #p::Ok(())
            }
            fn set_parameter(&mut self, __name: &str, __value: f64) -> bool {
                match __name {
                    #(#sets,)*
                    _ => false,
                }
            }
        }
    }

    /// M and f, C and c, q̇, the constraint residuals, W and w, the input
    /// power and the energies.
    fn equations_functions(&self, c: &Common) -> TokenStream {
        let p = p();
        let d = self.d;
        let lowered = self.lowered_equations();
        let (n, l) = (d.n, d.l);
        let Common {
            params_t,
            positivity: pos,
            bind_q,
            bind_u,
            solve_x,
            ..
        } = c;
        let chk = |arg: &str, len: usize| self.check(arg, len);
        let (chk_q, chk_u) = (chk("__q", n), chk("__u", l));
        let ke_fn = match (&d.structured, d.closed_form) {
            (Ok(_), false) => self.kinetic_through_mass(),
            _ => {
                let (ke_body, ke_out) = &lowered.kinetic;
                braced([
                    quote!(#chk_q #chk_u #pos #params_t #bind_q #bind_u #solve_x #ke_body),
                    quote!(#p::Ok(#ke_out)),
                ])
            }
        };
        let mf_fn = self.mass_and_forcing_fn(c);
        let mf_item = quote! {
            fn mass_matrix_and_forcing<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __u: &[__T], __inputs: &[__T], __m: &mut [__T], __f: &mut [__T]) -> #p::Result<(), #p::ModelError> #mf_fn
        };
        let sd_ip_pe = self.speeds_power_potential(c, &lowered);
        if !self.model.input_rates.is_empty() {
            return self.driven_equations_functions(c, &lowered, mf_item, sd_ip_pe);
        }
        let checks_ct = [chk("__c", n * l), chk("__c0", n)];
        let chk_qdot = chk("__qdot", n);
        let checks_res = [
            chk("__holonomic", d.constraints.holonomic.len()),
            chk("__velocity", d.m),
        ];
        let bind_qdot = &c.bind_qdot;
        let EquationPrograms {
            speed_transform: ct,
            coordinate_rates: cr,
            residuals: res,
            ..
        } = &lowered;
        quote! {
            #mf_item
            fn speed_transform<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __c: &mut [__T], __c0: &mut [__T]) -> #p::Result<(), #p::ModelError> {
                #chk_q #(#checks_ct)* #pos #params_t #bind_q #solve_x #ct
                #p::Ok(())
            }
            fn coordinate_rates<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __u: &[__T], __qdot: &mut [__T]) -> #p::Result<(), #p::ModelError> {
                #chk_q #chk_u #chk_qdot #pos #params_t #bind_q #bind_u #solve_x #cr
                #p::Ok(())
            }
            fn constraint_residuals<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __qdot: &[__T], __holonomic: &mut [__T], __velocity: &mut [__T]) -> #p::Result<(), #p::ModelError> {
                #chk_q #chk_qdot #(#checks_res)* #params_t #bind_q #bind_qdot #res
                #p::Ok(())
            }
            #sd_ip_pe
            fn kinetic_energy<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __u: &[__T]) -> #p::Result<__T, #p::ModelError> #ke_fn
        }
    }

    /// The programs of `equations_functions`, lowered: each function's
    /// statements with its stores after them.
    fn lowered_equations(&self) -> EquationPrograms {
        let d = self.d;
        let (n, m, l) = (d.n, d.m, d.l);
        let nh = d.constraints.holonomic.len();
        let generic = Target::Generic { hoist: false };
        let mut ct_roots = d.map.c.clone();
        ct_roots.extend(&d.map.c0);
        let mut ct = code(&self.model.g, &ct_roots, generic);
        let (ct_body, ct_c, ct_c0) = (
            ct.take_statements(),
            outputs_into(&ct, "__c", 0..n * l),
            outputs_into(&ct, "__c0", n * l..n * l + n),
        );
        let mut cr = code(&self.model.g, &d.map.qdot, generic);
        let (cr_body, cr_out) = (cr.take_statements(), outputs_into(&cr, "__qdot", 0..n));
        let mut res_roots = d.constraints.holonomic.clone();
        res_roots.extend(&d.velocity_residuals);
        let mut res = code(&self.model.g, &res_roots, generic);
        let (res_body, res_h, res_v) = (
            res.take_statements(),
            outputs_into(&res, "__holonomic", 0..nh),
            outputs_into(&res, "__velocity", nh..nh + m),
        );
        let mut sd_roots = d.speeds.w.clone();
        sd_roots.extend(&d.speeds.w0);
        let mut sd = code(&self.model.g, &sd_roots, generic);
        let (sd_body, sd_w, sd_w0) = (
            sd.take_statements(),
            outputs_into(&sd, "__w", 0..l * n),
            outputs_into(&sd, "__w0", l * n..l * n + l),
        );
        let single = |e: Id| {
            let mut c = code(&self.model.g, &[e], generic);
            (c.take_statements(), c.outputs[0].clone())
        };
        EquationPrograms {
            speed_transform: quote!(#ct_body #ct_c #ct_c0),
            coordinate_rates: quote!(#cr_body #cr_out),
            residuals: quote!(#res_body #res_h #res_v),
            speed_definitions: quote!(#sd_body #sd_w #sd_w0),
            input_power: single(d.energies.input_power),
            potential: single(d.energies.potential),
            kinetic: single(d.energies.kinetic),
        }
    }

    /// W and w, the input power and V: the same whether or not the
    /// constraints read inputs.
    fn speeds_power_potential(&self, c: &Common, lowered: &EquationPrograms) -> TokenStream {
        let p = p();
        let d = self.d;
        let (n, l) = (d.n, d.l);
        let chk = |arg: &str, len: usize| self.check(arg, len);
        let (chk_q, chk_u, chk_inputs) = (
            chk("__q", n),
            chk("__u", l),
            chk("__inputs", self.inputs().len()),
        );
        let checks_sd = [chk("__w", l * n), chk("__w0", l)];
        let Common {
            params_t,
            bind_q,
            bind_u,
            bind_inputs,
            solve_x,
            ..
        } = c;
        let sd = &lowered.speed_definitions;
        let (ip_body, ip_out) = &lowered.input_power;
        let (pe_body, pe_out) = &lowered.potential;
        quote! {
            fn speed_definitions<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __w: &mut [__T], __w0: &mut [__T]) -> #p::Result<(), #p::ModelError> {
                #chk_q #(#checks_sd)* #params_t #bind_q #sd
                #p::Ok(())
            }
            fn input_power<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __u: &[__T], __inputs: &[__T]) -> #p::Result<__T, #p::ModelError> {
                #chk_q #chk_u #chk_inputs #params_t #bind_q #bind_u #bind_inputs #solve_x #ip_body
                #p::Ok(#ip_out)
            }
            fn potential_energy<__T: #p::Scalar>(&self, t: __T, __q: &[__T]) -> #p::Result<__T, #p::ModelError> {
                #chk_q #params_t #bind_q #pe_body
                #p::Ok(#pe_out)
            }
        }
    }

    /// Driven coordinates: C, c, q̇, the residuals and T read the inputs;
    /// only the `driven_` forms take them. T is always the symbolic one:
    /// ½ uᵀ M u leaves out the commanded rates.
    fn driven_equations_functions(
        &self,
        c: &Common,
        lowered: &EquationPrograms,
        mf_item: TokenStream,
        sd_ip_pe: TokenStream,
    ) -> TokenStream {
        let p = p();
        let d = self.d;
        let (n, l) = (d.n, d.l);
        let chk = |arg: &str, len: usize| self.check(arg, len);
        let (chk_q, chk_u, chk_inputs) = (
            chk("__q", n),
            chk("__u", l),
            chk("__inputs", self.inputs().len()),
        );
        let checks_ct = [chk("__c", n * l), chk("__c0", n)];
        let chk_qdot = chk("__qdot", n);
        let checks_res = [
            chk("__holonomic", d.constraints.holonomic.len()),
            chk("__velocity", d.m),
        ];
        let Common {
            params_t,
            positivity: pos,
            bind_q,
            bind_qdot,
            bind_u,
            bind_inputs,
            solve_x,
            ..
        } = c;
        let EquationPrograms {
            speed_transform: ct,
            coordinate_rates: cr,
            residuals: res,
            kinetic: (ke_body, ke_out),
            ..
        } = lowered;
        let needs = |f: &str| quote!({ #p::Err(#p::ModelError::NeedsInputs { function: #f }) });
        let (ns, nc, nr, nk) = (
            needs("speed_transform"),
            needs("coordinate_rates"),
            needs("constraint_residuals"),
            needs("kinetic_energy"),
        );
        quote! {
            #mf_item
            fn speed_transform<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __c: &mut [__T], __c0: &mut [__T]) -> #p::Result<(), #p::ModelError> #ns
            fn driven_speed_transform<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __inputs: &[__T], __c: &mut [__T], __c0: &mut [__T]) -> #p::Result<(), #p::ModelError> {
                #chk_q #chk_inputs #(#checks_ct)* #pos #params_t #bind_q #bind_inputs #solve_x #ct
                #p::Ok(())
            }
            fn coordinate_rates<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __u: &[__T], __qdot: &mut [__T]) -> #p::Result<(), #p::ModelError> #nc
            fn driven_coordinate_rates<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __u: &[__T], __inputs: &[__T], __qdot: &mut [__T]) -> #p::Result<(), #p::ModelError> {
                #chk_q #chk_u #chk_inputs #chk_qdot #pos #params_t #bind_q #bind_u #bind_inputs #solve_x #cr
                #p::Ok(())
            }
            fn constraint_residuals<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __qdot: &[__T], __holonomic: &mut [__T], __velocity: &mut [__T]) -> #p::Result<(), #p::ModelError> #nr
            fn driven_constraint_residuals<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __qdot: &[__T], __inputs: &[__T], __holonomic: &mut [__T], __velocity: &mut [__T]) -> #p::Result<(), #p::ModelError> {
                #chk_q #chk_qdot #chk_inputs #(#checks_res)* #params_t #bind_q #bind_qdot #bind_inputs #res
                #p::Ok(())
            }
            #sd_ip_pe
            fn kinetic_energy<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __u: &[__T]) -> #p::Result<__T, #p::ModelError> #nk
            fn driven_kinetic_energy<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __u: &[__T], __inputs: &[__T]) -> #p::Result<__T, #p::ModelError> {
                #chk_q #chk_u #chk_inputs #pos #params_t #bind_q #bind_u #bind_inputs #solve_x #ke_body
                #p::Ok(#ke_out)
            }
        }
    }

    /// The body of `mass_matrix_and_forcing`: the structured form's, or M
    /// and f of the closed form.
    fn mass_and_forcing_fn(&self, c: &Common) -> proc_macro2::Group {
        let p = p();
        let d = self.d;
        let (n, l) = (d.n, d.l);
        if let (Ok(s), false) = (&d.structured, d.closed_form) {
            return self.structured_mass_and_forcing(c, s);
        }
        let Common {
            params_t,
            positivity: pos,
            bind_q,
            bind_u,
            bind_inputs,
            solve_x_and_w,
            ..
        } = c;
        let chk = |arg: &str, len: usize| self.check(arg, len);
        let (chk_q, chk_u) = (chk("__q", n), chk("__u", l));
        let chk_inputs = chk("__inputs", self.inputs().len());
        let checks_mf = [chk("__m", l * l), chk("__f", l)];
        let mut mf_roots = d.equations.mass.clone();
        mf_roots.extend(&d.equations.forcing);
        let mut mf = code(&self.model.g, &mf_roots, Target::Generic { hoist: false });
        let (mf_m, mf_f) = (
            outputs_into(&mf, "__m", 0..l * l),
            outputs_into(&mf, "__f", l * l..l * l + l),
        );
        braced([
            quote!(#chk_q #chk_u #chk_inputs #(#checks_mf)* #pos #params_t #bind_q #bind_u #bind_inputs #solve_x_and_w),
            mf.take_statements(),
            quote!(#mf_m #mf_f #p::Ok(())),
        ])
    }

    /// The bodies' description: mass properties, body poses and the
    /// constraint rows.
    fn kinematics_functions(&self, c: &Common) -> TokenStream {
        let p = p();
        let d = self.d;
        let model = self.model;
        let (n, m) = (d.n, d.m);
        let Common {
            params_t,
            params_f,
            bind_q,
            ..
        } = c;
        let generic = Target::Generic { hoist: false };
        let chk = |arg: &str, len: usize| self.check(arg, len);
        let chk_q = chk("__q", n);
        let nb = model.bodies.len();
        let mut mp_roots = Vec::new();
        for b in &model.bodies {
            mp_roots.push(b.mass);
            for row in &b.inertia {
                mp_roots.extend(row);
            }
        }
        let mut mp = code(&self.model.g, &mp_roots, Target::F64);
        let mp_out = (0..nb)
            .map(|k| {
                let mass = &mp.outputs[k * 10];
                let inertia = &mp.outputs[k * 10 + 1..k * 10 + 10];
                let k = int(k);
                quote!(__masses[#k] = #mass; __inertias[#k] = [#(#inertia),*];)
            })
            .collect::<Vec<_>>();
        let (_, identity) = unit_entries(model);
        let mut pose_roots = Vec::new();
        for b in &model.bodies {
            pose_roots.extend(b.center);
            let r = b.frame.map(|f| model.frames[f].rot).unwrap_or(identity);
            for row in &r {
                pose_roots.extend(row);
            }
        }
        let mut poses = code(&self.model.g, &pose_roots, generic);
        let poses_out = (0..nb)
            .map(|k| {
                let position = &poses.outputs[k * 12..k * 12 + 3];
                let rotation = &poses.outputs[k * 12 + 3..k * 12 + 12];
                let k = int(k);
                quote!(__positions[#k] = [#(#position),*]; __rotations[#k] = [#(#rotation),*];)
            })
            .collect::<Vec<_>>();
        let mut rows_roots = d.constraints.d.clone();
        rows_roots.extend(&d.constraints.d0);
        let mut rows = code(&self.model.g, &rows_roots, generic);
        let (rows_d, rows_d0) = (
            outputs_into(&rows, "__d", 0..m * n),
            outputs_into(&rows, "__d0", m * n..m * n + m),
        );
        let checks_mp = [chk("__masses", nb), chk("__inertias", nb)];
        let checks_poses = [chk("__positions", nb), chk("__rotations", nb)];
        let checks_rows = [chk("__d", m * n), chk("__d0", m)];
        let (mp_body, poses_body, rows_body) = (
            mp.take_statements(),
            poses.take_statements(),
            rows.take_statements(),
        );
        let rows_fn = if self.model.input_rates.is_empty() {
            quote! {
                fn constraint_rows<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __d: &mut [__T], __d0: &mut [__T]) -> #p::Result<(), #p::ModelError> {
                    #chk_q #(#checks_rows)* #params_t #bind_q #rows_body #rows_d #rows_d0
                    #p::Ok(())
                }
            }
        } else {
            let (chk_inputs, bind_inputs) = (
                chk("__inputs", self.inputs().len()),
                self.bind_inputs("__inputs"),
            );
            quote! {
                fn constraint_rows<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __d: &mut [__T], __d0: &mut [__T]) -> #p::Result<(), #p::ModelError> {
                    #p::Err(#p::ModelError::NeedsInputs { function: "constraint_rows" })
                }
                fn driven_constraint_rows<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __inputs: &[__T], __d: &mut [__T], __d0: &mut [__T]) -> #p::Result<(), #p::ModelError> {
                    #chk_q #chk_inputs #(#checks_rows)* #params_t #bind_q #bind_inputs #rows_body #rows_d #rows_d0
                    #p::Ok(())
                }
            }
        };
        let margin_fn = self.dependent_block_margin(c);
        let validate_fn = self.validate(c);
        quote! {
            #margin_fn
            #validate_fn
            fn mass_properties(&self, __masses: &mut [f64], __inertias: &mut [[f64; 9]]) -> #p::Result<(), #p::ModelError> {
                #(#checks_mp)* #params_f #mp_body #(#mp_out)*
                #p::Ok(())
            }
            fn body_poses<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __positions: &mut [[__T; 3]], __rotations: &mut [[__T; 9]]) -> #p::Result<(), #p::ModelError> {
                #chk_q #(#checks_poses)* #params_t #bind_q #poses_body #(#poses_out)*
                #p::Ok(())
            }
            #rows_fn
        }
    }

    /// `validate`: positivity, then every body whose mass or inertia
    /// depends on parameters (the others were checked at compile time)
    /// against the rules of `physical`, through `mass_properties`. Nothing
    /// (the trait's default) for a model with neither.
    fn validate(&self, c: &Common) -> TokenStream {
        let p = p();
        let g = &self.model.g;
        let params = &self.model.params;
        let checks: Vec<TokenStream> = self
            .model
            .bodies
            .iter()
            .enumerate()
            .filter_map(|(k, b)| {
                let names = |roots: &[Id]| -> Vec<String> {
                    params
                        .iter()
                        .filter(|prm| roots.iter().any(|&e| g.depends_on(e, prm.symbol)))
                        .map(|prm| prm.display())
                        .collect()
                };
                let of_mass = names(&[b.mass]);
                let of_inertia = names(&b.inertia.concat());
                if of_mass.is_empty() && of_inertia.is_empty() {
                    return None;
                }
                let (name, k) = (&b.name, int(k));
                Some(quote!(#p::check_body(#name, &[#(#of_mass),*], &[#(#of_inertia),*], __masses[#k], &__inertias[#k])?;))
            })
            .collect();
        let positivity = &c.positivity;
        let divisors = self.divisor_checks();
        if checks.is_empty() && positivity.is_empty() && divisors.is_empty() {
            return TokenStream::new();
        }
        let nb = int(self.model.bodies.len());
        let bodies = (!checks.is_empty()).then(|| {
            quote! {
                let mut __masses = [0.0f64; #nb];
                let mut __inertias = [[0.0f64; 9]; #nb];
                <Self as #p::Model>::mass_properties(self, &mut __masses, &mut __inertias)?;
                #(#checks)*
            }
        });
        quote! {
            fn validate(&self) -> #p::Result<(), #p::ModelError> {
                #positivity
                #divisors
                #bodies
                #p::Ok(())
            }
        }
    }

    /// `dependent_block_margin`: D′, the constraint rows' columns of the
    /// dependent coordinates, and its pivot margin. Nothing for a model
    /// without dependent rates (the trait's default serves it).
    fn dependent_block_margin(&self, c: &Common) -> TokenStream {
        let p = p();
        let d = self.d;
        let (n, m) = (d.n, d.m);
        let dependent = &d.speeds.dependent;
        if m == 0 || dependent.len() != m {
            return TokenStream::new();
        }
        let Common {
            params_t, bind_q, ..
        } = c;
        let mut roots = Vec::with_capacity(m * m);
        for i in 0..m {
            roots.extend(dependent.iter().map(|&col| d.constraints.d[i * n + col]));
        }
        let mut block = code(&self.model.g, &roots, Target::Generic { hoist: false });
        let rows = matrix(&block.outputs, 0, m, m);
        let body = block.take_statements();
        let mi = int(m);
        let chk_q = self.check("__q", n);
        let (chk_inputs, bind_inputs) = if self.model.input_rates.is_empty() {
            (TokenStream::new(), TokenStream::new())
        } else {
            (
                self.check("__inputs", self.inputs().len()),
                self.bind_inputs("__inputs"),
            )
        };
        quote! {
            fn dependent_block_margin<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __inputs: &[__T]) -> #p::Result<f64, #p::ModelError> {
                #chk_q #chk_inputs #params_t #bind_q #bind_inputs #body
                let __block: [[__T; #mi]; #mi] = [#rows];
                #p::pivot_margin(&__block)
            }
        }
    }

    /// Where the loads act and what they are, and the rolling contacts'
    /// geometry: load geometry, contact geometry and load values.
    fn load_functions(&self, c: &Common) -> TokenStream {
        let p = p();
        let d = self.d;
        let model = self.model;
        let (n, m) = (d.n, d.m);
        let Common {
            params_t,
            bind_q,
            bind_qdot,
            bind_inputs,
            ..
        } = c;
        let generic = Target::Generic { hoist: false };
        let chk = |arg: &str, len: usize| self.check(arg, len);
        let chk_q = chk("__q", n);
        let (forces, torques) = (self.forces(), self.torques());
        let (nf, nt, nc) = (
            forces.len(),
            torques.len(),
            self.d.constraint_set.rolling.len(),
        );
        let (zero, identity) = unit_entries(model);
        let mut geo_roots = Vec::new();
        for f in &forces {
            geo_roots.extend(f.point);
        }
        for t in &torques {
            for row in &model.frames[t.frame].rot {
                geo_roots.extend(row);
            }
        }
        let mut geo = code(&self.model.g, &geo_roots, generic);
        let (geo_points, geo_frames) = (
            groups_into(&geo, "__points", 0, nf, 3),
            groups_into(&geo, "__frames", nf * 3, nt, 9),
        );
        let mut load_roots = Vec::new();
        for f in &forces {
            load_roots.extend(f.vector);
        }
        for t in &torques {
            load_roots.extend(t.vector);
        }
        let mut loads = code(&self.model.g, &load_roots, generic);
        let (loads_forces, loads_torques) = (
            groups_into(&loads, "__forces", 0, nf, 3),
            groups_into(&loads, "__torques", nf * 3, nt, 3),
        );
        // Contact points, then the direction of every rolling row.
        let mut contact_roots = Vec::new();
        for r in &self.d.constraint_set.rolling {
            contact_roots.extend(r.contact);
        }
        for src in &d.constraints.sources {
            match *src {
                RowSource::Rolling { contact, direction } => {
                    match &self.d.constraint_set.rolling[contact].along {
                        Some(dirs) => contact_roots.extend(dirs[direction]),
                        None => contact_roots.extend(identity[direction]),
                    }
                }
                _ => contact_roots.extend([zero; 3]),
            }
        }
        let mut contacts = code(&self.model.g, &contact_roots, generic);
        let (contacts_points, contacts_dirs) = (
            groups_into(&contacts, "__points", 0, nc, 3),
            groups_into(&contacts, "__directions", nc * 3, m, 3),
        );
        let checks_geo = [chk("__points", nf), chk("__frames", nt)];
        let checks_contacts = [chk("__points", nc), chk("__directions", m)];
        let checks_loads = [
            chk("__qdot", n),
            chk("__inputs", self.inputs().len()),
            chk("__forces", nf),
            chk("__torques", nt),
        ];
        let (geo_body, contacts_body, loads_body) = (
            geo.take_statements(),
            contacts.take_statements(),
            loads.take_statements(),
        );
        quote! {
            fn load_geometry<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __points: &mut [[__T; 3]], __frames: &mut [[__T; 9]]) -> #p::Result<(), #p::ModelError> {
                #chk_q #(#checks_geo)* #params_t #bind_q #geo_body #geo_points #geo_frames
                #p::Ok(())
            }
            fn contact_geometry<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __points: &mut [[__T; 3]], __directions: &mut [[__T; 3]]) -> #p::Result<(), #p::ModelError> {
                #chk_q #(#checks_contacts)* #params_t #bind_q #contacts_body #contacts_points #contacts_dirs
                #p::Ok(())
            }
            fn load_values<__T: #p::Scalar>(&self, t: __T, __q: &[__T], __qdot: &[__T], __inputs: &[__T], __forces: &mut [[__T; 3]], __torques: &mut [[__T; 3]]) -> #p::Result<(), #p::ModelError> {
                #chk_q #(#checks_loads)* #params_t #bind_q #bind_qdot #bind_inputs #loads_body #loads_forces #loads_torques
                #p::Ok(())
            }
        }
    }

    /// Statements returning `NonFinite` naming the first state component,
    /// input or parameter of the rhs that is NaN or infinite, or a
    /// zero-length `norm`/`unit` argument that the state determines.
    pub(super) fn non_finite_diagnosis(&self) -> TokenStream {
        let p = p();
        let d = self.d;
        let model = self.model;
        let this = &self.this;
        let mut names: Vec<String> = d
            .reduction
            .retained
            .iter()
            .map(|&r| self.coord(r).to_string())
            .collect();
        names.extend(self.speeds().iter().map(|sp| {
            let name = self.model.g.symbol_name(sp.symbol).to_string();
            match sp.coordinate {
                Some(_) => name,
                None => sp.name.clone(),
            }
        }));
        let mut out = TokenStream::new();
        for (k, name) in names.iter().enumerate() {
            let (k, what) = (int(k), format!("state component `{name}`"));
            out.extend(quote!(if !#p::Scalar::re(__state[#k]).is_finite() { return #p::Err(#p::ModelError::NonFinite { what: #what }); }));
        }
        for (k, (name, _)) in self.inputs().into_iter().enumerate() {
            let (k, what) = (int(k), format!("input `{name}`"));
            out.extend(quote!(if !#p::Scalar::re(__inputs[#k]).is_finite() { return #p::Err(#p::ModelError::NonFinite { what: #what }); }));
        }
        for prm in &model.params {
            let (f, what) = (prm.place(), format!("parameter `{}`", prm.display()));
            out.extend(quote!(if !#this.#f.is_finite() { return #p::Err(#p::ModelError::NonFinite { what: #what }); }));
        }
        out.extend(self.divisor_checks());
        out.extend(self.zero_length_checks());
        out
    }

    /// A `ZeroDivisor` for each divisor made of parameters alone that is
    /// zero, naming the parameters (nothing when there is none).
    fn divisor_checks(&self) -> TokenStream {
        let p = p();
        let model = self.model;
        let g = &model.g;
        let mut list: Vec<&(Id, String)> = Vec::new();
        for entry in &model.divisors {
            if !list.iter().any(|(d, _)| *d == entry.0) {
                list.push(entry);
            }
        }
        if list.is_empty() {
            return TokenStream::new();
        }
        let roots: Vec<Id> = list.iter().map(|(d, _)| *d).collect();
        let mut c = code(g, &roots, Target::F64);
        let statements = c.take_statements();
        let params_f = self.params_as(false);
        let tests = list.iter().enumerate().map(|(k, (d, place))| {
            let names: Vec<String> = model
                .params
                .iter()
                .filter(|prm| g.depends_on(*d, prm.symbol))
                .map(|prm| prm.display())
                .collect();
            let value = &c.outputs[k];
            quote!(if #value == 0.0 { return #p::Err(#p::ModelError::ZeroDivisor { place: #place, parameters: &[#(#names),*] }); })
        });
        quote!({ #params_f #statements #(#tests)* })
    }

    /// A zero-length `norm`/`unit` argument, where it depends on the
    /// retained coordinates and the parameters only (so the state
    /// determines it).
    fn zero_length_checks(&self) -> TokenStream {
        let p = p();
        let d = self.d;
        let model = self.model;
        let g = &model.g;
        let retained: Vec<Symbol> = d
            .reduction
            .retained
            .iter()
            .map(|&r| model.coords[r].1.q)
            .collect();
        let checked: Vec<&(Id, String)> = model
            .norms
            .iter()
            .filter(|(n2, _)| {
                g.dependencies(*n2)
                    .iter()
                    .all(|sym| match g.symbol_kind(sym) {
                        SymbolKind::Parameter | SymbolKind::Time => true,
                        SymbolKind::Coordinate => retained.contains(&sym),
                        _ => false,
                    })
                    && !g.is_parameter_only(*n2)
            })
            .collect();
        if checked.is_empty() {
            return TokenStream::new();
        }
        let roots: Vec<Id> = checked.iter().map(|(n2, _)| *n2).collect();
        let mut c = code(&self.model.g, &roots, Target::Generic { hoist: false });
        let params_t = self.params_as(true);
        let binds = d.reduction.retained.iter().enumerate().map(|(k, &r)| {
            let (q, k) = (self.coord(r), int(k));
            quote!(let #q = __state[#k];)
        });
        let statements = c.take_statements();
        let tests = checked.iter().enumerate().map(|(k, (_, label))| {
            let (value, what) = (&c.outputs[k], format!("{label} has zero length"));
            quote!(if !(#p::Scalar::re(#value) > 1e-20) { return #p::Err(#p::ModelError::NonFinite { what: #what }); })
        });
        quote!({ #params_t #(#binds)* #statements #(#tests)* })
    }

    /// The quaternions whose four coordinates are all in the reduced state.
    pub(super) fn retained_quaternions(&self) -> impl Iterator<Item = &[usize; 4]> {
        let retained = &self.d.reduction.retained;
        let all = &self.model.quaternions;
        all.iter()
            .filter(|block| block.iter().all(|c| retained.contains(c)))
    }

    /// A quaternion of the reduced state with zero length is an error in
    /// `rhs` itself: the rates no longer divide by its length (they hold
    /// on the unit sphere), so nothing else would turn non-finite. One
    /// comparison per quaternion, of a sum of the squares the rotation
    /// computes anyway. Statements for the closure, where the state is
    /// bound.
    pub(super) fn quaternion_length_checks(&self) -> TokenStream {
        let p = p();
        let model = self.model;
        let g = &model.g;
        let mut checked = Vec::new();
        for block in self.retained_quaternions() {
            let symbols: Vec<Symbol> = block.iter().map(|&c| model.coords[c].1.q).collect();
            // The block's squared length: the norm reading its four
            // coordinates and nothing else.
            let found = model.norms.iter().find(|(n2, _)| {
                let deps = g.dependencies(*n2);
                deps.len() == 4 && symbols.iter().all(|s| deps.contains(*s))
            });
            if let Some((id, label)) = found {
                checked.push((*id, label.clone()));
            }
        }
        if checked.is_empty() {
            return TokenStream::new();
        }
        let roots: Vec<Id> = checked.iter().map(|(n2, _)| *n2).collect();
        let mut c = code(&model.g, &roots, Target::Generic { hoist: false });
        let statements = c.take_statements();
        let tests = checked.iter().enumerate().map(|(k, (_, label))| {
            let (value, what) = (&c.outputs[k], format!("{label} has zero length"));
            quote!(if !(#p::Scalar::re(#value) > 1e-20) { return #p::Err(#p::ModelError::NonFinite { what: #what }); })
        });
        quote!({ #statements #(#tests)* })
    }
}

/// The graph's zero and the identity matrix: N's rotation, which the
/// model builds from them.
fn unit_entries(model: &crate::model::Model) -> (Id, [[Id; 3]; 3]) {
    let identity = model.frames[0].rot;
    (identity[0][1], identity)
}
