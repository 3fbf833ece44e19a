//! `rhs_jacobian`: the reduced rhs and its Jacobians A = ∂rhs/∂state and
//! B = ∂rhs/∂inputs in one call, from stage 14's derivatives.
//!
//! Of six candidates the cheapest is written: the closed form (one
//! program for M, f, q̇ and their derivatives; M factored once by LDLᵀ; ÿ,
//! then each column ∂ÿ/∂c = M⁻¹ (∂f/∂c − (∂M/∂c) ÿ) by the same factors,
//! [`closed`]), the structured form (one program for the articulated-body
//! algorithm's ÿ and its derivatives), inverse dynamics (a tree's recursive
//! Newton–Euler differentiated at the articulated-body ÿ, each column
//! −M⁻¹ ∂R, [`recursive`]), the world frame (one program: its derivatives
//! of inverse dynamics, ÿ and every column solved by M's factors), the
//! world frame with its columns solved in loops over the columns
//! ([`loops`]), or dual
//! numbers (the model's own rhs evaluated
//! in W-wide dual numbers, ⌈columns / W⌉ times, by the runtime's
//! `rhs_jacobian_by_duals`: no code of its own). A symbolic one is written
//! only within a size limit against the rhs's expressions (dual numbers
//! cost about 1 + 2W expressions per rhs expression and pass); of those
//! left, the one of the lowest estimated cost once lowered: its
//! operations, those in loops counted [`loops::LANES`] to one, and the
//! loops' calls and copies. Parameter-only
//! work is not hoisted: the function needs no `Prepared`.

mod closed;
mod loops;
mod recursive;
mod sparse;

use appell_symbolic::{Id, OpCount};
use proc_macro2::TokenStream;
use quote::quote;

use super::code::{braced, code, Target};
use super::{int, p, Emitter};
use crate::derivation::jacobian::{retained_rates, Jacobians, SIZE_LIMIT};
use crate::derivation::Elimination;

/// The generated `rhs_jacobian` and the `Option<JacobianInfo>` it is
/// described by.
pub(super) struct JacobianParts {
    /// `fn rhs_jacobian`, or nothing (the trait's default).
    pub function: TokenStream,
    /// How `ModelInfo::jacobian` is written ([`JacobianParts::info`]).
    info: InfoParts,
    /// How it is computed, or why there is none, for the equations text.
    pub summary: String,
}

/// What `ModelInfo::jacobian` says.
enum InfoParts {
    /// `None`.
    Nothing,
    /// A symbolic candidate's `Some(JacobianInfo { .. })`.
    Symbolic(TokenStream),
    /// Dual numbers: W directions a pass, the passes; the cost follows
    /// from the rhs's.
    Dual(usize, usize),
}

impl JacobianParts {
    /// `ModelInfo::jacobian`'s value for a model whose rhs costs `rhs`.
    pub(super) fn info(&self, rhs: appell_core::OpCounts) -> TokenStream {
        let p = p();
        match &self.info {
            InfoParts::Nothing => quote!(::core::option::Option::None),
            InfoParts::Symbolic(info) => info.clone(),
            &InfoParts::Dual(width, passes) => {
                // The runtime's count of the passes, taken here.
                let c = appell_core::dual::pass_costs(rhs, width, passes);
                let form = &self.summary;
                let (add, mul, div, calls, total) = (
                    int(c.add),
                    int(c.mul),
                    int(c.div),
                    int(c.calls),
                    int(c.total),
                );
                quote! {
                    ::core::option::Option::Some(#p::JacobianInfo {
                        form: #form,
                        ops: #p::OpCounts { add: #add, mul: #mul, div: #div, calls: #calls, total: #total },
                    })
                }
            }
        }
    }
}

/// Dual numbers over `columns` columns: (W, passes), at most 8 directions
/// a pass (a large rhs's temporaries stay small) spread evenly over the
/// fewest passes (9 columns: 5 and 4, not 8 and 1).
pub(super) fn dual_width(columns: usize) -> (usize, usize) {
    let passes = columns.div_ceil(8).max(1);
    (columns.div_ceil(passes).max(1), passes)
}

/// A candidate's roots: the values, then the derivatives.
struct Roots {
    /// Every root.
    all: Vec<Id>,
    /// How many of them are values.
    values: usize,
}

