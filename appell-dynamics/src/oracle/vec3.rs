//! Small fixed-size products of 3-vectors and row-major 3×3 matrices.

/// `a bᵀ` for row-major 3×3 matrices.
pub(crate) fn mul_bt(a: &[f64; 9], b: &[f64; 9]) -> [f64; 9] {
    let mut out = [0.0; 9];
    for i in 0..3 {
        for j in 0..3 {
            out[3 * i + j] = (0..3).map(|k| a[3 * i + k] * b[3 * j + k]).sum();
        }
    }
    out
}

/// `a b` for row-major 3×3 matrices.
pub(crate) fn mul(a: &[f64; 9], b: &[f64; 9]) -> [f64; 9] {
    let mut out = [0.0; 9];
    for i in 0..3 {
        for j in 0..3 {
            out[3 * i + j] = (0..3).map(|k| a[3 * i + k] * b[3 * k + j]).sum();
        }
    }
    out
}

/// The axial vector of the skew-symmetric part of `s`.
pub(crate) fn vee(s: &[f64; 9]) -> [f64; 3] {
    [
        0.5 * (s[7] - s[5]),
        0.5 * (s[2] - s[6]),
        0.5 * (s[3] - s[1]),
    ]
}

pub(super) fn mat_vec(a: &[f64; 9], v: &[f64; 3]) -> [f64; 3] {
    [
        a[0] * v[0] + a[1] * v[1] + a[2] * v[2],
        a[3] * v[0] + a[4] * v[1] + a[5] * v[2],
        a[6] * v[0] + a[7] * v[1] + a[8] * v[2],
    ]
}

pub(super) fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(super) fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(super) fn map3<T: Copy, const K: usize>(x: &[T; K], f: impl Fn(T) -> f64) -> [f64; K] {
    let mut out = [0.0; K];
    for (o, v) in out.iter_mut().zip(x) {
        *o = f(*v);
    }
    out
}
