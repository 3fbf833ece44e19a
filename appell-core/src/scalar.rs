//! The scalar trait the generated code is generic over.

use core::fmt::Debug;
use core::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Sub, SubAssign};

/// A real number type the generated equations of motion can run on: `f64`,
/// `f32`, and (with the `dual` feature) the dual numbers of `num-dual`, so
/// derivatives of the generated code come out exactly by forward-mode
/// automatic differentiation.
///
/// Emitted code calls these as methods (`x.sin()`), so the trait must be in
/// scope there; the derive takes care of that.
///
/// ```
/// use appell_core::Scalar;
///
/// fn pendulum_accel<T: Scalar>(theta: T, g_over_l: T) -> T {
///     -(g_over_l * theta.sin())
/// }
/// assert_eq!(pendulum_accel(0.0_f64, 9.81), 0.0);
/// assert!((pendulum_accel(0.5_f32, 9.81) + 9.81 * 0.5_f32.sin()).abs() < 1e-6);
/// ```
pub trait Scalar:
    Copy
    + Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
    + DivAssign
    + 'static
{
    /// The value `x` (rounded for `f32`; a constant for dual numbers).
    fn from_f64(x: f64) -> Self;
    /// The real part as `f64` (the value itself for plain floats).
    fn re(self) -> f64;
    /// Sine.
    fn sin(self) -> Self;
    /// Cosine.
    fn cos(self) -> Self;
    /// Tangent.
    fn tan(self) -> Self;
    /// Exponential.
    fn exp(self) -> Self;
    /// Natural logarithm.
    fn ln(self) -> Self;
    /// Absolute value.
    fn abs(self) -> Self;
    /// Square root.
    fn sqrt(self) -> Self;
    /// Integer power.
    fn powi(self, n: i32) -> Self;
    /// Four-quadrant arctangent of `self / x`.
    fn atan2(self, x: Self) -> Self;
    /// `self · a + b`, which generated code writes for every product that
    /// feeds a sum. For `f32` and `f64` built with the `std` feature for a
    /// target with FMA instructions (`-C target-cpu=native` on most x86-64
    /// machines since 2013, or `-C target-feature=+fma`) it is one fused
    /// instruction with a single rounding; everywhere else it is the product
    /// and the sum, rounded apart, so the default build's values are those
    /// of `self * a + b` to the bit.
    ///
    /// ```
    /// use appell_core::Scalar;
    /// let x = 0.1_f64.fused_mul_add(3.0, -0.3);
    /// assert!(x.abs() < 1e-16);
    /// assert_eq!(2.0_f32.fused_mul_add(3.0, 1.0), 7.0);
    /// ```
    #[inline(always)]
    fn fused_mul_add(self, a: Self, b: Self) -> Self {
        self * a + b
    }
    /// [`Scalar::fused_mul_add`] under the short name generated code
    /// writes: a large model writes it tens of thousands of times, and the
    /// emitted text is what rustc has to read. Implement
    /// `fused_mul_add`, not this.
    ///
    /// ```
    /// use appell_core::Scalar;
    /// assert_eq!(2.0_f64.fma(3.0, 1.0), 7.0);
    /// ```
    #[inline(always)]
    fn fma(self, a: Self, b: Self) -> Self {
        self.fused_mul_add(a, b)
    }
    /// Hyperbolic sine.
    fn sinh(self) -> Self {
        let e = self.exp();
        (e - Self::one() / e) * Self::from_f64(0.5)
    }
    /// Hyperbolic cosine.
    fn cosh(self) -> Self {
        let e = self.exp();
        (e + Self::one() / e) * Self::from_f64(0.5)
    }
    /// Hyperbolic tangent (no overflow for large arguments).
    fn tanh(self) -> Self {
        let e = (Self::from_f64(-2.0) * self.abs()).exp();
        let t = (Self::one() - e) / (Self::one() + e);
        if self.re() < 0.0 {
            -t
        } else {
            t
        }
    }
    /// Arcsine, in [−π/2, π/2].
    fn asin(self) -> Self {
        let c = ((Self::one() - self) * (Self::one() + self)).sqrt();
        self.atan2(c)
    }
    /// Arccosine, in [0, π].
    fn acos(self) -> Self {
        let s = ((Self::one() - self) * (Self::one() + self)).sqrt();
        s.atan2(self)
    }
    /// Arctangent, in (−π/2, π/2).
    fn atan(self) -> Self {
        self.atan2(Self::one())
    }
    /// `self` to the real power `y` (NaN for a negative base, as `f64::powf`
    /// gives for a non-integer power).
    fn powf(self, y: Self) -> Self {
        (y * self.ln()).exp()
    }
    /// The sign as the generated code takes it: 1 above zero, −1 below, 0 at
    /// zero (not `f64::signum`, which is 1 at +0). A constant: its derivative
    /// is zero.
    ///
    /// ```
    /// use appell_core::Scalar;
    /// assert_eq!([(-2.0_f64).sign(), 0.0.sign(), 3.0.sign()], [-1.0, 0.0, 1.0]);
    /// ```
    fn sign(self) -> Self {
        let r = self.re();
        Self::from_f64(if r > 0.0 {
            1.0
        } else if r < 0.0 {
            -1.0
        } else {
            r * 0.0
        })
    }
    /// `a` where `self > 0`, else `b`: the generated code's conditional
    /// (`if c > 0 { a } else { b }`, `min`, `max`). For dual numbers the
    /// derivative is that of the branch taken.
    ///
    /// ```
    /// use appell_core::Scalar;
    /// assert_eq!(0.5_f64.select(1.0, 2.0), 1.0);
    /// assert_eq!(0.0_f64.select(1.0, 2.0), 2.0);
    /// ```
    #[inline(always)]
    fn select(self, a: Self, b: Self) -> Self {
        if self.re() > 0.0 {
            a
        } else {
            b
        }
    }
    /// Zero.
    fn zero() -> Self {
        Self::from_f64(0.0)
    }
    /// One.
    fn one() -> Self {
        Self::from_f64(1.0)
    }
}

