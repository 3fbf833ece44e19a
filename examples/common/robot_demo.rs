//! The command line's default action for the robot examples: the model's
//! size, then 2 s of motion under gravity alone from a bent pose.

use std::error::Error;

use appell::Model;

/// What the model is, then 2 s of RK4 (h = 0.1 ms) from every joint at
/// 0.3 rad at rest with no torque, and the energy drift over them.
pub fn demonstrate<M: Model>(model: &M) -> Result<(), Box<dyn Error>> {
    let info = M::info();
    println!(
        "{}: coordinates {:?}; the reduced state keeps {} of them and {} speeds; inputs {:?}; {} operations per rhs call",
        info.name,
        info.coordinates,
        info.retained.len(),
        info.speeds.len(),
        info.inputs,
        info.rhs_ops.total
    );
    let prepared = model.prepare::<f64>();
    let len = info.state_len();
    let mut state: Vec<f64> = (0..len)
        .map(|k| if k < info.retained.len() { 0.3 } else { 0.0 })
        .collect();
    let inputs = vec![0.0; info.inputs.len()];
    let energy = |state: &[f64]| -> Result<f64, appell::ModelError> {
        // Coordinates left out of the state do not change the energy.
        let q: Vec<f64> = info
            .coordinates
            .iter()
            .map(|c| {
                info.retained
                    .iter()
                    .position(|r| r == c)
                    .map_or(0.0, |k| state[k])
            })
            .collect();
        let e = appell::energy::energies(model, 0.0, &q, &state[info.retained.len()..], &inputs)?;
        Ok(e.kinetic + e.potential)
    };
    let e0 = energy(&state)?;
    let h = 1e-4;
    let (mut k1, mut k2, mut k3, mut k4) = (
        vec![0.0; len],
        vec![0.0; len],
        vec![0.0; len],
        vec![0.0; len],
    );
    let start = std::time::Instant::now();
    for step in 0..20_000 {
        let t = step as f64 * h;
        model.rhs(&prepared, t, &state, &inputs, &mut k1)?;
        model.rhs(
            &prepared,
            t + 0.5 * h,
            &ahead(&state, 0.5 * h, &k1),
            &inputs,
            &mut k2,
        )?;
        model.rhs(
            &prepared,
            t + 0.5 * h,
            &ahead(&state, 0.5 * h, &k2),
            &inputs,
            &mut k3,
        )?;
        model.rhs(&prepared, t + h, &ahead(&state, h, &k3), &inputs, &mut k4)?;
        for i in 0..len {
            state[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
    }
    let elapsed = start.elapsed().as_secs_f64();
    println!(
        "2 s of RK4 (h = 0.1 ms, 80,000 rhs calls) from 0.3 rad at rest, no torque: {:.1} ms; energy {e0:.6} J, drift {:.2e} J",
        elapsed * 1e3,
        energy(&state)? - e0
    );
    Ok(())
}

/// x + c d.
fn ahead(x: &[f64], c: f64, d: &[f64]) -> Vec<f64> {
    x.iter().zip(d).map(|(x, d)| x + c * d).collect()
}
