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
use super::{complete, text, Derivation, Options};
use crate::algebra::expanded;
use crate::ctxt::Ctxt;
use crate::model::{ConstraintSet, Model, Scene, Twin};

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
        constraint_set: full.constraint_set.clone(),
        own_constraints: full.own_constraints,
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
        jacobians: None,
    };
    d.text = text::equations_text(model, &d);
    d.jacobians = Some(super::jacobian::differentiate(model, &d));
    Ok(d)
}

/// Derives `scene`, which leaves some of the model's constraints out or
/// names its own speeds: stages 1 to 13 again with its constraints and
/// speeds ([`ConstraintSet::of_scene`]) instead of the model's (and the
/// twin's constraints likewise), then its effects' loads as for any scene.
pub fn derive_constrained_scene(
    cx: &Ctxt,
    model: &mut Model,
    twin: Option<&Twin>,
    scene: &Scene,
    options: &Options,
) -> Option<Derivation> {
    let own = ConstraintSet::of_scene(model, scene)?;
    let twin = twin.map(|t| own.twin(t, scene));
    // The scene's own errors, each named with the scene (and not mistaken
    // for an earlier scene's by the stages' checks).
    let scene_cx = Ctxt::new();
    let d = complete(&scene_cx, model, &own, twin, options)
        .and_then(|full| derive_scene(&scene_cx, model, &full, scene));
    match scene_cx.check() {
        Err(errors) => {
            for e in errors {
                cx.syn_error(syn::Error::new(
                    e.span(),
                    format!("scene `{}`: {e}", scene.name),
                ));
            }
        }
        Ok(()) if d.is_none() => cx.error_spanned_by(
            &scene.name,
            format!("deriving scene `{}` failed", scene.name),
        ),
        Ok(()) => {}
    }
    d.map(|mut d| {
        d.own_constraints = true;
        d
    })
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

    #[test]
    fn a_scene_without_the_rolling_contact_slides_with_its_own_speeds() {
        // Sliding, the disc's centre and its spin move independently: the
        // push accelerates the centre only, f/m, and nothing turns it.
        let src = testing::DISC_ON_A_LINE.replace(
            "#[appell(rolls(disc, contact = P))]",
            "#[appell(rolls(disc, contact = P, effect = rolling))]\n#[appell(scene(sliding, effects(push), speeds(x, phi)))]",
        );
        let cx = Ctxt::new();
        let derived = derive(&cx, testing::kinematics(&src)).expect("derivation");
        cx.check().expect("no errors");
        let (full, (_, sliding)) = (&derived.full, &derived.scenes[0]);
        assert_eq!((full.m, full.l), (1, 1));
        assert_eq!((sliding.m, sliding.l), (0, 2));
        assert!(sliding.own_constraints);
        let mut g = derived.model.g.clone();
        assert_agrees(&mut g, sliding.equations.mass[0], "m");
        assert_agrees(&mut g, sliding.equations.mass[3], "j");
        assert_agrees(&mut g, sliding.equations.forcing[0], "f");
        assert_agrees(&mut g, sliding.equations.forcing[1], "0");
        // The model is left with its own constraint and speed.
        assert_eq!(
            (
                derived.model.constraints.rolling.len(),
                derived.model.constraints.speed_specs.len()
            ),
            (1, 1)
        );
    }
}