/// One candidate's statements and cost.
struct Candidate {
    /// Everything after the bindings of state and inputs.
    body: TokenStream,
    /// The program's operations.
    ops: OpCount,
    /// Operations besides the program's (the factorization and solves).
    extra: usize,
    /// Operations in loops over the columns ([`loops`]), among `extra`'s
    /// kind but vectorized.
    looped: usize,
    /// What the loops cost besides their operations, in operations'
    /// worth (calls, the scratch zeroed and copied out): only compared.
    overhead: usize,
}

impl Candidate {
    /// Its operations per call.
    fn total(&self) -> usize {
        self.ops.total() + self.extra + self.looped
    }

    /// What candidates are compared by: the operations per call, those in
    /// loops over the columns taken [`loops::LANES`] at a time, and the
    /// loops' overhead.
    fn cost(&self) -> usize {
        self.ops.total() + self.extra + self.looped.div_ceil(loops::LANES) + self.overhead
    }

    /// Its operations, and those in loops, where it is compared with the
    /// chosen one.
    fn describe_total(&self) -> String {
        if self.looped == 0 {
            self.total().to_string()
        } else {
            format!("{} ({} in loops)", self.total(), self.looped)
        }
    }

    /// How `info().jacobian.form` counts it.
    fn describe_ops(&self) -> String {
        if self.looped == 0 {
            format!("{} operations per call", self.total())
        } else {
            format!(
                "{} operations per call, {} of them in loops over the columns",
                self.total(),
                self.looped
            )
        }
    }
}

/// Where the Jacobian's columns come from: each state column, then the
/// implementation's inputs (a scene may take fewer than the model).
struct Layout {
    /// Index into stage 14's columns of each column written, in order.
    columns: Vec<usize>,
    /// The state's length s.
    states: usize,
    /// The number of inputs taken.
    inputs: usize,
    /// The retained coordinates.
    retained: usize,
}