macro_rules! float_scalar {
    ($t:ty, $libm_suffix:ident) => {
        impl Scalar for $t {
            #[inline(always)]
            fn from_f64(x: f64) -> Self {
                x as $t
            }
            #[inline(always)]
            fn re(self) -> f64 {
                self as f64
            }
            #[inline(always)]
            fn sin(self) -> Self {
                // Inline, in f64 (`appell-trig`: the engine's own values);
                // for f32 the f64 value rounded once.
                appell_trig::sin(self as f64) as $t
            }
            #[inline(always)]
            fn cos(self) -> Self {
                appell_trig::cos(self as f64) as $t
            }
            #[inline(always)]
            fn tan(self) -> Self {
                float_scalar!(@call $t, $libm_suffix, tan, self)
            }
            #[inline(always)]
            fn exp(self) -> Self {
                float_scalar!(@call $t, $libm_suffix, exp, self)
            }
            #[inline(always)]
            fn ln(self) -> Self {
                #[cfg(feature = "std")]
                {
                    <$t>::ln(self)
                }
                #[cfg(not(feature = "std"))]
                {
                    libm::Libm::<$t>::log(self)
                }
            }
            #[inline(always)]
            fn abs(self) -> Self {
                if self < 0.0 {
                    -self
                } else {
                    self
                }
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                float_scalar!(@call $t, $libm_suffix, sqrt, self)
            }
            #[inline(always)]
            fn powi(self, n: i32) -> Self {
                #[cfg(feature = "std")]
                {
                    <$t>::powi(self, n)
                }
                #[cfg(not(feature = "std"))]
                {
                    libm::Libm::<$t>::pow(self, n as $t)
                }
            }
            #[inline(always)]
            fn fused_mul_add(self, a: Self, b: Self) -> Self {
                #[cfg(all(feature = "std", target_feature = "fma"))]
                {
                    <$t>::mul_add(self, a, b)
                }
                #[cfg(not(all(feature = "std", target_feature = "fma")))]
                {
                    self * a + b
                }
            }
            #[inline(always)]
            fn atan2(self, x: Self) -> Self {
                #[cfg(feature = "std")]
                {
                    <$t>::atan2(self, x)
                }
                #[cfg(not(feature = "std"))]
                {
                    libm::Libm::<$t>::atan2(self, x)
                }
            }
            #[inline(always)]
            fn sinh(self) -> Self {
                float_scalar!(@call $t, $libm_suffix, sinh, self)
            }
            #[inline(always)]
            fn cosh(self) -> Self {
                float_scalar!(@call $t, $libm_suffix, cosh, self)
            }
            #[inline(always)]
            fn tanh(self) -> Self {
                float_scalar!(@call $t, $libm_suffix, tanh, self)
            }
            #[inline(always)]
            fn asin(self) -> Self {
                float_scalar!(@call $t, $libm_suffix, asin, self)
            }
            #[inline(always)]
            fn acos(self) -> Self {
                float_scalar!(@call $t, $libm_suffix, acos, self)
            }
            #[inline(always)]
            fn atan(self) -> Self {
                float_scalar!(@call $t, $libm_suffix, atan, self)
            }
            #[inline(always)]
            fn powf(self, y: Self) -> Self {
                #[cfg(feature = "std")]
                {
                    <$t>::powf(self, y)
                }
                #[cfg(not(feature = "std"))]
                {
                    libm::Libm::<$t>::pow(self, y)
                }
            }
            #[inline(always)]
            fn select(self, a: Self, b: Self) -> Self {
                if self > 0.0 {
                    a
                } else {
                    b
                }
            }
        }
    };
    (@call $t:ty, $s:ident, $f:ident, $x:expr) => {{
        #[cfg(feature = "std")]
        {
            <$t>::$f($x)
        }
        #[cfg(not(feature = "std"))]
        {
            libm::Libm::<$t>::$f($x)
        }
    }};
}

