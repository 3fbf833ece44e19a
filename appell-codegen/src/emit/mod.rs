//! The `Model` implementation, built with `quote!`.
//!
//! Every numeric function is one straight-line program lowered by the engine
//! (shared subexpressions bound once; `code.rs`), generic over the scalar
//! `__T`. The reduced rhs (`rhs.rs`) reads parameter-only values from
//! `Prepared`, computed once per parameter set, solves the numeric part of
//! the elimination (`solve.rs`) and Appell's equations by an unrolled LDLᵀ
//! factorization (`ldlt.rs`). `info.rs` writes the `ModelInfo` metadata and
//! `functions.rs` the other trait methods. Paths go through
//! `::appell::__private`; everything is wrapped in `const _: () = { ... };`,
//! beside the scene newtypes (`scenes.rs`). On errors, [`stub`] stands in.

mod build_hint;
mod code;
mod contacts;
mod controller;
mod functions;
mod info;
mod jacobian;
mod ldlt;
mod rhs;
mod scenes;
mod solve;
mod stub;

use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};

use crate::derivation::{Derivation, Derived};
use crate::model::{Load, Model, Scene};
use scenes::{info_static, newtype, scene_dispatch};

pub use build_hint::{unoptimised_hint, DeriveBuild, SLOW_EXPANSION_SECONDS};
pub use stub::stub;

/// The runtime's items, as the generated code reaches them.
fn p() -> TokenStream {
    quote!(::appell::__private)
}

/// An integer literal without a suffix (`3`, not `3usize`).
fn int(i: usize) -> Literal {
    Literal::usize_unsuffixed(i)
}

/// One `Model` implementation: the full model's or a scene's.
struct Emitter<'a> {
    /// The model; its graph holds every expression.
    model: &'a Model,
    /// The equations: the full model's or the scene's.
    d: &'a Derivation,
    /// The scene, for a scene's implementation.
    scene: Option<&'a Scene>,
    /// The type the implementation is for.
    type_name: syn::Ident,
    /// How the parameters are reached (`self`, or `self.0` for a scene).
    this: TokenStream,
    /// The name of the `ModelInfo` static.
    info_ident: syn::Ident,
    /// The scene infos the full model lists (`&[]` for a scene).
    scene_infos: TokenStream,
    /// The full model's `scene_rhs` and `visit_scene` (empty for a scene).
    scene_rhs: TokenStream,
}