impl Layout {
    /// `__a[row * s + col]` or `__b[row * i + col - s]`.
    fn entry(&self, row: usize, col: usize) -> TokenStream {
        if col < self.states {
            let at = int(row * self.states + col);
            quote!(__a[#at])
        } else {
            let at = int(row * self.inputs + col - self.states);
            quote!(__b[#at])
        }
    }
}

/// The symbolic candidates, in the order a tie is decided.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Kind {
    Closed,
    Structured,
    Recursive,
    World,
    WorldLoops,
}

impl Kind {
    /// How `info().jacobian.form` says it.
    fn describe(self) -> &'static str {
        match self {
            Kind::Closed => "closed form: ∂M and ∂f, each column M⁻¹ (∂f − ∂M ÿ) by M's factors",
            Kind::Structured => {
                "structured: the articulated-body algorithm's accelerations differentiated"
            }
            Kind::Recursive => {
                "inverse dynamics: recursive Newton–Euler differentiated at the articulated-body ÿ, each column −M⁻¹ ∂R by the factors of M (composite rigid bodies)"
            }
            Kind::World => {
                "inverse dynamics in the world frame: recursive Newton–Euler's derivatives by joint pairs (Carpentier and Mansard), ÿ and each column M⁻¹ (∂τ − ∂Q) by the factors of M (subtree inertias)"
            }
            Kind::WorldLoops => {
                "inverse dynamics in the world frame: recursive Newton–Euler's derivatives by joint pairs (Carpentier and Mansard), ÿ by the factors of M (subtree inertias), the columns M⁻¹ (∂τ − ∂Q) by the same factors in loops over the columns"
            }
        }
    }

    /// Its short name among the others.
    fn name(self) -> &'static str {
        match self {
            Kind::Closed => "the closed form's",
            Kind::Structured => "the structured form's",
            Kind::Recursive => "inverse dynamics'",
            Kind::World => "the world frame's",
            Kind::WorldLoops => "the world frame's in loops",
        }
    }
}

/// A candidate's roots and sizes before lowering.
struct Sized {
    kind: Kind,
    roots: Roots,
    /// Its distinct expressions.
    total: usize,
    /// The distinct expressions of the rhs values it computes.
    values: usize,
}

impl Emitter<'_> {
    /// `rhs_jacobian` and its info: of the symbolic candidates with at
    /// most [`SIZE_LIMIT`] times the expressions of the rhs values they
    /// compute and fewer than the dual passes' estimate (any size with
    /// `jacobian(on)`), the one of the lowest estimated cost per call once
    /// lowered ([`Candidate::cost`]); where none is left, or stage 14 has no candidate, the rhs
    /// in dual numbers; nothing with `jacobian(off)`.
    /// `articulated`: whether the rhs written is the articulated-body
    /// algorithm's (else the closed form's).
    pub(super) fn jacobian(
        &self,
        common: &super::functions::Common,
        articulated: bool,
    ) -> JacobianParts {
        if self.model.jacobian == Some(false) {
            return JacobianParts {
                function: TokenStream::new(),
                info: InfoParts::Nothing,
                summary:
                    "none (turned off by `jacobian(off)`; tools use dual numbers through the rhs)"
                        .to_string(),
            };
        }
        let (width, passes) = self.dual_shape();
        // Expressions per rhs expression, over all passes (see the module).
        let dual_ratio = passes * (1 + 2 * width);
        let Some(j) = &self.d.jacobians else {
            return self.dual_parts(
                "stage 14 does not differentiate a scene with constraints of its own".to_string(),
            );
        };
        let layout = self.layout(j);
        let mut sized = self.candidates(j, &layout);
        if self.quaternion_in_state() {
            // Off the unit sphere the closed form and the recursions read a
            // quaternion differently; the Jacobian must be the rhs's.
            sized.retain(|c| (c.kind == Kind::Closed) != articulated);
        }
        if sized.is_empty() {
            let why = |r: Result<(), &String>| r.err().cloned().unwrap_or_default();
            let c = why(j.closed.as_ref().map(|_| ()));
            let s = why(j.structured.as_ref().map(|_| ()));
            let r = why(j.recursive.as_ref().map(|_| ()));
            let w = why(j.world.as_ref().map(|_| ()));
            return self.dual_parts(format!(
                "closed form: {c}; structured: {s}; inverse dynamics: {r}; world frame: {w}"
            ));
        }
        // Past the size limits (unless asked for), the rhs in dual numbers:
        // a symbolic Jacobian would grow the code past about twice the
        // model's.
        if self.model.jacobian != Some(true) {
            sized.sort_by_key(|c| c.total);
            let (total, values) = (sized[0].total, sized[0].values.max(1));
            sized.retain(|c| c.total <= SIZE_LIMIT * c.values.max(1));
            if sized.is_empty() {
                return self.dual_parts(format!(
                    "symbolic: its {total} expressions are more than {SIZE_LIMIT} times the rhs's {values}; `jacobian(on)` writes it"
                ));
            }
            sized.retain(|c| c.total <= dual_ratio * c.values.max(1));
            if sized.is_empty() {
                return self.dual_parts(format!(
                    "symbolic: its {total} expressions are more than the dual passes' {dual_ratio} times the rhs's {values}"
                ));
            }
        }
        // Each one left lowered; the lowest estimated cost wins, a tie going
        // to the earlier kind.
        let mut lowered: Vec<(Kind, Candidate)> = sized
            .into_iter()
            .map(|c| {
                let candidate = match c.kind {
                    Kind::Closed => {
                        let closed = j.closed.as_ref().expect("a closed candidate");
                        self.closed_candidate(c.roots, &layout, closed)
                    }
                    Kind::Structured => self.structured_candidate(c.roots, &layout),
                    Kind::Recursive => self.recursive_candidate(c.roots, &layout),
                    Kind::World => self.structured_candidate(c.roots, &layout),
                    Kind::WorldLoops => {
                        let world = j.world.as_ref().expect("a world-frame candidate");
                        self.loop_candidate(c.roots, &layout, world)
                    }
                };
                (c.kind, candidate)
            })
            .collect();
        lowered.sort_by_key(|(_, c)| c.cost());
        let (kind, chosen) = lowered.remove(0);
        let what = kind.describe();
        let against = lowered
            .iter()
            .map(|(k, c)| format!("{} {}", k.name(), c.describe_total()))
            .collect::<Vec<_>>();
        let against = if against.is_empty() {
            String::new()
        } else {
            format!(" against {}", against.join(", "))
        };
        let form = format!("{what}, {}{against}", chosen.describe_ops());
        let p = p();
        let o = chosen.ops;
        let (add, mul, div, calls, total) = (
            int(o.add),
            int(o.mul),
            int(o.div),
            int(o.calls),
            int(chosen.total()),
        );
        let info = quote! {
            ::core::option::Option::Some(#p::JacobianInfo {
                form: #form,
                ops: #p::OpCounts { add: #add, mul: #mul, div: #div, calls: #calls, total: #total },
            })
        };
        JacobianParts {
            function: self.jacobian_function(common, &layout, chosen.body),
            info: InfoParts::Symbolic(info),
            summary: form,
        }
    }

    /// Whether a quaternion's four coordinates are in the state: there the
    /// rhs's forms agree only on the unit sphere.
    fn quaternion_in_state(&self) -> bool {
        self.retained_quaternions().next().is_some()
    }

    /// Every symbolic candidate stage 14 built, with its sizes, counted
    /// in distinct expressions before lowering (a numeric elimination's S,
    /// R and right side count as the rhs's).
    fn candidates(&self, j: &Jacobians, layout: &Layout) -> Vec<Sized> {
        let g = &self.model.g;
        let elimination: Vec<Id> = match &self.d.elimination {
            Elimination::Numeric(ne) => ne.expressions().copied().collect(),
            Elimination::Symbolic => Vec::new(),
        };
        let size = |roots: &[Id]| {
            let mut all = roots.to_vec();
            all.extend(&elimination);
            g.dag_size(&all)
        };
        let tri = self.d.l * (self.d.l + 1) / 2;
        let mut out = Vec::new();
        if let Ok(c) = &j.closed {
            let roots = self.closed_roots(c, layout, j);
            let (total, values) = (size(&roots.all), size(&roots.all[..roots.values]));
            out.push(Sized {
                kind: Kind::Closed,
                roots,
                total,
                values,
            });
        }
        if let (Ok(s), Ok(form)) = (&j.structured, &self.d.structured) {
            let roots = self.rows_roots(&form.accelerations, s, layout, j);
            let (total, values) = (size(&roots.all), size(&roots.all[..roots.values]));
            out.push(Sized {
                kind: Kind::Structured,
                roots,
                total,
                values,
            });
        }
        if let Ok(r) = &j.recursive {
            let roots = self.recursive_roots(r, layout, j);
            // The rhs's values: ÿ and q̇, without M.
            let (total, values) = (size(&roots.all), size(&roots.all[tri..roots.values]));
            out.push(Sized {
                kind: Kind::Recursive,
                roots,
                total,
                values,
            });
        }
        if let (Ok(w), Ok(form)) = (&j.world, &self.d.structured) {
            // Against the rhs's values (q̇ and the articulated-body ÿ), not
            // its own ÿ by M's factors: the limit bounds the code's growth.
            let mut rhs = retained_rates(self.d);
            rhs.extend(&form.accelerations);
            let values = size(&rhs);
            if let Some(derivatives) = &w.derivatives {
                let roots = self.rows_roots(&w.accelerations, derivatives, layout, j);
                let total = size(&roots.all);
                out.push(Sized {
                    kind: Kind::World,
                    roots,
                    total,
                    values,
                });
            }
            let roots = self.loop_roots(w, layout, j);
            let total = size(&roots.all);
            out.push(Sized {
                kind: Kind::WorldLoops,
                roots,
                total,
                values,
            });
        }
        out
    }

    /// The dual numbers' width W and passes over the state's and the
    /// inputs' columns.
    fn dual_shape(&self) -> (usize, usize) {
        dual_width(self.d.reduction.retained.len() + self.d.l + self.inputs().len())
    }

    /// `rhs_jacobian` as the runtime's `rhs_jacobian_by_duals` over this
    /// implementation's state and inputs; `why` says why not symbolic.
    fn dual_parts(&self, why: String) -> JacobianParts {
        let p = p();
        let (width, passes) = self.dual_shape();
        let (s, i) = (
            self.d.reduction.retained.len() + self.d.l,
            self.inputs().len(),
        );
        let (su, iu, wu) = (int(s), int(i), int(width));
        let function = quote! {
            fn rhs_jacobian<__T: #p::Scalar>(&self, t: __T, __state: &[__T], __inputs: &[__T], __dstate: &mut [__T], __a: &mut [__T], __b: &mut [__T]) -> #p::Result<(), #p::ModelError> {
                #p::rhs_jacobian_by_duals::<Self, __T, #su, #iu, #wu>(self, t, __state, __inputs, __dstate, __a, __b)
            }
        };
        let plural = if passes == 1 { "" } else { "es" };
        let summary = format!(
            "dual numbers: the rhs in {passes} pass{plural} of {width} directions over the {} columns ({why})",
            s + i
        );
        JacobianParts {
            function,
            info: InfoParts::Dual(width, passes),
            summary,
        }
    }

    /// The columns this implementation writes.
    fn layout(&self, j: &Jacobians) -> Layout {
        let states = j.columns.state.len();
        let mut columns: Vec<usize> = (0..states).collect();
        let inputs = self.inputs();
        for (_, s) in &inputs {
            let k = j.columns.inputs.iter().position(|x| x == s);
            columns.push(states + k.expect("an input of the model"));
        }
        Layout {
            columns,
            states,
            inputs: inputs.len(),
            retained: self.d.reduction.retained.len(),
        }
    }

    /// The roots of a candidate that computes its rows in one program (the
    /// structured form, the world frame): q̇ and `accelerations`, then
    /// the rows of `jac` over the written columns.
    fn rows_roots(
        &self,
        accelerations: &[Id],
        jac: &[Id],
        layout: &Layout,
        j: &Jacobians,
    ) -> Roots {
        let n = j.columns.len();
        let mut roots = retained_rates(self.d);
        roots.extend(accelerations);
        let values = roots.len();
        for row in 0..values {
            roots.extend(layout.columns.iter().map(|&col| jac[row * n + col]));
        }
        Roots { all: roots, values }
    }

    /// The structured form or the world frame: one program for q̇, ÿ and
    /// their derivatives.
    fn structured_candidate(&self, roots: Roots, layout: &Layout) -> Candidate {
        let rows = roots.values;
        let mut program = code(&self.model.g, &roots.all, Target::Generic { hoist: false });
        let statements = program.take_statements();
        let mut body = quote!(#statements);
        for k in 0..rows {
            let (value, k) = (&program.outputs[k], int(k));
            body.extend(quote!(__dstate[#k] = #value;));
        }
        let width = layout.columns.len();
        for row in 0..rows {
            for w in 0..width {
                let at = rows + row * width + w;
                if !program.zero[at] {
                    let (value, entry) = (&program.outputs[at], layout.entry(row, w));
                    body.extend(quote!(#entry = #value;));
                }
            }
        }
        Candidate {
            body,
            ops: program.ops,
            extra: 0,
            looped: 0,
            overhead: 0,
        }
    }

    /// `fn rhs_jacobian` around a candidate's body.
    fn jacobian_function(
        &self,
        common: &super::functions::Common,
        layout: &Layout,
        body: TokenStream,
    ) -> TokenStream {
        let p = p();
        let (s, ni) = (layout.states, layout.inputs);
        let checks = [
            self.check("__state", s),
            self.check("__inputs", ni),
            self.check("__dstate", s),
            self.check("__a", s * s),
            self.check("__b", s * ni),
        ];
        let (params_t, pos, bind_inputs) =
            (&common.params_t, &common.positivity, &common.bind_inputs);
        let quaternions = self.quaternion_length_checks();
        let bind_state = self.bind_state();
        let diagnose = self.non_finite_diagnosis();
        let closure_body = braced([
            quote! {
                #params_t #bind_state #bind_inputs #quaternions
                for __v in __a.iter_mut().chain(__b.iter_mut()) {
                    *__v = <__T as #p::Scalar>::zero();
                }
            },
            body,
            quote! {
                if !__dstate.iter().all(|__v| #p::Scalar::re(*__v).is_finite()) {
                    return #p::Err(#p::ModelError::NonFinite { what: "the state derivative" });
                }
                if !__a.iter().chain(__b.iter()).all(|__v| #p::Scalar::re(*__v).is_finite()) {
                    return #p::Err(#p::ModelError::NonFinite { what: "the rhs's Jacobian" });
                }
                #p::Ok(())
            },
        ]);
        quote! {
            fn rhs_jacobian<__T: #p::Scalar>(&self, t: __T, __state: &[__T], __inputs: &[__T], __dstate: &mut [__T], __a: &mut [__T], __b: &mut [__T]) -> #p::Result<(), #p::ModelError> {
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
        }
    }
}
