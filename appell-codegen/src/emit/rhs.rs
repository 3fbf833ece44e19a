//! `prepare` and `rhs`: the reduced equations as the integrators call them.
//!
//! `prepare` computes every parameter-only value once per parameter set
//! (and the LDLᵀ factors of a constant M); `rhs` reads them from the
//! `Prepared` array, solves the numeric elimination and M ÿ = f, and writes
//! the retained coordinates' rates and ÿ. Its work runs in a closure so
//! that an error path can name a NaN or infinite input (see
//! `non_finite_diagnosis`) without slowing the path that
//! succeeds.

use appell_symbolic::{Id, OpCount};

use crate::derivation::Elimination;
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

use super::code::{braced, code, Target};
use super::{int, p, Emitter};

/// The pieces of the reduced equations the implementation is made of.
pub(super) struct RhsParts {
    /// The `ModelInfo` value.
    pub info: TokenStream,
    /// `fn prepare`.
    pub prepare: TokenStream,
    /// `fn rhs`.
    pub rhs: TokenStream,
    /// The length of the `Prepared` array.
    pub hoisted: usize,
    /// The program's operations per call.
    pub ops: OpCount,
    /// Operations per call besides the program's (solves).
    pub extra: usize,
}

/// What `prepare` and `rhs` are made of, in either form.
struct Pieces<'a> {
    /// `prepare`'s statements.
    prepare: TokenStream,
    /// The names `rhs` reads from `Prepared`.
    names: &'a [TokenStream],
    /// The expressions `prepare` returns.
    values: &'a [TokenStream],
    /// The program's per-call statements.
    body: TokenStream,
    /// What follows them: the solve and the writes to `dstate`.
    tail: TokenStream,
}

/// The factorization of M, where it runs and what it costs per call.
struct Factors {
    /// Statements in `prepare` (a constant M), else empty.
    prepare: TokenStream,
    /// Statements in `rhs`: the factorization, or the pivot checks of the
    /// prepared factors.
    rhs: TokenStream,
    /// Operations per rhs call.
    ops: usize,
    /// The names `rhs` reads from `Prepared`.
    names: Vec<TokenStream>,
    /// The expressions `prepare` returns.
    values: Vec<TokenStream>,
}

