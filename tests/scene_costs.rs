//! A scene costs what a model declared with only its effects costs: the
//! scene's op count against the op count of the same model file with the
//! other effects' loads deleted, expanded by the derive (`appell_codegen`).

#[path = "../examples/models/wheel_axle.rs"]
mod wheel_axle;
#[path = "../examples/models/whipple_bicycle.rs"]
#[allow(dead_code)]
mod whipple_bicycle;

use appell::Model;

/// The rhs op count of the struct `name` in `source` after deleting every
/// line that contains one of `drop` (the left-out effects' loads and inputs,
/// and the scene declarations), as the derive expands it.
fn declared_ops(source: &str, name: &str, drop: &[&str]) -> usize {
    let kept: Vec<&str> = source
        .lines()
        .filter(|l| !drop.iter().any(|d| l.contains(d)))
        .collect();
    let source = kept.join("\n");
    let at = source
        .find(&format!("pub struct {name} {{"))
        .expect("struct");
    let start = source[..at].rfind("#[derive(Appell").expect("derive");
    let end = at + source[at..].find("\n}").expect("end of struct") + 2;
    let input: syn::DeriveInput = syn::parse_str(&source[start..end]).expect("struct");
    let out = appell_codegen::expand(&input).to_string();
    assert!(!out.contains("compile_error"), "the reduced model derives");
    let info = &out[out.find("rhs_ops").expect("info")..];
    let total = &info[info.find("total :").expect("total") + "total :".len()..];
    total
        .trim_start()
        .split(|c: char| !c.is_ascii_digit())
        .next()
        .unwrap()
        .parse()
        .unwrap()
}

fn within_five_percent(label: &str, scene: usize, declared: usize) {
    println!("{label}: scene {scene} ops, declared alone {declared} ops");
    let diff = scene.abs_diff(declared) as f64;
    assert!(
        diff <= 0.05 * declared as f64,
        "{label}: scene {scene} ops against {declared} for the model declared with its effects only"
    );
}

#[test]
fn wheel_axle_scenes_cost_what_their_effects_cost() {
    let source = include_str!("../examples/models/wheel_axle.rs");
    let scenes = ["scene(", "clippy::duplicated_attributes"];
    // coasting: gravity only (the drive torque and its input deleted).
    let mut drop = vec!["torque(W1"];
    drop.extend(scenes);
    let declared = declared_ops(source, "WheelAxle", &drop);
    within_five_percent(
        "wheel-axle coasting",
        wheel_axle::WheelAxleCoasting::info().rhs_ops.total,
        declared,
    );
    // driven: the motor only (the gravity forces deleted).
    let mut drop = vec!["force(C", "mass * g * sin(alpha)"];
    drop.extend(scenes);
    let declared = declared_ops(source, "WheelAxle", &drop);
    within_five_percent(
        "wheel-axle driven",
        wheel_axle::WheelAxleDriven::info().rhs_ops.total,
        declared,
    );
}

#[test]
fn bicycle_coasting_costs_what_gravity_alone_costs() {
    let source = include_str!("../examples/models/whipple_bicycle.rs");
    let drop = [
        "inputs(steer_torque)",
        "effect = rider",
        "scene(",
        "clippy::duplicated_attributes",
    ];
    let declared = declared_ops(source, "WhippleBicycle", &drop);
    within_five_percent(
        "bicycle coasting",
        whipple_bicycle::WhippleBicycleCoasting::info()
            .rhs_ops
            .total,
        declared,
    );
}
