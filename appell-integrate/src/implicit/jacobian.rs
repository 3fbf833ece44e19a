//! The Newton matrix's Jacobian of a model's reduced rhs, for both implicit
//! integrators.

use appell_core::dynamic::DynRhs;
use appell_core::ModelError;
use num_dual::Dual64;

/// The Jacobian `∂f/∂x` of `rhs` (row-major n×n into its last argument)
/// at `(t, x)` with `inputs` held constant: the model's generated
/// [`Model::rhs_jacobian`](appell_core::Model::rhs_jacobian) where it has one and `by_duals` is false, else
/// exactly by forward-mode dual numbers, one [`DynRhs::rhs_dual`] per state
/// component. What the implicit integrators use for a model.
pub(crate) fn dual_jacobian<'a, R: DynRhs + ?Sized>(
    rhs: &'a R,
    inputs: &[f64],
    by_duals: bool,
) -> impl FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError> + 'a {
    let n = rhs.state_len();
    let inputs_d: Vec<Dual64> = inputs.iter().map(|&v| Dual64::from_re(v)).collect();
    let mut xd = vec![Dual64::from_re(0.0); n];
    let mut outd = vec![Dual64::from_re(0.0); n];
    // The generated Jacobian's other outputs, allocated once.
    let real_inputs = inputs.to_vec();
    let (mut values, mut b) = (vec![0.0; n], vec![0.0; n * inputs.len()]);
    move |t: f64, x: &[f64], j: &mut [f64]| {
        if !by_duals && rhs.generated_jacobian(t, x, &real_inputs, &mut values, j, &mut b)? {
            return Ok(());
        }
        let td = Dual64::from_re(t);
        for (d, &v) in xd.iter_mut().zip(x) {
            *d = Dual64::from_re(v);
        }
        for col in 0..n {
            xd[col].eps = 1.0;
            let r = rhs.rhs_dual(td, &xd, &inputs_d, &mut outd);
            xd[col].eps = 0.0;
            r?;
            for (row, o) in outd.iter().enumerate() {
                j[row * n + col] = o.eps;
            }
        }
        Ok(())
    }
}
