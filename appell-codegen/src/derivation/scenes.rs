//! Scenes: a derived model with some effects' loads only, and its own
//! outputs.
//!
//! A scene reuses the full derivation's stages 1 to 9 (kinematics, the
//! elimination, M and f's inertial terms) and derives again only what its
//! effects change: f from the inertial terms and its effects' load terms
//! (stage 10), the potential and input power (stage 11), and the reduced
//! state, which its quadrature outputs may extend (stage 12).

use appell_symbolic::{Id, SymbolicError};

use super::energies::Energies;
use super::loads::Equations;
use super::reduction::{reduce_state, ReductionInputs};
use super::{text, Derivation};
use crate::algebra::expanded;
use crate::ctxt::Ctxt;
use crate::model::{Model, Scene};

/// Derives `scene` of `full`; errors go to `cx`, spanned by the scene's
/// name.
pub fn derive_scene(
    cx: &Ctxt,
    model: &mut Model,
    full: &Derivation,
    scene: &Scene,
) -> Option<Derivation> {
    match scene_derivation(model, full, scene) {
        Ok(d) => Some(d),
        Err(e) => {
            cx.error_spanned_by(
                &scene.name,
                format!("deriving scene `{}` failed: {e}", scene.name),
            );
            None
        }
    }
}

fn scene_derivation(
    model: &mut Model,
    full: &Derivation,
    scene: &Scene,
) -> Result<Derivation, SymbolicError> {
    let g = &mut model.g;
    let l = full.l;
    let mut mass = full.unreduced.mass.clone();
    let mut forcing = Vec::with_capacity(l);
    for k in 0..l {
        let mut terms = full.equations.inertial_terms[k].clone();
        for (effect, per_k) in &full.equations.load_terms {
            if scene.effects.contains(effect) {
                terms.push(per_k[k]);
            }
        }
        let sum = g.sum(&terms)?;
        forcing.push(expanded(g, sum)?);
    }
    let mut elimination = full.unreduced.elimination.clone();
    let potential = if scene.effects.iter().any(|e| e == "gravity") {
        full.energies.potential
    } else {
        g.int(0)?
    };
    let scene_power: Vec<Id> = full
        .energies
        .power_terms
        .iter()
        .filter(|(e, _)| scene.effects.contains(e))
        .map(|(_, p)| *p)
        .collect();
    let input_power = g.sum(&scene_power)?;
    let input_power = expanded(g, input_power)?;
    let reduction = reduce_state(
        g,
        ReductionInputs {
            coords: &model.coords,
            quadrature: &scene.quadrature,
            qdot: &full.map.qdot,
            dependent: &full.speeds.dependent,
        },
        &mut mass,
        &mut forcing,
        &mut elimination,
    )?;
    let mut d = Derivation {
        n: full.n,
        m: full.m,
        l,
        constraints: full.constraints.clone(),
        velocity_residuals: full.velocity_residuals.clone(),
        speeds: full.speeds.clone(),
        map: full.map.clone(),
        elimination,
        equations: Equations {
            mass,
            forcing,
            inertial_terms: full.equations.inertial_terms.clone(),
            load_terms: Vec::new(),
        },
        structured: Err("a scene uses the closed form".into()),
        projection: None,
        closed_form: full.closed_form,
        energies: Energies {
            kinetic: full.energies.kinetic,
            potential,
            input_power,
            power_terms: Vec::new(),
        },
        reduction,
        unreduced: full.unreduced.clone(),
        folded: full.folded.clone(),
        text: String::new(),
    };
    d.text = text::equations_text(model, &d);
    Ok(d)
}

#[cfg(test)]
mod tests {
    use super::super::derive;
    use super::super::testing::{self, assert_agrees};
    use super::*;

    #[test]
    fn a_scene_keeps_its_effects_loads_only() {
        // Gravity does no work along the line: without the push, f = 0.
        let src = testing::DISC_ON_A_LINE
            .replace(
                "#[appell(rolls(disc, contact = P))]",
                "#[appell(rolls(disc, contact = P), gravity(-g * N.y))]\n#[appell(scene(falling, effects(gravity)))]",
            )
            .replace("j: f64 }", "j: f64, g: f64 }");
        let cx = Ctxt::new();
        let derived = derive(&cx, testing::kinematics(&src)).expect("derivation");
        cx.check().expect("no errors");
        let (full, (scene_of, scene)) = (&derived.full, &derived.scenes[0]);
        assert_eq!(scene_of.name, "falling");
        let mut g = derived.model.g.clone();
        assert_agrees(&mut g, full.equations.forcing[0], "-r*f");
        assert_agrees(&mut g, scene.equations.forcing[0], "0");
        assert!(g.is_zero(scene.energies.input_power));
        assert_eq!(scene.equations.mass, full.equations.mass);
    }
}
