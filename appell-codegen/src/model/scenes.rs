//! Scenes: a name, the effects whose loads the scene keeps, and the
//! outputs it asks for (`quadrature(coordinates...)`, `energies`,
//! `contact_forces`), each checked against the model.

use super::builder::{hint, not_raw, Builder};
use super::Scene;
use crate::ast::*;

impl Builder<'_> {
    /// The declared scenes that check out; the others are reported.
    pub(super) fn scenes(&mut self, ast: &ModelAst, effects: &[String]) -> Vec<Scene> {
        let cx = self.cx;
        let mut scenes = Vec::new();
        for sc in &ast.scenes {
            let mut ok = true;
            for e in &sc.effects {
                if !effects.contains(&e.to_string()) {
                    let h = hint(&e.to_string(), effects.iter().cloned());
                    cx.error_spanned_by(
                        e,
                        format!(
                            "scene `{}` names the effect `{e}`, which no load declares{h}",
                            sc.name
                        ),
                    );
                    ok = false;
                }
            }
            let mut quadrature = Vec::new();
            let mut outputs: Vec<String> = Vec::new();
            for (kind, args) in &sc.outputs {
                let k = kind.to_string();
                if outputs.contains(&k) {
                    cx.error_spanned_by(kind, format!("scene output `{k}` is listed twice"));
                    ok = false;
                    continue;
                }
                outputs.push(k.clone());
                if k == "energies" || k == "contact_forces" {
                    if let Some(a) = args.first() {
                        cx.error_spanned_by(a, format!("`{k}` takes no arguments"));
                        ok = false;
                    }
                    if k == "contact_forces"
                        && ast.holonomic.is_empty()
                        && ast.nonholonomic.is_empty()
                        && ast.rolls.is_empty()
                    {
                        cx.error_spanned_by(
                            kind,
                            "`contact_forces` needs constraints (`rolls`, `holonomic` or `nonholonomic`), and the model has none",
                        );
                        ok = false;
                    }
                } else if k == "quadrature" {
                    if args.is_empty() {
                        cx.error_spanned_by(
                            kind,
                            "`quadrature(...)` needs the coordinates to keep",
                        );
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
                                    format!(
                                        "`quadrature` takes coordinates, and `{a}` is not one{h}"
                                    ),
                                );
                                ok = false;
                            }
                        }
                    }
                } else {
                    let h = hint(
                        &k,
                        ["quadrature", "energies", "contact_forces"].map(String::from),
                    );
                    cx.error_spanned_by(
                        kind,
                        format!("unknown scene output `{kind}`; available: quadrature(coordinates...), energies, contact_forces{h}"),
                    );
                    ok = false;
                }
            }
            if scenes.iter().any(|s: &Scene| s.name == sc.name) {
                cx.error_spanned_by(&sc.name, format!("duplicate scene `{}`", sc.name));
                ok = false;
            }
            if !not_raw(cx, &sc.name, "scene") {
                ok = false;
            }
            if ok {
                scenes.push(Scene {
                    name: sc.name.clone(),
                    effects: sc.effects.iter().map(|e| e.to_string()).collect(),
                    quadrature,
                    outputs,
                });
            }
        }
        scenes
    }
}
