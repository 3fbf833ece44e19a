//! Whether a rigid body's inertia can be physical, in the words of a
//! compile error: the rules are the runtime's (`appell_core::physical`,
//! which `Model::validate` applies to inertias made of parameters), used
//! here on URDF inertials and on the inertias a model writes in numbers.

use appell_core::physical::{check_inertia, BodyRule};

/// Checks a central inertia matrix (a zero one, a point mass, and a
/// slender rod's pass); `Err` says which rule it breaks, with its entries.
pub(crate) fn check_matrix(m: &[[f64; 3]; 3]) -> Result<(), String> {
    let rule = match check_inertia(m) {
        Ok(()) => return Ok(()),
        Err(BodyRule::Triangle) => {
            "violates the triangle inequality: a principal moment exceeds the sum of the other two"
        }
        Err(BodyRule::NonFiniteInertia) => "is not finite",
        Err(_) => "is not positive semidefinite (it has a negative principal moment)",
    };
    Err(format!(
        "its inertia (ixx {}, iyy {}, izz {}, ixy {}, iyz {}, ixz {}) {rule}",
        m[0][0], m[1][1], m[2][2], m[0][1], m[1][2], m[0][2]
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rules() {
        let diag = |a: f64, b: f64, c: f64| [[a, 0.0, 0.0], [0.0, b, 0.0], [0.0, 0.0, c]];
        assert_eq!(check_matrix(&diag(1.0, 1.0, 2.0)), Ok(()));
        assert_eq!(check_matrix(&diag(0.0, 0.0, 0.0)), Ok(()));
        assert_eq!(check_matrix(&diag(0.0, 0.5, 0.5)), Ok(()));
        let e = check_matrix(&diag(1.0, 1.0, 5.0)).unwrap_err();
        assert!(e.contains("triangle"), "{e}");
        let e = check_matrix(&diag(1.0, -1.0, 1.0)).unwrap_err();
        assert!(e.contains("not positive semidefinite"), "{e}");
    }
}
