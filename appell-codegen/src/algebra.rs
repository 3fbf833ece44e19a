//! Vectors and 3×3 matrices whose entries are expressions of one [`Graph`].
//!
//! Every vector helper the kinematics and the derivation use lives here, so
//! that a dot product is built the same way (and yields the same nodes)
//! wherever it is taken. Vectors are in N components unless a caller says
//! otherwise; matrices are row-major.

use appell_symbolic::{Graph, Id, Symbol, SymbolicError};

/// A vector in N components.
pub type Vec3 = [Id; 3];
/// A 3×3 matrix, row-major.
pub type Mat3 = [[Id; 3]; 3];

/// `a · b` of vectors.
pub fn dot(g: &mut Graph, a: Vec3, b: Vec3) -> Result<Id, SymbolicError> {
    let t: Vec<Id> = (0..3)
        .map(|k| g.mul(a[k], b[k]))
        .collect::<Result<_, _>>()?;
    g.sum(&t)
}

/// `a × b`.
pub fn cross(g: &mut Graph, a: Vec3, b: Vec3) -> Result<Vec3, SymbolicError> {
    let c = |g: &mut Graph, i: usize, j: usize| -> Result<Id, SymbolicError> {
        let x = g.mul(a[i], b[j])?;
        let y = g.mul(a[j], b[i])?;
        g.sub(x, y)
    };
    Ok([c(g, 1, 2)?, c(g, 2, 0)?, c(g, 0, 1)?])
}

/// `a · b` of 3×3 matrices.
pub fn mat_mul(g: &mut Graph, a: &Mat3, b: &Mat3) -> Result<Mat3, SymbolicError> {
    let zero = g.int(0)?;
    let mut out = [[zero; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            let t: Vec<Id> = (0..3)
                .map(|k| g.mul(a[i][k], b[k][j]))
                .collect::<Result<_, _>>()?;
            out[i][j] = g.sum(&t)?;
        }
    }
    Ok(out)
}

/// `m v`.
pub fn mat_vec(g: &mut Graph, m: &Mat3, v: Vec3) -> Result<Vec3, SymbolicError> {
    Ok([dot(g, m[0], v)?, dot(g, m[1], v)?, dot(g, m[2], v)?])
}

/// `mᵀ v`: with a frame's rotation matrix, N components to the frame's.
pub fn mat_t_vec(g: &mut Graph, m: &Mat3, v: Vec3) -> Result<Vec3, SymbolicError> {
    let col = |k: usize| [m[0][k], m[1][k], m[2][k]];
    Ok([dot(g, col(0), v)?, dot(g, col(1), v)?, dot(g, col(2), v)?])
}

/// `rel · v + plus`, componentwise, skipping the zero entries of `rel`
/// (a frame-to-frame rotation whose direction cosines are mostly zero).
pub fn turned(g: &mut Graph, rel: &Mat3, v: Vec3, plus: Vec3) -> Result<Vec3, SymbolicError> {
    let mut out = plus;
    for i in 0..3 {
        let mut terms = vec![plus[i]];
        for j in 0..3 {
            if !g.is_zero(rel[i][j]) {
                terms.push(g.mul(rel[i][j], v[j])?);
            }
        }
        out[i] = g.sum(&terms)?;
    }
    Ok(out)
}

/// Σ_k parts_k ẏ_k + p0, with ẏ_k the symbols `speeds`.
pub fn combine(
    g: &mut Graph,
    parts: &[Vec3],
    p0: Vec3,
    speeds: &[Symbol],
) -> Result<Vec3, SymbolicError> {
    let mut out = p0;
    for i in 0..3 {
        let mut terms = vec![p0[i]];
        for (k, s) in speeds.iter().enumerate() {
            let y = g.sym(*s)?;
            terms.push(g.mul(parts[k][i], y)?);
        }
        out[i] = g.sum(&terms)?;
    }
    Ok(out)
}

