//! The `info` subcommand: the model's metadata as JSON.

use super::output::finite_or_null;
use appell_core::dynamic::DynModel;
use appell_core::{Model, ModelError};
use serde_json::{json, Value};

/// The metadata printed by `info` (layout in the module documentation).
///
/// ```
/// # use appell_core::{BodyInfo, Model, ModelError, ModelInfo, OpCounts, Scalar};
/// # struct Spin { i: f64 }
/// # static INFO: ModelInfo = ModelInfo {
/// #     name: "Spin", parameters: &["i"], coordinates: &["phi"], speeds: &["phi"],
/// #     dependent: &[], cyclic: &[], ignorable: &[], retained: &["phi"], inputs: &["tau"],
/// #     effects: &["motor"], outputs: &[], row_sources: &[], contacts: &[], holonomic: 0, constraints: 0,
/// #     bodies: &[BodyInfo { name: "B", rigid: true }], force_points: 0, torques: 1,
/// #     form: "closed form", symbolic_elimination: true,
/// #     rhs_ops: OpCounts { add: 0, mul: 0, div: 1, calls: 0, total: 1 },
/// #     jacobian: None,
/// #     equations: "phi'' = tau/i",
/// # };
/// # fn unused() -> Result<(), ModelError> { Err(ModelError::NonFinite { what: "unused" }) }
/// # impl Model for Spin {
/// #     type Prepared<T: Scalar> = ();
/// #     fn info() -> &'static ModelInfo { &INFO }
/// #     fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> {
/// #         appell_core::check_len("out", out, 1)?; out[0] = self.i; Ok(())
/// #     }
/// #     fn set_parameter(&mut self, _: &str, _: f64) -> bool { false }
/// #     fn prepare<T: Scalar>(&self) {}
/// #     fn rhs<T: Scalar>(&self, _: &(), _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn coordinate_rates<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn mass_matrix_and_forcing<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn speed_transform<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn constraint_residuals<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn kinetic_energy<T: Scalar>(&self, _: T, _: &[T], _: &[T]) -> Result<T, ModelError> { unused().map(|_| T::zero()) }
/// #     fn mass_properties(&self, _: &mut [f64], _: &mut [[f64; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn body_poses<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn constraint_rows<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn load_geometry<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn load_values<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [[T; 3]], _: &mut [[T; 3]]) -> Result<(), ModelError> { unused() }
/// # }
/// let info = appell_tools::cli::info_json(&Spin { i: 0.25 }).unwrap();
/// assert_eq!(info["name"], "Spin");
/// assert_eq!(info["parameters"][0]["value"], 0.25);
/// assert_eq!(info["state"], serde_json::json!(["phi", "phi_dot"]));
/// assert_eq!(info["rhs_ops"]["total"], 1);
/// assert_eq!(info["rhs_ops"]["other"], 0);
/// assert_eq!(info["jacobian"], serde_json::Value::Null);
/// ```
pub fn info_json<M: Model>(model: &M) -> Result<Value, ModelError> {
    info_json_dyn(model)
}

/// [`info_json`] of any [`DynModel`], compiled once.
pub(super) fn info_json_dyn(model: &dyn DynModel) -> Result<Value, ModelError> {
    let info = model.dyn_info();
    let mut values = vec![0.0; info.parameters.len()];
    model.dyn_parameter_values(&mut values)?;
    let parameters: Vec<Value> = info
        .parameters
        .iter()
        .zip(&values)
        .map(|(name, value)| json!({ "name": name, "value": finite_or_null(*value) }))
        .collect();
    let state: Vec<String> = info.state_names().map(|n| n.to_string()).collect();
    let bodies: Vec<Value> = info
        .bodies
        .iter()
        .map(|b| json!({ "name": b.name, "rigid": b.rigid }))
        .collect();
    let ops = info.rhs_ops;
    let scenes: Vec<Value> = model
        .dyn_scene_infos()
        .iter()
        .map(|s| {
            json!({
                "name": s.name,
                "effects": s.effects,
                "retained": s.retained,
                "state_len": s.state_len(),
                "rhs_ops": s.rhs_ops.total,
                "outputs": s.outputs,
            })
        })
        .collect();
    Ok(json!({
        "name": info.name,
        "scenes": scenes,
        "parameters": parameters,
        "coordinates": info.coordinates,
        "speeds": info.speeds,
        "dependent": info.dependent,
        "cyclic": info.cyclic,
        "ignorable": info.ignorable,
        "retained": info.retained,
        "state": state,
        "inputs": info.inputs,
        "effects": info.effects,
        "bodies": bodies,
        "holonomic": info.holonomic,
        "constraints": info.constraints,
        "contacts": info
            .contacts
            .iter()
            .map(|c| json!({
                "point": c.point,
                "body": info.bodies.get(c.body).map(|b| b.name),
                "along": c.along,
            }))
            .collect::<Vec<_>>(),
        "force_points": info.force_points,
        "torques": info.torques,
        "form": info.form,
        "symbolic_elimination": info.symbolic_elimination,
        "rhs_ops": {
            "add": ops.add,
            "mul": ops.mul,
            "div": ops.div,
            "calls": ops.calls,
            "other": ops.total.saturating_sub(ops.add + ops.mul + ops.div + ops.calls),
            "total": ops.total,
        },
        "jacobian": info.jacobian.map(|j| json!({ "form": j.form, "ops": j.ops.total })),
    }))
}