float_scalar!(f64, f64);
float_scalar!(f32, f32);

#[cfg(feature = "std")]
mod dual {
    use super::Scalar;
    use num_dual::{Dual, Dual2, DualNum, HyperDual};

    macro_rules! dual_scalar {
        ($ty:ty, [$($gen:tt)*]) => {
            impl<$($gen)*> Scalar for $ty {
                #[inline(always)]
                fn from_f64(x: f64) -> Self {
                    <$ty>::from(x)
                }
                #[inline(always)]
                fn re(self) -> f64 {
                    num_dual::DualStruct::re(&self)
                }
                #[inline(always)]
                fn sin(self) -> Self {
                    DualNum::sin(&self)
                }
                #[inline(always)]
                fn cos(self) -> Self {
                    DualNum::cos(&self)
                }
                #[inline(always)]
                fn tan(self) -> Self {
                    DualNum::tan(&self)
                }
                #[inline(always)]
                fn exp(self) -> Self {
                    DualNum::exp(&self)
                }
                #[inline(always)]
                fn ln(self) -> Self {
                    DualNum::ln(&self)
                }
                #[inline(always)]
                fn abs(self) -> Self {
                    if Scalar::re(self) < 0.0 {
                        -self
                    } else {
                        self
                    }
                }
                #[inline(always)]
                fn sqrt(self) -> Self {
                    DualNum::sqrt(&self)
                }
                #[inline(always)]
                fn powi(self, n: i32) -> Self {
                    DualNum::powi(&self, n)
                }
                #[inline(always)]
                fn atan2(self, x: Self) -> Self {
                    DualNum::atan2(&self, x)
                }
                #[inline(always)]
                fn sinh(self) -> Self {
                    DualNum::sinh(&self)
                }
                #[inline(always)]
                fn cosh(self) -> Self {
                    DualNum::cosh(&self)
                }
                #[inline(always)]
                fn tanh(self) -> Self {
                    DualNum::tanh(&self)
                }
                #[inline(always)]
                fn asin(self) -> Self {
                    DualNum::asin(&self)
                }
                #[inline(always)]
                fn acos(self) -> Self {
                    DualNum::acos(&self)
                }
                #[inline(always)]
                fn atan(self) -> Self {
                    DualNum::atan(&self)
                }
                #[inline(always)]
                fn powf(self, y: Self) -> Self {
                    DualNum::powd(&self, y)
                }
            }
        };
    }

    dual_scalar!(Dual<f64>, []);
    dual_scalar!(Dual2<f64>, []);
    dual_scalar!(HyperDual<f64>, []);
    dual_scalar!(Dual<Dual<f64>>, []);
    dual_scalar!(num_dual::DualSVec64<N>, [const N: usize]);
}

#[cfg(test)]
mod tests {
    use super::Scalar;

    fn poly<T: Scalar>(x: T) -> T {
        x * x.sin() + T::from_f64(2.0) * x.powi(3) - x.exp().ln()
            + x.abs().sqrt()
            + x.atan2(T::one())
    }

    #[test]
    fn f32_and_f64_agree() {
        let a = poly(0.7_f64);
        let b = poly(0.7_f32) as f64;
        assert!((a - b).abs() < 1e-5, "{a} vs {b}");
    }

    #[cfg(feature = "std")]
    #[test]
    fn dual_gives_the_derivative() {
        use num_dual::Dual64;
        let x = 0.7;
        let d = poly(Dual64::new(x, 1.0));
        // d/dx [x sin x + 2x³ − x + √x + atan(x)]
        let exact =
            x.sin() + x * x.cos() + 6.0 * x * x - 1.0 + 0.5 / x.sqrt() + 1.0 / (1.0 + x * x);
        assert!((d.eps - exact).abs() < 1e-12);
        assert!((d.re - poly(x)).abs() < 1e-15);
    }
}
