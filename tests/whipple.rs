//! The Whipple bicycle benchmark.

#[path = "../examples/models/whipple_bicycle.rs"]
mod whipple_bicycle;

use appell::Model;
use whipple_bicycle::WhippleBicycle;

#[test]
fn derives() {
    let info = WhippleBicycle::info();
    println!("{}", &info.equations[..info.equations.len().min(3000)]);
    println!("ops {:?}", info.rhs_ops);
}