impl Emitter<'_> {
    /// Whether this implementation keeps the loads of `effect`: a scene
    /// keeps its effects' only.
    fn keeps(&self, effect: &str) -> bool {
        self.scene
            .is_none_or(|s| s.effects.iter().any(|e| e == effect))
    }

    /// The forces this implementation describes.
    fn forces(&self) -> Vec<&Load> {
        self.model
            .forces
            .iter()
            .filter(|f| self.keeps(&f.effect))
            .collect()
    }

    /// The torques this implementation describes.
    fn torques(&self) -> Vec<&Load> {
        self.model
            .torques
            .iter()
            .filter(|t| self.keeps(&t.effect))
            .collect()
    }

    /// The effects whose loads it keeps, in the model's order.
    fn effects(&self) -> Vec<String> {
        self.model
            .effects
            .iter()
            .filter(|e| self.keeps(e))
            .cloned()
            .collect()
    }

    /// The inputs this implementation takes: the model's, or for a scene
    /// those its kept loads read (a scene of loads without inputs takes
    /// none).
    fn inputs(&self) -> Vec<&(syn::Ident, appell_symbolic::Symbol)> {
        let g = &self.model.g;
        let loads: Vec<&Load> = self.forces().into_iter().chain(self.torques()).collect();
        self.model
            .inputs
            .iter()
            .filter(|(_, s)| {
                self.scene.is_none()
                    || self.model.input_rates.iter().any(|(a, b)| a == s || b == s)
                    || loads
                        .iter()
                        .any(|l| l.vector.iter().any(|&e| g.depends_on(e, *s)))
            })
            .collect()
    }

    /// The scene's outputs (none for the full model).
    fn outputs(&self) -> Vec<String> {
        self.scene.map_or_else(Vec::new, |s| s.outputs.clone())
    }

    /// The name its `ModelInfo` carries: `Model` or `Model::scene`.
    fn info_name(&self) -> String {
        match self.scene {
            Some(s) => format!("{}::{}", self.model.name, s.name),
            None => self.model.name.to_string(),
        }
    }

    fn coord(&self, i: usize) -> syn::Ident {
        self.model.coords[i].0.clone()
    }

    fn ident(&self, name: &str) -> syn::Ident {
        syn::Ident::new(name, proc_macro2::Span::call_site())
    }

    /// The parameters bound as locals: as `__T` when `scalar`, else `f64`.
    fn params_as(&self, scalar: bool) -> TokenStream {
        let (p, this) = (p(), &self.this);
        let locals = self.model.params.iter().map(|prm| &prm.ident);
        let places = self.model.params.iter().map(|prm| prm.place());
        if scalar {
            quote!(#(let #locals: __T = <__T as #p::Scalar>::from_f64(#this.#places);)*)
        } else {
            quote!(#(let #locals: f64 = #this.#places;)*)
        }
    }

    /// An early `NonPositiveParameter` for each parameter declared
    /// `positive`.
    fn positivity(&self) -> TokenStream {
        let (p, this) = (p(), &self.this);
        let checks = self.model.params.iter().filter(|prm| prm.positive).map(|prm| {
            let (f, name) = (prm.place(), prm.display());
            quote!(if !(#this.#f > 0.0) { return #p::Err(#p::ModelError::NonPositiveParameter { name: #name, value: #this.#f }); })
        });
        quote!(#(#checks)*)
    }

    /// `let q_i = slice[i];` for every coordinate.
    fn bind_q(&self, slice: &str) -> TokenStream {
        let slice = self.ident(slice);
        let binds = (0..self.d.n).map(|i| {
            let (q, i) = (self.coord(i), int(i));
            quote!(let #q = #slice[#i];)
        });
        quote!(#(#binds)*)
    }

    /// `let q_i_dot = slice[i];` for every coordinate.
    fn bind_qdot(&self, slice: &str) -> TokenStream {
        let slice = self.ident(slice);
        let binds = (0..self.d.n).map(|i| {
            let (q, i) = (format_ident!("{}_dot", self.coord(i)), int(i));
            quote!(let #q = #slice[#i];)
        });
        quote!(#(#binds)*)
    }

    /// The privileged speeds this implementation's derivation has (a
    /// scene's own, where it names them).
    fn speeds(&self) -> &[crate::model::SpeedSpec] {
        &self.d.constraint_set.speed_specs
    }

    /// `let u_k = slice[k];` for every privileged speed.
    fn bind_u(&self, slice: &str) -> TokenStream {
        self.bind_speeds(slice, |spec| spec.symbol)
    }

    /// `let a_k = slice[k];` for every privileged speed's acceleration.
    fn bind_accel(&self, slice: &str) -> TokenStream {
        self.bind_speeds(slice, |spec| spec.accel)
    }

    /// `let s_k = slice[k];` for the symbol `of` each privileged speed.
    fn bind_speeds(
        &self,
        slice: &str,
        of: impl Fn(&crate::model::SpeedSpec) -> appell_symbolic::Symbol,
    ) -> TokenStream {
        let slice = self.ident(slice);
        let g = &self.model.g;
        let binds = self.speeds().iter().enumerate().map(|(k, spec)| {
            let (s, k) = (self.ident(g.symbol_name(of(spec))), int(k));
            quote!(let #s = #slice[#k];)
        });
        quote!(#(#binds)*)
    }

    /// `let q = __state[k];` for every retained coordinate, then `let u =
    /// __state[k];` for every privileged speed: the reduced state bound.
    fn bind_state(&self) -> TokenStream {
        let retained = &self.d.reduction.retained;
        let g = &self.model.g;
        let state_q = retained.iter().enumerate().map(|(k, &r)| {
            let (q, k) = (self.coord(r), int(k));
            quote!(let #q = __state[#k];)
        });
        let state_u = self.speeds().iter().enumerate().map(|(k, spec)| {
            let (u, k) = (
                self.ident(g.symbol_name(spec.symbol)),
                int(retained.len() + k),
            );
            quote!(let #u = __state[#k];)
        });
        quote!(#(#state_q)* #(#state_u)*)
    }

    /// `let input_k = slice[k];` for every input.
    fn bind_inputs(&self, slice: &str) -> TokenStream {
        let slice = self.ident(slice);
        let binds = self.inputs().into_iter().enumerate().map(|(k, (name, _))| {
            let k = int(k);
            quote!(let #name = #slice[#k];)
        });
        quote!(#(#binds)*)
    }

    /// `check_len(name, arg, len)?;`: a slice argument of the wrong length
    /// is a typed error naming it as the trait does (`inputs`, not
    /// `__inputs`).
    fn check(&self, arg: &str, len: usize) -> TokenStream {
        let p = p();
        let (ident, len) = (self.ident(arg), int(len));
        // The error names the argument as the `Model` trait does.
        let name = arg.trim_start_matches("__");
        quote!(#p::check_len(#name, #ident, #len)?;)
    }
}

/// `track_check` → `TrackCheck`.
fn camel(s: &str) -> String {
    s.split('_')
        .filter(|p| !p.is_empty())
        .map(|p| {
            let mut c = p.chars();
            match c.next() {
                Some(f) => f.to_uppercase().collect::<String>() + c.as_str(),
                None => String::new(),
            }
        })
        .collect()
}

/// The `Model` implementations: the full model's, and one per scene on a
/// generated newtype (`{Model}{Scene}(pub Model)`), all in one `const _`
/// block; the scene types are declared beside the struct.
pub fn emit(derived: &Derived, vis: &syn::Visibility) -> TokenStream {
    let p = p();
    let mut body = full_implementation(derived);
    let mut decls = TokenStream::new();
    for k in 0..derived.scenes.len() {
        let (decl, implementation) = scene_implementation(derived, k, vis);
        decls.extend(decl);
        body.extend(implementation);
    }
    quote! {
        #decls
        const _: () = {
            #[allow(unused_imports)]
            use #p::Scalar as _;
            #body
        };
    }
}

/// The type of scene `name` of `base`: `{Base}{Name}`.
fn scene_type(base: &syn::Ident, name: &syn::Ident) -> syn::Ident {
    format_ident!("{}{}", base, camel(&name.to_string()))
}

/// The full model's implementation, the scene infos' static and the
/// files it includes.
fn full_implementation(derived: &Derived) -> TokenStream {
    let p = p();
    let (model, full, scenes) = (&derived.model, &derived.full, &derived.scenes);
    let base = &model.name;
    let scene_type = |name: &syn::Ident| scene_type(base, name);
    let scene_infos = scenes.iter().map(|(s, _)| info_static(&s.name));
    let count = int(scenes.len());
    let mut body = quote! {
        static __SCENES: [&#p::ModelInfo; #count] = [#(&#scene_infos),*];
    };
    body.extend(
        Emitter {
            model,
            d: full,
            scene: None,
            type_name: base.clone(),
            this: quote!(self),
            info_ident: format_ident!("__INFO"),
            scene_infos: quote!(&__SCENES),
            scene_rhs: scene_dispatch(scenes, &scene_type),
        }
        .implementation(),
    );
    // The files the model was read from: cargo tracks what a crate
    // includes, so a changed URDF builds the model again.
    let files = &model.files;
    body.extend(quote!(#(const _: &[u8] = ::core::include_bytes!(#files);)*));
    body
}

/// Scene `k`'s newtype declaration and its implementation.
fn scene_implementation(
    derived: &Derived,
    k: usize,
    vis: &syn::Visibility,
) -> (TokenStream, TokenStream) {
    let model = &derived.model;
    let (scene, d) = &derived.scenes[k];
    let (base, name) = (&model.name, &scene.name);
    let emitter = Emitter {
        model,
        d,
        scene: Some(scene),
        type_name: scene_type(base, name),
        this: quote!(self.0),
        info_ident: info_static(name),
        scene_infos: quote!(&[]),
        scene_rhs: TokenStream::new(),
    };
    let decl = newtype(base, &emitter.type_name, name, &emitter.effects(), vis);
    (decl, emitter.implementation())
}
