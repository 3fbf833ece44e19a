//! The coefficients of the three-stage Radau IIA method (order 5): its
//! nodes, the eigen-decomposition of the inverse of its matrix that splits
//! the Newton system into one real and one complex system, the weights of
//! the embedded error estimate and the collocation polynomial's
//! coefficients.

/// √6.
const S6: f64 = 2.449_489_742_783_178;

/// The nodes `c`: the stages sit at `t + c_i h`.
pub(super) const C: [f64; 3] = [(4.0 - S6) / 10.0, (4.0 + S6) / 10.0, 1.0];

/// The weights of the stage increments `z_i` in the error estimate
/// `(γ/h − J)⁻¹ (f(t, x) + Σ E_i z_i / h)`.
pub(super) const E: [f64; 3] = [
    (-13.0 - 7.0 * S6) / 3.0,
    (-13.0 + 7.0 * S6) / 3.0,
    -1.0 / 3.0,
];

/// The real eigenvalue of `A⁻¹`: `3 + 3^(2/3) − 3^(1/3)`.
pub(super) const GAMMA: f64 = 3.637_834_252_744_496;

/// The complex eigenvalue `α − iβ` of `A⁻¹`: `α = 3 + (3^(1/3) − 3^(2/3))/2`.
pub(super) const ALPHA: f64 = 2.681_082_873_627_752_3;

/// `β = (3^(5/6) + 3^(7/6))/2`.
pub(super) const BETA: f64 = 3.050_430_199_247_411;

/// `T` with `T⁻¹ A⁻¹ T = [[γ, 0, 0], [0, α, β], [0, −β, α]]`.
pub(super) const T: [[f64; 3]; 3] = [
    [
        0.094_438_762_488_975_24,
        -0.141_255_295_020_954_2,
        0.030_029_194_105_147_42,
    ],
    [
        0.250_213_122_965_333_3,
        0.204_129_352_293_799_94,
        -0.382_942_112_757_261_9,
    ],
    [1.0, 1.0, 0.0],
];

/// `T⁻¹`.
pub(super) const TI: [[f64; 3]; 3] = [
    [
        4.178_718_591_551_904,
        0.327_682_820_761_062_37,
        0.523_376_445_499_449_5,
    ],
    [
        -4.178_718_591_551_904,
        -0.327_682_820_761_062_37,
        0.476_623_554_500_550_44,
    ],
    [
        0.502_872_634_945_786_8,
        -2.571_926_949_855_605,
        0.596_039_204_828_224_9,
    ],
];

/// The collocation polynomial of a step in powers of `s = (τ − t)/h`:
/// `x(τ) = x + Σ_k q_k s^(k+1)` with `q_k = Σ_i P[i][k] z_i` passes
/// through `x + z_i` at `s = c_i`.
pub(super) const P: [[f64; 3]; 3] = [
    [
        13.0 / 3.0 + 7.0 * S6 / 3.0,
        -23.0 / 3.0 - 22.0 * S6 / 3.0,
        10.0 / 3.0 + 5.0 * S6,
    ],
    [
        13.0 / 3.0 - 7.0 * S6 / 3.0,
        -23.0 / 3.0 + 22.0 * S6 / 3.0,
        10.0 / 3.0 - 5.0 * S6,
    ],
    [1.0 / 3.0, -8.0 / 3.0, 10.0 / 3.0],
];

#[cfg(test)]
mod tests {
    use super::*;

    /// The Radau IIA matrix `A`.
    fn a() -> [[f64; 3]; 3] {
        let s6 = 6f64.sqrt();
        [
            [
                (88.0 - 7.0 * s6) / 360.0,
                (296.0 - 169.0 * s6) / 1800.0,
                (-2.0 + 3.0 * s6) / 225.0,
            ],
            [
                (296.0 + 169.0 * s6) / 1800.0,
                (88.0 + 7.0 * s6) / 360.0,
                (-2.0 - 3.0 * s6) / 225.0,
            ],
            [(16.0 - s6) / 36.0, (16.0 + s6) / 36.0, 1.0 / 9.0],
        ]
    }

    fn mul(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
        let mut m = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
            }
        }
        m
    }

    #[test]
    fn constants_match_their_closed_forms() {
        assert_eq!(S6, 6f64.sqrt());
        let (c1, c2) = (3f64.powf(1.0 / 3.0), 3f64.powf(2.0 / 3.0));
        assert!((GAMMA - (3.0 + c2 - c1)).abs() < 1e-15);
        assert!((ALPHA - (3.0 + 0.5 * (c1 - c2))).abs() < 1e-15);
        assert!((BETA - 0.5 * (3f64.powf(5.0 / 6.0) + 3f64.powf(7.0 / 6.0))).abs() < 1e-15);
        // The row sums of A are the nodes.
        for (row, c) in a().iter().zip(C) {
            assert!((row.iter().sum::<f64>() - c).abs() < 1e-15);
        }
    }

    #[test]
    fn t_block_diagonalises_the_inverse_of_a() {
        let id = mul(&T, &TI);
        for (i, row) in id.iter().enumerate() {
            for (j, v) in row.iter().enumerate() {
                assert!((v - if i == j { 1.0 } else { 0.0 }).abs() < 1e-15, "{id:?}");
            }
        }
        // TI A⁻¹ T = Λ  ⇔  A T Λ = T.
        let lambda = [[GAMMA, 0.0, 0.0], [0.0, ALPHA, BETA], [0.0, -BETA, ALPHA]];
        let m = mul(&mul(&a(), &T), &lambda);
        for i in 0..3 {
            for j in 0..3 {
                assert!((m[i][j] - T[i][j]).abs() < 1e-14, "{m:?}");
            }
        }
    }

    #[test]
    fn the_collocation_polynomial_interpolates_the_stages() {
        for (i, row) in P.iter().enumerate() {
            for (j, &c) in C.iter().enumerate() {
                let v: f64 = (0..3).map(|k| row[k] * c.powi(k as i32 + 1)).sum();
                assert!(
                    (v - if i == j { 1.0 } else { 0.0 }).abs() < 1e-13,
                    "{i} {j} {v}"
                );
            }
        }
    }

    #[test]
    fn the_error_weights_give_an_order_three_estimate() {
        // The estimate's weights b̂ − b on the stage derivatives: E A⁻¹·h
        // combined with γ0 = 1/γ must annihilate 1, c, c² (order 3).
        let a = a();
        for p in 0..3 {
            // z_i = h Σ_j a_ij c_j^p (stage increments of x' = t^p, h = 1).
            let z: Vec<f64> = (0..3)
                .map(|i| (0..3).map(|j| a[i][j] * C[j].powi(p)).sum())
                .collect();
            let f0 = if p == 0 { 1.0 } else { 0.0 };
            let est = f0 + (0..3).map(|i| E[i] * z[i]).sum::<f64>();
            assert!(est.abs() < 1e-13, "p = {p}: {est}");
        }
    }
}