/// Splits a vector linear in `speeds` into its coefficient vectors and the
/// rest: the inverse of [`combine`].
pub fn split_linear(
    g: &mut Graph,
    v: Vec3,
    speeds: &[Symbol],
) -> Result<(Vec<Vec3>, Vec3), SymbolicError> {
    let zero = g.int(0)?;
    let mut parts = vec![[zero; 3]; speeds.len()];
    let mut rest = [zero; 3];
    for i in 0..3 {
        let form = g.linear_coefficients(v[i], speeds)?;
        for (k, c) in form.coefficients.into_iter().enumerate() {
            parts[k][i] = c;
        }
        rest[i] = form.remainder;
    }
    Ok((parts, rest))
}

/// Multiplies out products of sums when that makes the expression no
/// larger: cancellations then happen (the velocity terms of the
/// wheel-axle's forcing vanish only after expansion), while an expansion
/// that would blow up (nested rotations) is abandoned early by a term
/// budget and the factored form is kept.
pub fn expanded(g: &mut Graph, e: Id) -> Result<Id, SymbolicError> {
    const TERM_BUDGET: usize = 32;
    match g.expand_outside_functions(e, TERM_BUDGET) {
        Ok(x) if x == e => Ok(e),
        Ok(x) => {
            if g.dag_size(&[x]) <= g.dag_size(&[e]) {
                Ok(x)
            } else {
                Ok(e)
            }
        }
        Err(SymbolicError::TermLimit { .. }) => Ok(e),
        Err(other) => Err(other),
    }
}

/// [`expanded`], componentwise.
pub fn expanded3(g: &mut Graph, v: Vec3) -> Result<Vec3, SymbolicError> {
    Ok([expanded(g, v[0])?, expanded(g, v[1])?, expanded(g, v[2])?])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vec3(g: &mut Graph, e: [&str; 3]) -> Vec3 {
        e.map(|s| g.parse(s).unwrap())
    }

    #[test]
    fn products_follow_the_right_hand_rule() {
        let mut g = Graph::new();
        g.parameter("a").unwrap();
        g.parameter("b").unwrap();
        let x = vec3(&mut g, ["a", "0", "0"]);
        let y = vec3(&mut g, ["0", "b", "0"]);
        let z = cross(&mut g, x, y).unwrap();
        assert_eq!(z, vec3(&mut g, ["0", "0", "a*b"]));
        let d = dot(&mut g, x, x).unwrap();
        assert_eq!(d, g.parse("a^2").unwrap());
    }

    #[test]
    fn a_rotation_and_its_transpose_undo_each_other() {
        let mut g = Graph::new();
        g.coordinate("q").unwrap();
        g.parameter("a").unwrap();
        let rot = [
            vec3(&mut g, ["cos(q)", "-sin(q)", "0"]),
            vec3(&mut g, ["sin(q)", "cos(q)", "0"]),
            vec3(&mut g, ["0", "0", "1"]),
        ];
        let v = vec3(&mut g, ["a", "0", "1"]);
        let there = mat_vec(&mut g, &rot, v).unwrap();
        let back = mat_t_vec(&mut g, &rot, there).unwrap();
        let back = expanded3(&mut g, back).unwrap();
        assert_eq!(back, v);
        let product = mat_mul(&mut g, &rot, &rot).unwrap();
        assert_eq!(product[2][2], g.parse("1").unwrap());
    }

    #[test]
    fn split_linear_inverts_combine() {
        let mut g = Graph::new();
        let q = g.coordinate("q").unwrap();
        g.parameter("a").unwrap();
        let v = vec3(&mut g, ["a*q_dot + 1", "q_dot*sin(q)", "a"]);
        let (parts, rest) = split_linear(&mut g, v, &[q.rate]).unwrap();
        assert_eq!(parts[0], vec3(&mut g, ["a", "sin(q)", "0"]));
        assert_eq!(rest, vec3(&mut g, ["1", "0", "a"]));
        let again = combine(&mut g, &parts, rest, &[q.rate]).unwrap();
        assert_eq!(again, v);
    }
}
