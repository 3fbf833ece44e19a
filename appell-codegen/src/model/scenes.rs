//! Scenes: a name, the effects whose loads the scene keeps, and the
//! outputs it asks for (`quadrature(coordinates...)`, `energies`,
//! `contact_forces`), each checked against the model.

use super::builder::{hint, not_raw, Builder};
use super::{Scene, SpeedSpec};
use crate::ast::*;

impl Builder<'_> {
    /// The declared scenes that check out; the others are reported.
    pub(super) fn scenes(
        &mut self,
        ast: &ModelAst,
        effects: &[String],
        constraint_effects: &[String],
        model_speeds: &[SpeedSpec],
        contacts: &[super::Contact],
    ) -> Vec<Scene> {
        let cx = self.cx;
        let mut scenes = Vec::new();
        for sc in &ast.scenes {
            let mut ok = self.scene_effects(sc, effects);
            let (quadrature, outputs) = self.scene_outputs(ast, sc, &mut ok);
            if scenes.iter().any(|s: &Scene| s.name == sc.name) {
                cx.error_spanned_by(&sc.name, format!("duplicate scene `{}`", sc.name));
                ok = false;
            }
            if !not_raw(cx, &sc.name, "scene") {
                ok = false;
            }
            ok &= self.keeps_constraints(sc, constraint_effects);
            let speeds = match &sc.speeds {
                Some((list, at)) => match self.scene_speeds(list, model_speeds) {
                    Some(specs) => Some((specs, at.clone())),
                    None => {
                        ok = false;
                        None
                    }
                },
                None => self.contact_speeds(ast, sc, contacts, model_speeds, &mut ok),
            };
            if ok {
                scenes.push(Scene {
                    name: sc.name.clone(),
                    effects: sc.effects.iter().map(|e| e.to_string()).collect(),
                    quadrature,
                    outputs,
                    speeds,
                });
            }
        }
        scenes
    }

    /// Whether every effect the scene names is a load's; an error for each
    /// that is not.
    fn scene_effects(&self, sc: &SceneDef, effects: &[String]) -> bool {
        let mut ok = true;
        for e in &sc.effects {
            if !effects.contains(&e.to_string()) {
                let h = hint(&e.to_string(), effects.iter().cloned());
                self.cx.error_spanned_by(
                    e,
                    format!(
                        "scene `{}` names the effect `{e}`, which no load declares{h}",
                        sc.name
                    ),
                );
                ok = false;
            }
        }
        ok
    }

    /// The scene's quadrature coordinates (indices) and its outputs' names;
    /// `ok` turns false at an output that does not check out.
    fn scene_outputs(
        &self,
        ast: &ModelAst,
        sc: &SceneDef,
        ok: &mut bool,
    ) -> (Vec<usize>, Vec<String>) {
        let cx = self.cx;
        let mut quadrature = Vec::new();
        let mut outputs: Vec<String> = Vec::new();
        for (kind, args) in &sc.outputs {
            let k = kind.to_string();
            if outputs.contains(&k) {
                cx.error_spanned_by(kind, format!("scene output `{k}` is listed twice"));
                *ok = false;
                continue;
            }
            outputs.push(k.clone());
            if k == "energies" || k == "contact_forces" {
                if let Some(a) = args.first() {
                    cx.error_spanned_by(a, format!("`{k}` takes no arguments"));
                    *ok = false;
                }
                if k == "contact_forces"
                    && ast.holonomic.is_empty()
                    && ast.nonholonomic.is_empty()
                    && ast.rolls.is_empty()
                    && ast.contacts.is_empty()
                {
                    cx.error_spanned_by(
                        kind,
                        "`contact_forces` needs constraints (`rolls`, `holonomic` or `nonholonomic`), and the model has none",
                    );
                    *ok = false;
                }
            } else if k == "quadrature" {
                *ok &= self.quadrature(kind, args, &mut quadrature);
            } else {
                let h = hint(
                    &k,
                    ["quadrature", "energies", "contact_forces"].map(String::from),
                );
                cx.error_spanned_by(
                    kind,
                    format!("unknown scene output `{kind}`; available: quadrature(coordinates...), energies, contact_forces{h}"),
                );
                *ok = false;
            }
        }
        (quadrature, outputs)
    }

    /// `quadrature(...)`'s coordinates, pushed on `quadrature` by index;
    /// whether every argument is one.
    fn quadrature(
        &self,
        kind: &syn::Ident,
        args: &[syn::Ident],
        quadrature: &mut Vec<usize>,
    ) -> bool {
        let cx = self.cx;
        let mut ok = true;
        if args.is_empty() {
            cx.error_spanned_by(kind, "`quadrature(...)` needs the coordinates to keep");
            ok = false;
        }
        for a in args {
            match self.coords.iter().position(|(c, _)| c == a) {
                Some(i) => quadrature.push(i),
                None => {
                    let h = hint(
                        &a.to_string(),
                        self.coords.iter().map(|(c, _)| c.to_string()),
                    );
                    cx.error_spanned_by(
                        a,
                        format!("`quadrature` takes coordinates, and `{a}` is not one{h}"),
                    );
                    ok = false;
                }
            }
        }
        ok
    }

    /// Whether a scene that leaves out constraint effects names its own
    /// speeds; an error where it does not.
    fn keeps_constraints(&self, sc: &SceneDef, constraint_effects: &[String]) -> bool {
        let left_out: Vec<&String> = constraint_effects
            .iter()
            .filter(|e| !sc.effects.iter().any(|s| s == *e))
            .collect();
        if left_out.is_empty() || sc.speeds.is_some() {
            return true;
        }
        let names: Vec<String> = left_out.iter().map(|e| format!("`{e}`")).collect();
        self.cx.error_spanned_by(
            &sc.name,
            format!(
                "scene `{}` leaves out the constraints of {}, so it moves with more degrees of freedom than the model: name all its privileged speeds with `speeds(...)` in the scene (or name the effect in `effects(...)` to keep the constraints)",
                sc.name,
                names.join(", ")
            ),
        );
        false
    }

    /// The speeds of a scene that names no speeds: the model's, less the
    /// joints its contacts make dependent (None when it holds none).
    fn contact_speeds(
        &self,
        ast: &ModelAst,
        sc: &SceneDef,
        contacts: &[super::Contact],
        model_speeds: &[SpeedSpec],
        ok: &mut bool,
    ) -> Option<(Vec<SpeedSpec>, proc_macro2::TokenStream)> {
        let held: Vec<&super::Contact> = contacts
            .iter()
            .filter(|c| sc.effects.iter().any(|e| *e == c.effect))
            .collect();
        if held.is_empty() {
            return None;
        }
        let rates: Vec<(String, appell_symbolic::Symbol)> = self
            .coords
            .iter()
            .map(|(c, coord)| (c.to_string(), coord.rate))
            .collect();
        // The rank probe differentiates in a copy of the graph, so that the
        // model's node order (and every expansion) is as without it.
        let mut scratch = self.g.clone();
        match super::contacts::scene_speeds(&mut scratch, ast, &rates, &held, model_speeds) {
            Ok(speeds) => {
                let name = &sc.name;
                Some((speeds, quote::quote!(#name)))
            }
            Err(message) => {
                self.cx
                    .error_spanned_by(&sc.name, format!("scene `{}`: {message}", sc.name));
                *ok = false;
                None
            }
        }
    }

    /// A scene's `speeds(...)`: each a coordinate (its rate) or one of the
    /// model's quasi-velocities, once; None after reporting an error.
    fn scene_speeds(
        &self,
        list: &[syn::Ident],
        model_speeds: &[SpeedSpec],
    ) -> Option<Vec<SpeedSpec>> {
        let mut out: Vec<SpeedSpec> = Vec::new();
        let mut ok = true;
        for name in list {
            let text = name.to_string();
            if out.iter().any(|s| s.name == text) {
                self.cx
                    .error_spanned_by(name, format!("duplicate speed `{text}`"));
                ok = false;
                continue;
            }
            if let Some(spec) = model_speeds.iter().find(|s| s.name == text) {
                out.push(spec.clone());
                continue;
            }
            match self.coords.iter().position(|(c, _)| *c == *name) {
                Some(i) => {
                    let c = self.coords[i].1;
                    out.push(SpeedSpec {
                        name: text,
                        symbol: c.rate,
                        accel: c.accel,
                        coordinate: Some(i),
                        definition: None,
                    });
                }
                None => {
                    let h = hint(&text, self.coords.iter().map(|(c, _)| c.to_string()));
                    self.cx.error_spanned_by(
                        name,
                        format!("`{text}` is not a coordinate; a scene's speeds are coordinates or the model's quasi-velocities{h}"),
                    );
                    ok = false;
                }
            }
        }
        ok.then_some(out)
    }
}