impl Emitter<'_> {
    /// `prepare` and `rhs` (their `info` left empty for [`Self::rhs_info`]),
    /// the form's description, and whether it is the articulated-body
    /// algorithm's: the structured form where the model has one and it
    /// costs fewer operations per call, else the closed form.
    pub(super) fn rhs(&self, common: &super::functions::Common) -> (RhsParts, String, bool) {
        if let (false, Ok(s)) = (self.d.closed_form, &self.d.structured) {
            let chosen = self.structured_rhs(common, &s.accelerations);
            let form = format!(
                "structured: the articulated-body algorithm over the joint tree, {} operations per call (the closed form is not derived for trees of {} moving links or more)",
                chosen.ops.total(),
                crate::derivation::tree::STRUCTURED_ONLY_LINKS
            );
            return (chosen, form, true);
        }
        let flat = self.flat_rhs(common);
        let flat_total = flat.ops.total() + flat.extra;
        if let Some(pr) = self.d.projection {
            let form = if pr.chosen() {
                format!("structured: M by the composite-rigid-body algorithm and f by recursive Newton–Euler over the joint tree, projected onto the privileged speeds (M = Cᵀ M_q C), {} operations for M and f per call against the closed form's {}", pr.ops, pr.closed_ops)
            } else {
                format!("closed form: {} operations for M and f per call against the projected joint tree's {}", pr.closed_ops, pr.ops)
            };
            return (flat, form, false);
        }
        if !self.d.closed_form {
            // A large tree's scene: M and f from the tree's recursions, for
            // a scene that holds contacts in the tree's own speeds and
            // projected onto the scene's.
            let form = if self.d.own_constraints {
                format!("structured: M by the composite-rigid-body algorithm and f by recursive Newton–Euler over the joint tree, in its own speeds and projected onto the scene's (the dependent joints' rates from the scene's constraints), {flat_total} operations per call")
            } else {
                format!("structured: M by the composite-rigid-body algorithm and f by recursive Newton–Euler over the joint tree, solved by LDLᵀ, {flat_total} operations per call")
            };
            return (flat, form, false);
        }
        let (chosen, form, structured) = match &self.d.structured {
            Ok(s) if matches!(self.d.elimination, Elimination::Symbolic) => {
                let structured = self.structured_rhs(common, &s.accelerations);
                let total = structured.ops.total();
                if total < flat_total {
                    let form = format!("structured: the articulated-body algorithm over the joint tree, {total} operations per call against the closed form's {flat_total}");
                    (structured, form, true)
                } else {
                    let form = format!("closed form: {flat_total} operations per call against the structured form's {total}");
                    (flat, form, false)
                }
            }
            Ok(_) => (flat, "closed form".to_string(), false),
            Err(reason) if reason.is_empty() => (flat, "closed form".to_string(), false),
            Err(reason) => (
                flat,
                format!("closed form ({reason}, so no structured form)"),
                false,
            ),
        };
        (chosen, form, structured)
    }

    /// The chosen rhs with its `ModelInfo`, which counts its operations,
    /// names its form and says which Jacobian was written.
    pub(super) fn rhs_info(
        &self,
        chosen: RhsParts,
        form: &str,
        jacobian: &super::jacobian::JacobianParts,
    ) -> RhsParts {
        let info = self.info(chosen.ops, chosen.extra, form, jacobian);
        RhsParts { info, ..chosen }
    }

    /// The closed form: M and f from Appell's equations, the numeric
    /// elimination, M ÿ = f by LDLᵀ.
    fn flat_rhs(&self, common: &super::functions::Common) -> RhsParts {
        let d = self.d;
        let (l, retained) = (d.l, &d.reduction.retained);
        let constant_mass = self.constant_mass();
        let mut tri_roots: Vec<Id> = Vec::new();
        for i in 0..l {
            for j in 0..=i {
                tri_roots.push(d.equations.mass[i * l + j]);
            }
        }
        let mut roots: Vec<Id> = if constant_mass {
            Vec::new()
        } else {
            tri_roots.clone()
        };
        roots.extend(&d.equations.forcing);
        roots.extend(retained.iter().map(|&r| d.map.qdot[r]));
        let (rhs, rhs_body, elim_ops) = self.staged_rhs(&roots);
        let tri = if constant_mass { 0 } else { l * (l + 1) / 2 };
        let factors = self.factors(&tri_roots, &rhs.outputs, &rhs.hoisted, constant_mass);
        let (solve, solve_ops) = self.ldlt_solve(&rhs.outputs[tri..tri + l]);
        let rates_out = (0..retained.len()).map(|k| {
            let (value, k) = (&rhs.outputs[tri + l + k], int(k));
            quote!(__dstate[#k] = #value;)
        });
        let accels_out = (0..l).map(|k| {
            let (y, k) = (format_ident!("__y_{}", k), int(retained.len() + k));
            quote!(__dstate[#k] = #y;)
        });
        let (factors_rhs, prepare_statements) = (&factors.rhs, &rhs.prepare);
        let factors_prepare = &factors.prepare;
        let pieces = Pieces {
            prepare: quote!(#(#prepare_statements)* #factors_prepare),
            names: &factors.names,
            values: &factors.values,
            body: rhs_body,
            tail: quote!(#factors_rhs #solve #(#rates_out)* #(#accels_out)*),
        };
        let (prepare, rhs_fn) = self.rhs_functions(common, pieces);
        RhsParts {
            info: TokenStream::new(),
            prepare,
            rhs: rhs_fn,
            hoisted: factors.names.len(),
            ops: rhs.ops,
            extra: factors.ops + solve_ops + elim_ops,
        }
    }

    /// The structured form: ÿ straight from the recursions' expressions.
    fn structured_rhs(&self, common: &super::functions::Common, accelerations: &[Id]) -> RhsParts {
        let d = self.d;
        let (l, retained) = (d.l, &d.reduction.retained);
        let mut roots: Vec<Id> = accelerations.to_vec();
        roots.extend(retained.iter().map(|&r| d.map.qdot[r]));
        let mut c = code(&self.model.g, &roots, Target::Generic { hoist: true });
        let rates_out = (0..retained.len()).map(|k| {
            let (value, k) = (&c.outputs[l + k], int(k));
            quote!(__dstate[#k] = #value;)
        });
        let accels_out = (0..l).map(|k| {
            let (value, k) = (&c.outputs[k], int(retained.len() + k));
            quote!(__dstate[#k] = #value;)
        });
        let tail = quote!(#(#rates_out)* #(#accels_out)*);
        let body = std::mem::take(&mut c.body);
        let prepare = std::mem::take(&mut c.prepare);
        let pieces = Pieces {
            prepare: quote!(#(#prepare)*),
            names: &c.hoisted,
            values: &c.hoisted,
            body: quote!(#(#body)*),
            tail,
        };
        let (prepare, rhs_fn) = self.rhs_functions(common, pieces);
        RhsParts {
            info: TokenStream::new(),
            prepare,
            rhs: rhs_fn,
            hoisted: c.hoisted.len(),
            ops: c.ops,
            extra: 0,
        }
    }

    /// `prepare` and `rhs` around the pieces of either form.
    fn rhs_functions(
        &self,
        common: &super::functions::Common,
        pieces: Pieces,
    ) -> (TokenStream, TokenStream) {
        let p = p();
        let retained = &self.d.reduction.retained;
        let ns = retained.len() + self.d.l;
        let finite = if ns == 0 {
            quote!(true)
        } else {
            let each = (0..ns).map(|k| {
                let k = int(k);
                quote!(#p::Scalar::re(__dstate[#k]).is_finite())
            });
            quote!(#(#each)&&*)
        };
        let hi = int(pieces.names.len());
        let (params_t, pos, bind_inputs) =
            (&common.params_t, &common.positivity, &common.bind_inputs);
        let (names, values, prepare_statements, tail) =
            (pieces.names, pieces.values, &pieces.prepare, &pieces.tail);
        let checks = [
            self.check("__state", ns),
            self.check("__inputs", self.inputs().len()),
            self.check("__dstate", ns),
        ];
        let diagnose = self.non_finite_diagnosis();
        let quaternions = self.quaternion_length_checks();
        let bind_state = self.bind_state();
        let prepare = quote! {
            fn prepare<__T: #p::Scalar>(&self) -> [__T; #hi] {
                #params_t #prepare_statements
                [#(#values),*]
            }
        };
        let closure_body = braced([
            quote! {
                let [#(#names),*] = *__prepared;
                #params_t #bind_state #bind_inputs #quaternions
            },
            pieces.body,
            quote! {
                #tail
                if !(#finite) { return #p::Err(#p::ModelError::NonFinite { what: "the state derivative" }); }
                #p::Ok(())
            },
        ]);
        let rhs_fn = quote! {
            fn rhs<__T: #p::Scalar>(&self, __prepared: &[__T; #hi], t: __T, __state: &[__T], __inputs: &[__T], __dstate: &mut [__T]) -> #p::Result<(), #p::ModelError> {
                #(#checks)* #pos
                let __result: #p::Result<(), #p::ModelError> = (|| #closure_body)();
                match __result {
                    #p::Ok(()) => #p::Ok(()),
                    #p::Err(__e) => {
                        #diagnose
                        #p::Err(__e)
                    }
                }
            }
        };
        (prepare, rhs_fn)
    }

    /// M's factorization: in `prepare` when M is constant (its pivots still
    /// checked per call, against the prepared tolerance), else in `rhs`
    /// from the program's outputs.
    fn factors(
        &self,
        tri_roots: &[Id],
        outputs: &[TokenStream],
        hoisted: &[TokenStream],
        constant_mass: bool,
    ) -> Factors {
        let p = p();
        let l = self.d.l;
        let lower = |values: &[TokenStream]| {
            let mut m = vec![TokenStream::new(); l * l];
            let mut idx = 0;
            for i in 0..l {
                for j in 0..=i {
                    m[i * l + j] = values[idx].clone();
                    idx += 1;
                }
            }
            m
        };
        if !constant_mass {
            let (rhs, ops) = self.ldlt_factor(&lower(outputs), true);
            return Factors {
                prepare: TokenStream::new(),
                rhs,
                ops,
                names: hoisted.to_vec(),
                values: hoisted.to_vec(),
            };
        }
        let mut mc = code(&self.model.g, tri_roots, Target::Generic { hoist: false });
        let (fac, _) = self.ldlt_factor(&lower(&mc.outputs), false);
        let factor_names = self.factor_names();
        let count = int(factor_names.len());
        let statements = mc.take_statements();
        let prepare = quote! {
            let __factors: [__T; #count] = {
                #statements
                #fac
                let __tolv = <__T as #p::Scalar>::from_f64(__tol);
                [#(#factor_names),*]
            };
        };
        let rhs = (0..l)
            .map(|j| self.pivot_check(j, quote!(#p::Scalar::re(__tolv))))
            .collect();
        let mut names = hoisted.to_vec();
        names.extend(factor_names.iter().map(|n| quote!(#n)));
        let mut values = hoisted.to_vec();
        values.extend((0..factor_names.len()).map(|i| {
            let i = int(i);
            quote!(__factors[#i])
        }));
        Factors {
            prepare,
            rhs,
            ops: 0,
            names,
            values,
        }
    }
}
