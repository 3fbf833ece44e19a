//! Arithmetic modulo the Mersenne prime 2⁶¹ − 1, where
//! [`share_equal_values`](super::share_equal_values) evaluates programs
//! exactly.

/// The prime.
pub(super) const P: u64 = (1 << 61) - 1;

/// `a + b`.
pub(super) fn add(a: u64, b: u64) -> u64 {
    let s = a + b;
    if s >= P {
        s - P
    } else {
        s
    }
}

/// `−a`.
pub(super) fn neg(a: u64) -> u64 {
    if a == 0 {
        0
    } else {
        P - a
    }
}

/// `a · b`.
pub(super) fn mul(a: u64, b: u64) -> u64 {
    let t = a as u128 * b as u128;
    let r = ((t & P as u128) + (t >> 61)) as u64;
    if r >= P {
        r - P
    } else {
        r
    }
}

/// `aᵉ`.
pub(super) fn pow(mut a: u64, mut e: u64) -> u64 {
    let mut r = 1;
    while e > 0 {
        if e & 1 == 1 {
            r = mul(r, a);
        }
        a = mul(a, a);
        e >>= 1;
    }
    r
}

/// The inverse, or None for zero.
pub(super) fn inv(a: u64) -> Option<u64> {
    (a != 0).then(|| pow(a, P - 2))
}

/// An integer's residue.
pub(super) fn int(n: i128) -> u64 {
    let r = (n.unsigned_abs() % P as u128) as u64;
    if n < 0 {
        neg(r)
    } else {
        r
    }
}
