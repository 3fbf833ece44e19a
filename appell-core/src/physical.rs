//! Whether a body's mass and inertia can be physical: a positive mass, and
//! a central inertia that is positive semidefinite and obeys the triangle
//! inequality (each principal moment at most the sum of the other two).
//!
//! The same rules serve the derive, which refuses a body written in
//! numbers that breaks them, and [`Model::validate`](crate::Model::validate),
//! which checks the bodies whose mass or inertia are parameters.
//!
//! Both inertia conditions are positivity tests by principal minors, with
//! no eigenvalues: I is positive semidefinite, and so is the second-moment
//! matrix S = tr(I)/2 · 1 − I, whose eigenvalues (λⱼ + λₖ − λᵢ)/2 are the
//! ∫x² dm about the principal axes. Semidefinite, not definite: a particle
//! (I = 0) and a slender rod (principal moments 0, I, I) are the limits
//! of real bodies and pass.
//!
//! ```
//! use appell_core::physical::{check_inertia, BodyRule};
//! let diag = |a: f64, b: f64, c: f64| [[a, 0.0, 0.0], [0.0, b, 0.0], [0.0, 0.0, c]];
//! assert_eq!(check_inertia(&diag(0.0, 1.0, 1.0)), Ok(()));
//! assert_eq!(check_inertia(&diag(1.0, 1.0, 5.0)), Err(BodyRule::Triangle));
//! assert_eq!(check_inertia(&diag(1.0, -1.0, 1.0)), Err(BodyRule::NotSemidefinite));
//! ```

pub use crate::error::BodyRule;
use crate::error::ModelError;

/// Checks a central inertia matrix; a zero one (a point mass) passes. The
/// tolerance is relative, 1e-9 of the largest entry's scale, for rounding
/// in the last digit of a file's numbers.
pub fn check_inertia(m: &[[f64; 3]; 3]) -> Result<(), BodyRule> {
    if !m.iter().flatten().all(|x| x.is_finite()) {
        return Err(BodyRule::NonFiniteInertia);
    }
    let scale = m.iter().flatten().fold(0.0f64, |a, x| a.max(x.abs()));
    if scale == 0.0 {
        return Ok(());
    }
    let tol = [
        1e-9 * scale,
        1e-9 * scale * scale,
        1e-9 * scale * scale * scale,
    ];
    if !semidefinite(m, &tol) {
        return Err(BodyRule::NotSemidefinite);
    }
    let half = (m[0][0] + m[1][1] + m[2][2]) / 2.0;
    let mut s = [[0.0; 3]; 3];
    for r in 0..3 {
        for c in 0..3 {
            s[r][c] = if r == c { half - m[r][c] } else { -m[r][c] };
        }
    }
    if !semidefinite(&s, &tol) {
        return Err(BodyRule::Triangle);
    }
    Ok(())
}

/// Checks one body's mass and its row-major inertia (the layout of
/// [`Model::mass_properties`](crate::Model::mass_properties)); the error
/// names the body and the parameters the broken quantity is made of
/// (`of_mass` for the mass, `of_inertia` for the inertia).
///
/// ```
/// use appell_core::physical::{check_body, BodyRule};
/// use appell_core::ModelError;
/// let rod = [0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
/// assert_eq!(check_body("rod", &["m"], &["m", "l"], 2.0, &rod), Ok(()));
/// assert_eq!(
///     check_body("rod", &["m"], &["m", "l"], -2.0, &rod),
///     Err(ModelError::ImpossibleBody { body: "rod", rule: BodyRule::NonPositiveMass, parameters: &["m"] })
/// );
/// ```
pub fn check_body(
    body: &'static str,
    of_mass: &'static [&'static str],
    of_inertia: &'static [&'static str],
    mass: f64,
    inertia: &[f64; 9],
) -> Result<(), ModelError> {
    let (rule, parameters) = if !(mass > 0.0 && mass.is_finite()) {
        (BodyRule::NonPositiveMass, of_mass)
    } else {
        let i = inertia;
        match check_inertia(&[[i[0], i[1], i[2]], [i[3], i[4], i[5]], [i[6], i[7], i[8]]]) {
            Ok(()) => return Ok(()),
            Err(rule) => (rule, of_inertia),
        }
    };
    Err(ModelError::ImpossibleBody {
        body,
        rule,
        parameters,
    })
}

/// 2×2 principal minor of rows and columns a, b.
fn minor(m: &[[f64; 3]; 3], a: usize, b: usize) -> f64 {
    m[a][a] * m[b][b] - m[a][b] * m[b][a]
}

fn det(m: &[[f64; 3]; 3]) -> f64 {
    m[0][0] * minor(m, 1, 2) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// Every principal minor is non-negative (to `tol` by order).
fn semidefinite(m: &[[f64; 3]; 3], tol: &[f64; 3]) -> bool {
    (0..3).all(|k| m[k][k] >= -tol[0])
        && [(0, 1), (0, 2), (1, 2)]
            .iter()
            .all(|&(a, b)| minor(m, a, b) >= -tol[1])
        && det(m) >= -tol[2]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn diag(a: f64, b: f64, c: f64) -> [[f64; 3]; 3] {
        [[a, 0.0, 0.0], [0.0, b, 0.0], [0.0, 0.0, c]]
    }

    #[test]
    fn bodies_and_their_limits_pass() {
        for m in [
            diag(1.0, 1.0, 2.0),
            diag(0.0, 0.0, 0.0),
            diag(0.0, 0.5, 0.5),
            diag(1.0, 2.0, 3.0),
            // A cube's central inertia in rotated axes: dense, still fine.
            [[2.0, -0.5, 0.0], [-0.5, 2.0, 0.0], [0.0, 0.0, 2.5]],
            // The last digit of a file's numbers.
            diag(0.1, 0.2, 0.3 + 1e-12),
        ] {
            assert_eq!(check_inertia(&m), Ok(()), "{m:?}");
        }
    }

    #[test]
    fn each_rule_is_named() {
        assert_eq!(check_inertia(&diag(1.0, 1.0, 5.0)), Err(BodyRule::Triangle));
        // The planar shortcut: only the moment about the normal.
        assert_eq!(check_inertia(&diag(0.0, 0.0, 1.0)), Err(BodyRule::Triangle));
        assert_eq!(
            check_inertia(&diag(1.0, -1.0, 1.0)),
            Err(BodyRule::NotSemidefinite)
        );
        // Positive diagonal, indefinite through a product of inertia.
        let m = [[0.1, 0.2, 0.0], [0.2, 0.1, 0.0], [0.0, 0.0, 0.1]];
        assert_eq!(check_inertia(&m), Err(BodyRule::NotSemidefinite));
        assert_eq!(
            check_inertia(&diag(f64::NAN, 1.0, 1.0)),
            Err(BodyRule::NonFiniteInertia)
        );
        let i = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
        for mass in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(matches!(
                check_body("b", &[], &[], mass, &i),
                Err(ModelError::ImpossibleBody {
                    rule: BodyRule::NonPositiveMass,
                    ..
                })
            ));
        }
    }
}
