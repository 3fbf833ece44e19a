//! Adaptive Dormand–Prince 8(5,3) integration (`DOP853`) with dense output of
//! order 7 and event location, on fixed-size arrays and without allocation.

// The coefficients are kept with the digits they are published with.
#![allow(clippy::excessive_precision)]

use super::check_state_len;
use super::dopri5::{EventFn, IntegrateError, Solution, Stats};
use crate::model::{Model, ModelError};
use crate::scalar::Scalar;

/// Adaptive Dormand–Prince 8(5,3) integrator (Hairer, Nørsett & Wanner,
/// *Solving ODEs I*, 2nd ed., the `DOP853` scheme), configured by a builder
/// with the same API as [`Dopri5`](super::Dopri5).
///
/// The explicit 12-stage Runge–Kutta method of order 8 is propagated; its
/// last-stage derivative at the new state is the first stage of the next
/// step (FSAL), so an accepted step costs 12 rhs calls and a rejected one 11.
///
/// * **Error estimate**: the combined 5th/3rd-order estimator of `DOP853`.
///   With `sk_i = atol + rtol · max(|x_i|, |x_new_i|)`, `e5` the difference
///   to the embedded 5th-order solution and `e3` the one to the embedded
///   3rd-order solution, `E5 = Σ (e5_i/sk_i)²`, `E3 = Σ (e3_i/sk_i)²` and
///   `err = |h| · E5 / sqrt(n · (E5 + 0.01 E3))`, which behaves like an
///   error of order 8 for small steps. A step is accepted when `err ≤ 1`.
/// * **Step control**: `h_new = h · clamp(0.9 · err^(−α) · err_prev^β, 1/3, 6)`
///   with `α = 1/8 − 0.2 β`, `β = 0` by default ([`Dop853::beta`]; a
///   small `β` such as `0.04` gives the PI controller). After a rejection
///   the step shrinks by `clamp(0.9 err^(−1/8), 1/3, 1)` and may not grow on
///   the next accepted step.
/// * **Initial step**: Hairer's `HINIT` algorithm for order 8 (one extra rhs
///   call) unless [`Dop853::h_init`] gives one.
/// * **Dense output**: the continuous extension of order 7 of `DOP853`,
///   which needs 3 extra rhs calls per step; they are made (and counted in
///   [`Stats::rhs_calls`]) only for steps that contain a requested output
///   time strictly inside them or an event.
/// * **Events**: as [`Dopri5`](super::Dopri5): after every accepted step
///   whose end has `g` of the other sign than its start (or zero), the root
///   is located on the dense output by the Illinois method to
///   [`Dop853::event_tol`] and the integration stops there.
/// * **Fixed steps**: [`Dop853::adaptive`]`(false)` takes steps of exactly
///   [`Dop853::h_init`] (the last one cut to end at `t_end`) without error
///   control, e.g. to measure the order of the method.
/// * **Failures** are typed [`IntegrateError`]s, never a panic or a NaN: a
///   non-finite stage rejects the step and retries 5× smaller, and is
///   reported as [`IntegrateError::NonFinite`] once the step would fall
///   below the minimum (at once with fixed steps).
///
/// Time and step sizes are `f64`; the state is any [`Scalar`] (for dual
/// numbers the step-size decisions use the real parts).
///
/// Defaults: `rtol = 1e-6`, `atol = 1e-9`, `max_steps = 100_000`,
/// `h_init = None` (automatic), `h_min = 0` (only the 16-ulp floor),
/// `h_max = None` (the interval length), `beta = 0`, `event_tol = 1e-12`,
/// `adaptive = true`.
///
/// ```
/// use appell_runtime::integrate::Dop853;
/// use appell_runtime::ModelError;
///
/// // Harmonic oscillator x'' = -x over one period, x(0) = 1, x'(0) = 0.
/// let f = |_t: f64, x: &[f64; 2], dx: &mut [f64; 2]| -> Result<(), ModelError> {
///     dx[0] = x[1];
///     dx[1] = -x[0];
///     Ok(())
/// };
/// let tau = 2.0 * std::f64::consts::PI;
/// let sol = Dop853::new().rtol(1e-12).atol(1e-12).solve(f, 0.0, &[1.0, 0.0], tau).unwrap();
/// assert_eq!(sol.t, tau);
/// assert!((sol.x[0] - 1.0).abs() < 1e-10 && sol.x[1].abs() < 1e-10);
/// assert!(sol.stats.rhs_calls < 1000);
///
/// // The time the oscillator first crosses x = 0 (t = π/2), by an event.
/// let sol = Dop853::new()
///     .rtol(1e-10)
///     .solve_until(f, |_t, x: &[f64; 2]| x[0], 0.0, &[1.0, 0.0], tau)
///     .unwrap();
/// assert!(sol.event);
/// assert!((sol.t - std::f64::consts::FRAC_PI_2).abs() < 1e-9);
///
/// // Output at requested times from the 7th-order dense output.
/// let mut out = [(1.0, [0.0; 2]), (2.5, [0.0; 2]), (4.0, [0.0; 2])];
/// let sol = Dop853::new().rtol(1e-11).atol(1e-11).solve_at(f, 0.0, &[1.0, 0.0], &mut out).unwrap();
/// assert_eq!(sol.outputs, 3);
/// for (t, x) in out {
///     assert!((x[0] - t.cos()).abs() < 1e-9);
/// }
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dop853 {
    rtol: f64,
    atol: f64,
    max_steps: usize,
    h_init: Option<f64>,
    h_min: f64,
    h_max: Option<f64>,
    beta: f64,
    event_tol: f64,
    adaptive: bool,
}

impl Default for Dop853 {
    fn default() -> Self {
        Self::new()
    }
}

// Dormand–Prince 8(5,3) coefficients (Hairer, Nørsett & Wanner).
const C2: f64 = 0.526001519587677318785587544488e-01;
const C3: f64 = 0.789002279381515978178381316732e-01;
const C4: f64 = 0.118350341907227396726757197510;
const C5: f64 = 0.281649658092772603273242802490;
const C6: f64 = 0.333333333333333333333333333333;
const C7: f64 = 0.25;
const C8: f64 = 0.307692307692307692307692307692;
const C9: f64 = 0.651282051282051282051282051282;
const C10: f64 = 0.6;
const C11: f64 = 0.857142857142857142857142857142;
const C14: f64 = 0.1;
const C15: f64 = 0.2;
const C16: f64 = 0.777777777777777777777777777778;

const A21: f64 = 5.26001519587677318785587544488e-2;
const A31: f64 = 1.97250569845378994544595329183e-2;
const A32: f64 = 5.91751709536136983633785987549e-2;
const A41: f64 = 2.95875854768068491816892993775e-2;
const A43: f64 = 8.87627564304205475450678981324e-2;
const A51: f64 = 2.41365134159266685502369798665e-1;
const A53: f64 = -8.84549479328286085344864962717e-1;
const A54: f64 = 9.24834003261792003115737966543e-1;
const A61: f64 = 3.7037037037037037037037037037e-2;
const A64: f64 = 1.70828608729473871279604482173e-1;
const A65: f64 = 1.25467687566822425016691814123e-1;
const A71: f64 = 3.7109375e-2;
const A74: f64 = 1.70252211019544039314978060272e-1;
const A75: f64 = 6.02165389804559606850219397283e-2;
const A76: f64 = -1.7578125e-2;
const A81: f64 = 3.70920001185047927108779319836e-2;
const A84: f64 = 1.70383925712239993810214054705e-1;
const A85: f64 = 1.07262030446373284651809199168e-1;
const A86: f64 = -1.53194377486244017527936158236e-2;
const A87: f64 = 8.27378916381402288758473766002e-3;
const A91: f64 = 6.24110958716075717114429577812e-1;
const A94: f64 = -3.36089262944694129406857109825;
const A95: f64 = -8.68219346841726006818189891453e-1;
const A96: f64 = 2.75920996994467083049415600797e1;
const A97: f64 = 2.01540675504778934086186788979e1;
const A98: f64 = -4.34898841810699588477366255144e1;
const A101: f64 = 4.77662536438264365890433908527e-1;
const A104: f64 = -2.48811461997166764192642586468;
const A105: f64 = -5.90290826836842996371446475743e-1;
const A106: f64 = 2.12300514481811942347288949897e1;
const A107: f64 = 1.52792336328824235832596922938e1;
const A108: f64 = -3.32882109689848629194453265587e1;
const A109: f64 = -2.03312017085086261358222928593e-2;
const A111: f64 = -9.3714243008598732571704021658e-1;
const A114: f64 = 5.18637242884406370830023853209;
const A115: f64 = 1.09143734899672957818500254654;
const A116: f64 = -8.14978701074692612513997267357;
const A117: f64 = -1.85200656599969598641566180701e1;
const A118: f64 = 2.27394870993505042818970056734e1;
const A119: f64 = 2.49360555267965238987089396762;
const A1110: f64 = -3.0467644718982195003823669022;
const A121: f64 = 2.27331014751653820792359768449;
const A124: f64 = -1.05344954667372501984066689879e1;
const A125: f64 = -2.00087205822486249909675718444;
const A126: f64 = -1.79589318631187989172765950534e1;
const A127: f64 = 2.79488845294199600508499808837e1;
const A128: f64 = -2.85899827713502369474065508674;
const A129: f64 = -8.87285693353062954433549289258;
const A1210: f64 = 1.23605671757943030647266201528e1;
const A1211: f64 = 6.43392746015763530355970484046e-1;

const A141: f64 = 5.61675022830479523392909219681e-2;
const A147: f64 = 2.53500210216624811088794765333e-1;
const A148: f64 = -2.46239037470802489917441475441e-1;
const A149: f64 = -1.24191423263816360469010140626e-1;
const A1410: f64 = 1.5329179827876569731206322685e-1;
const A1411: f64 = 8.20105229563468988491666602057e-3;
const A1412: f64 = 7.56789766054569976138603589584e-3;
const A1413: f64 = -8.298e-3;
const A151: f64 = 3.18346481635021405060768473261e-2;
const A156: f64 = 2.83009096723667755288322961402e-2;
const A157: f64 = 5.35419883074385676223797384372e-2;
const A158: f64 = -5.49237485713909884646569340306e-2;
const A1511: f64 = -1.08347328697249322858509316994e-4;
const A1512: f64 = 3.82571090835658412954920192323e-4;
const A1513: f64 = -3.40465008687404560802977114492e-4;
const A1514: f64 = 1.41312443674632500278074618366e-1;
const A161: f64 = -4.28896301583791923408573538692e-1;
const A166: f64 = -4.69762141536116384314449447206;
const A167: f64 = 7.68342119606259904184240953878;
const A168: f64 = 4.06898981839711007970213554331;
const A169: f64 = 3.56727187455281109270669543021e-1;
const A1613: f64 = -1.39902416515901462129418009734e-3;
const A1614: f64 = 2.9475147891527723389556272149;
const A1615: f64 = -9.15095847217987001081870187138;

const B1: f64 = 5.42937341165687622380535766363e-2;
const B6: f64 = 4.45031289275240888144113950566;
const B7: f64 = 1.89151789931450038304281599044;
const B8: f64 = -5.8012039600105847814672114227;
const B9: f64 = 3.1116436695781989440891606237e-1;
const B10: f64 = -1.52160949662516078556178806805e-1;
const B11: f64 = 2.01365400804030348374776537501e-1;
const B12: f64 = 4.47106157277725905176885569043e-2;

const BHH1: f64 = 0.244094488188976377952755905512;
const BHH2: f64 = 0.733846688281611857341361741547;
const BHH3: f64 = 0.220588235294117647058823529412e-01;

const ER1: f64 = 0.1312004499419488073250102996e-01;
const ER6: f64 = -0.1225156446376204440720569753e+01;
const ER7: f64 = -0.4957589496572501915214079952;
const ER8: f64 = 0.1664377182454986536961530415e+01;
const ER9: f64 = -0.3503288487499736816886487290;
const ER10: f64 = 0.3341791187130174790297318841;
const ER11: f64 = 0.8192320648511571246570742613e-01;
const ER12: f64 = -0.2235530786388629525884427845e-01;

/// Dense output coefficients: row `j` (for the polynomial coefficients 4 to
/// 7) weights the stages 1, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16.
const D: [[f64; 12]; 4] = [
    [
        -0.84289382761090128651353491142e+01,
        0.56671495351937776962531783590,
        -0.30689499459498916912797304727e+01,
        0.23846676565120698287728149680e+01,
        0.21170345824450282767155149946e+01,
        -0.87139158377797299206789907490,
        0.22404374302607882758541771650e+01,
        0.63157877876946881815570249290,
        -0.88990336451333310820698117400e-01,
        0.18148505520854727256656404962e+02,
        -0.91946323924783554000451984436e+01,
        -0.44360363875948939664310572000e+01,
    ],
    [
        0.10427508642579134603413151009e+02,
        0.24228349177525818288430175319e+03,
        0.16520045171727028198505394887e+03,
        -0.37454675472269020279518312152e+03,
        -0.22113666853125306036270938578e+02,
        0.77334326684722638389603898808e+01,
        -0.30674084731089398182061213626e+02,
        -0.93321305264302278729567221706e+01,
        0.15697238121770843886131091075e+02,
        -0.31139403219565177677282850411e+02,
        -0.93529243588444783865713862664e+01,
        0.35816841486394083752465898540e+02,
    ],
    [
        0.19985053242002433820987653617e+02,
        -0.38703730874935176555105901742e+03,
        -0.18917813819516756882830838328e+03,
        0.52780815920542364900561016686e+03,
        -0.11573902539959630126141871134e+02,
        0.68812326946963000169666922661e+01,
        -0.10006050966910838403183860980e+01,
        0.77771377980534432092869265740,
        -0.27782057523535084065932004339e+01,
        -0.60196695231264120758267380846e+02,
        0.84320405506677161018159903784e+02,
        0.11992291136182789328035130030e+02,
    ],
    [
        -0.25693933462703749003312586129e+02,
        -0.15418974869023643374053993627e+03,
        -0.23152937917604549567536039109e+03,
        0.35763911791061412378285349910e+03,
        0.93405324183624310003907691704e+02,
        -0.37458323136451633156875139351e+02,
        0.10409964950896230045147246184e+03,
        0.29840293426660503123344363579e+02,
        -0.43533456590011143754432175058e+02,
        0.96324553959188282948394950600e+02,
        -0.39177261675615439165231486172e+02,
        -0.14972683625798562581422125276e+03,
    ],
];

const SAFETY: f64 = 0.9;
/// Smallest factor `h_new / h`.
const FAC_MIN: f64 = 1.0 / 3.0;
/// Largest factor `h_new / h`.
const FAC_MAX: f64 = 6.0;
/// Factor of the retry after a non-finite stage.
const FAC_NON_FINITE: f64 = 0.2;
const EVENT_MAX_ITER: usize = 200;

/// Where requested outputs go.
trait Sink<T, const S: usize> {
    fn len(&self) -> usize;
    fn time(&self, i: usize) -> f64;
    fn put(&mut self, i: usize, x: &[T; S]);
}

struct SliceSink<'a, T, const S: usize>(&'a mut [(f64, [T; S])]);

impl<T: Copy, const S: usize> Sink<T, S> for SliceSink<'_, T, S> {
    fn len(&self) -> usize {
        self.0.len()
    }
    fn time(&self, i: usize) -> f64 {
        self.0[i].0
    }
    fn put(&mut self, i: usize, x: &[T; S]) {
        self.0[i].1 = *x;
    }
}

struct CallbackSink<'a, 'b, T, const S: usize> {
    times: &'a [f64],
    cb: &'b mut dyn FnMut(f64, &[T; S]),
}

impl<T, const S: usize> Sink<T, S> for CallbackSink<'_, '_, T, S> {
    fn len(&self) -> usize {
        self.times.len()
    }
    fn time(&self, i: usize) -> f64 {
        self.times[i]
    }
    fn put(&mut self, i: usize, x: &[T; S]) {
        (self.cb)(self.times[i], x)
    }
}

/// The continuous extension (order 7) of one accepted step.
struct Dense<T, const S: usize> {
    t: f64,
    h: f64,
    r: [[T; S]; 8],
}

impl<T: Scalar, const S: usize> Dense<T, S> {
    fn at(&self, t: f64) -> [T; S] {
        let s = (t - self.t) / self.h;
        let (s, s1) = (T::from_f64(s), T::from_f64(1.0 - s));
        let r = &self.r;
        let mut out = r[0];
        for (i, o) in out.iter_mut().enumerate() {
            let p = r[4][i] + s * (r[5][i] + s1 * (r[6][i] + s * r[7][i]));
            *o = r[0][i] + s * (r[1][i] + s1 * (r[2][i] + s * (r[3][i] + s1 * p)));
        }
        out
    }
}

fn all_finite<T: Scalar, const S: usize>(x: &[T; S]) -> bool {
    x.iter().all(|v| v.re().is_finite())
}

/// `x + h Σ w_j k_j`.
fn combine<T: Scalar, const S: usize, const N: usize>(
    x: &[T; S],
    h: T,
    terms: [(f64, &[T; S]); N],
) -> [T; S] {
    let mut y = *x;
    for i in 0..S {
        let mut acc = T::zero();
        for (w, k) in terms.iter() {
            acc += T::from_f64(*w) * k[i];
        }
        y[i] = x[i] + h * acc;
    }
    y
}

/// The stages of one step.
struct Stages<T, const S: usize> {
    k: [[T; S]; 16],
}

impl Dop853 {
    /// The integrator with the documented defaults ([`Dop853`]).
    pub const fn new() -> Self {
        Dop853 {
            rtol: 1e-6,
            atol: 1e-9,
            max_steps: 100_000,
            h_init: None,
            h_min: 0.0,
            h_max: None,
            beta: 0.0,
            event_tol: 1e-12,
            adaptive: true,
        }
    }

    /// Relative tolerance (default `1e-6`; must be ≥ 0).
    pub const fn rtol(mut self, rtol: f64) -> Self {
        self.rtol = rtol;
        self
    }

    /// Absolute tolerance (default `1e-9`; must be ≥ 0, and `rtol` and
    /// `atol` not both 0).
    pub const fn atol(mut self, atol: f64) -> Self {
        self.atol = atol;
        self
    }

    /// Maximum number of steps, accepted and rejected (default `100_000`).
    pub const fn max_steps(mut self, max_steps: usize) -> Self {
        self.max_steps = max_steps;
        self
    }

    /// The first step size (magnitude), or `None` (default) for Hairer's
    /// automatic choice. With [`Dop853::adaptive`]`(false)` it is the size
    /// of every step and must be given.
    pub const fn h_init(mut self, h_init: Option<f64>) -> Self {
        self.h_init = h_init;
        self
    }

    /// Minimum step size (default `0`: only the floor of 16 ulp of `t`); a
    /// smaller proposed step is [`IntegrateError::StepSizeTooSmall`]. The
    /// last step, cut to end exactly at `t_end`, may be smaller.
    pub const fn h_min(mut self, h_min: f64) -> Self {
        self.h_min = h_min;
        self
    }

    /// Maximum step size, or `None` (default) for the interval length.
    pub const fn h_max(mut self, h_max: Option<f64>) -> Self {
        self.h_max = h_max;
        self
    }

    /// The controller's β (default `0`, the elementary controller of
    /// `DOP853`; must be in `[0, 0.2]`).
    pub const fn beta(mut self, beta: f64) -> Self {
        self.beta = beta;
        self
    }

    /// Absolute time tolerance of event location (default `1e-12`, never
    /// below 4 ulp of the event time).
    pub const fn event_tol(mut self, event_tol: f64) -> Self {
        self.event_tol = event_tol;
        self
    }

    /// Error control on (default `true`). With `false`, every step has the
    /// size [`Dop853::h_init`] (required; the last step is cut to end at
    /// `t_end`, and [`Dop853::h_max`] is ignored) and is accepted without an
    /// error estimate; a non-finite state is reported at once.
    pub const fn adaptive(mut self, adaptive: bool) -> Self {
        self.adaptive = adaptive;
        self
    }

    /// Integrates `dx/dt = f(t, x)` from `(t0, x0)` to `t_end` (which may
    /// be before `t0`). `f(t, x, dx)` writes the derivative into `dx`.
    ///
    /// See [`Dop853`] for an example.
    pub fn solve<T, F, const S: usize>(
        &self,
        f: F,
        t0: f64,
        x0: &[T; S],
        t_end: f64,
    ) -> Result<Solution<T, S>, IntegrateError>
    where
        T: Scalar,
        F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
    {
        let mut sink = CallbackSink {
            times: &[],
            cb: &mut |_, _| {},
        };
        self.run(f, t0, x0, t_end, &mut sink, None)
    }

    /// As [`Dop853::solve`], stopping at the first sign change of the event
    /// function `g(t, x)` (see [`Dop853`]); [`Solution::event`] tells
    /// whether it happened. A zero of `g` at `t0` is not an event.
    ///
    /// The reported time is the end of the final bracket on the far side of
    /// the crossing (where `g` has its new sign or is zero), within
    /// [`Dop853::event_tol`] of the root of `g` on the dense output; the
    /// state there comes from the dense output.
    pub fn solve_until<T, F, G, const S: usize>(
        &self,
        f: F,
        mut g: G,
        t0: f64,
        x0: &[T; S],
        t_end: f64,
    ) -> Result<Solution<T, S>, IntegrateError>
    where
        T: Scalar,
        F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
        G: FnMut(f64, &[T; S]) -> f64,
    {
        let mut sink = CallbackSink {
            times: &[],
            cb: &mut |_, _| {},
        };
        self.run(f, t0, x0, t_end, &mut sink, Some(&mut g))
    }

    /// Integrates from `(t0, x0)` to the last time of `out` and writes the
    /// state at each `out[i].0` (set by the caller, ordered in the
    /// direction of integration) into `out[i].1`, from the dense output.
    ///
    /// ```
    /// use appell_runtime::integrate::Dop853;
    /// use appell_runtime::ModelError;
    ///
    /// let f = |_t: f64, x: &[f64; 1], dx: &mut [f64; 1]| -> Result<(), ModelError> {
    ///     dx[0] = -x[0];
    ///     Ok(())
    /// };
    /// let mut out = [(0.5, [0.0]), (1.0, [0.0]), (2.0, [0.0])];
    /// let sol = Dop853::new().rtol(1e-9).atol(1e-12).solve_at(f, 0.0, &[1.0], &mut out).unwrap();
    /// assert_eq!(sol.outputs, 3);
    /// for (t, x) in out {
    ///     assert!((x[0] - (-t).exp()).abs() < 1e-8);
    /// }
    /// ```
    pub fn solve_at<T, F, const S: usize>(
        &self,
        f: F,
        t0: f64,
        x0: &[T; S],
        out: &mut [(f64, [T; S])],
    ) -> Result<Solution<T, S>, IntegrateError>
    where
        T: Scalar,
        F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
    {
        let t_end = out.last().map_or(t0, |o| o.0);
        self.run(f, t0, x0, t_end, &mut SliceSink(out), None)
    }

    /// The general form: integrates from `(t0, x0)` to `t_end`, calls
    /// `on_output(t, x)` at each of `times` (ordered in the direction of
    /// integration and within the interval), and stops at an event of `g`
    /// when one is given (as [`Dop853::solve_until`]); output times past the
    /// event are not reached.
    #[allow(clippy::too_many_arguments)]
    pub fn solve_with<T, F, const S: usize>(
        &self,
        f: F,
        t0: f64,
        x0: &[T; S],
        t_end: f64,
        times: &[f64],
        on_output: &mut dyn FnMut(f64, &[T; S]),
        event: Option<&mut EventFn<'_, T, S>>,
    ) -> Result<Solution<T, S>, IntegrateError>
    where
        T: Scalar,
        F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
    {
        let mut sink = CallbackSink {
            times,
            cb: on_output,
        };
        self.run(f, t0, x0, t_end, &mut sink, event)
    }

    /// [`Dop853::solve`] of a model's reduced equations ([`Model::rhs`],
    /// after one [`Model::prepare`]) with `inputs` held constant. The array
    /// length `S` must be the reduced state length.
    pub fn solve_model<M: Model, T: Scalar, const S: usize>(
        &self,
        model: &M,
        inputs: &[T],
        t0: f64,
        x0: &[T; S],
        t_end: f64,
    ) -> Result<Solution<T, S>, IntegrateError> {
        check_state_len::<M>(S)?;
        let p = model.prepare::<T>();
        let f = |t: T, x: &[T; S], dx: &mut [T; S]| model.rhs(&p, t, x, inputs, dx);
        self.solve(f, t0, x0, t_end)
    }

    /// [`Dop853::solve_at`] of a model's reduced equations, as
    /// [`Dop853::solve_model`].
    pub fn solve_model_at<M: Model, T: Scalar, const S: usize>(
        &self,
        model: &M,
        inputs: &[T],
        t0: f64,
        x0: &[T; S],
        out: &mut [(f64, [T; S])],
    ) -> Result<Solution<T, S>, IntegrateError> {
        check_state_len::<M>(S)?;
        let p = model.prepare::<T>();
        let f = |t: T, x: &[T; S], dx: &mut [T; S]| model.rhs(&p, t, x, inputs, dx);
        self.solve_at(f, t0, x0, out)
    }

    /// [`Dop853::solve_until`] of a model's reduced equations, as
    /// [`Dop853::solve_model`].
    pub fn solve_model_until<M: Model, T: Scalar, G, const S: usize>(
        &self,
        model: &M,
        inputs: &[T],
        g: G,
        t0: f64,
        x0: &[T; S],
        t_end: f64,
    ) -> Result<Solution<T, S>, IntegrateError>
    where
        G: FnMut(f64, &[T; S]) -> f64,
    {
        check_state_len::<M>(S)?;
        let p = model.prepare::<T>();
        let f = |t: T, x: &[T; S], dx: &mut [T; S]| model.rhs(&p, t, x, inputs, dx);
        self.solve_until(f, g, t0, x0, t_end)
    }

    fn check_settings(&self) -> Result<(), IntegrateError> {
        let bad = |what| Err(IntegrateError::InvalidInput { what });
        if !(self.rtol >= 0.0 && self.rtol.is_finite()) {
            return bad("rtol must be finite and >= 0");
        }
        if !(self.atol >= 0.0 && self.atol.is_finite()) {
            return bad("atol must be finite and >= 0");
        }
        if self.rtol == 0.0 && self.atol == 0.0 {
            return bad("rtol and atol are both 0");
        }
        if !(self.h_min >= 0.0 && self.h_min.is_finite()) {
            return bad("h_min must be finite and >= 0");
        }
        if let Some(h) = self.h_init {
            if !(h.is_finite() && h != 0.0) {
                return bad("h_init must be finite and nonzero");
            }
        }
        if !self.adaptive && self.h_init.is_none() {
            return bad("fixed steps (adaptive(false)) need h_init");
        }
        if let Some(h) = self.h_max {
            if h.is_nan() || h <= 0.0 {
                return bad("h_max must be > 0");
            }
        }
        if !(0.0..=0.2).contains(&self.beta) {
            return bad("beta must be in [0, 0.2]");
        }
        if self.event_tol.is_nan() || self.event_tol < 0.0 {
            return bad("event_tol must be >= 0");
        }
        Ok(())
    }

    /// The weight `atol + rtol |x|`, kept positive.
    fn scale(&self, a: f64, b: f64) -> f64 {
        let sk = self.atol + self.rtol * a.abs().max(b.abs());
        sk.max(f64::MIN_POSITIVE)
    }

    /// Hairer's `HINIT` for order 8: a first step from the size of `x`, `f`
    /// and an estimate of the second derivative (one rhs call).
    #[allow(clippy::too_many_arguments)]
    fn initial_step<T, F, const S: usize>(
        &self,
        f: &mut F,
        t: f64,
        x: &[T; S],
        k1: &[T; S],
        dir: f64,
        h_max: f64,
        stats: &mut Stats,
    ) -> Result<f64, IntegrateError>
    where
        T: Scalar,
        F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
    {
        let (mut dnf, mut dny) = (0.0, 0.0);
        for i in 0..S {
            let sk = self.scale(x[i].re(), 0.0);
            dnf += (k1[i].re() / sk) * (k1[i].re() / sk);
            dny += (x[i].re() / sk) * (x[i].re() / sk);
        }
        let mut h = if dnf <= 1e-10 || dny <= 1e-10 {
            1e-6
        } else {
            libm::sqrt(dny / dnf) * 0.01
        };
        h = h.min(h_max);
        let x1 = combine(x, T::from_f64(dir * h), [(1.0, k1)]);
        let mut f1 = [T::zero(); S];
        stats.rhs_calls += 1;
        f(T::from_f64(t + dir * h), &x1, &mut f1)?;
        if !all_finite(&f1) {
            // Let the main loop shrink the step.
            return Ok(h);
        }
        let mut der2 = 0.0;
        for i in 0..S {
            let sk = self.scale(x[i].re(), 0.0);
            let d = (f1[i].re() - k1[i].re()) / sk;
            der2 += d * d;
        }
        let der2 = libm::sqrt(der2) / h;
        let der12 = der2.max(libm::sqrt(dnf));
        let h1 = if der12 <= 1e-15 {
            (h * 1e-3).max(1e-6)
        } else {
            libm::pow(0.01 / der12, 1.0 / 8.0)
        };
        Ok((100.0 * h).min(h1).min(h_max))
    }

    /// Stages 2 to 12 (`st.k[0]` holds stage 1); returns the new state.
    fn stages<T, F, const S: usize>(
        f: &mut F,
        t: f64,
        hs: f64,
        x: &[T; S],
        st: &mut Stages<T, S>,
    ) -> Result<[T; S], ModelError>
    where
        T: Scalar,
        F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
    {
        let hh = T::from_f64(hs);
        let tc = |c: f64| T::from_f64(t + c * hs);
        let k = &mut st.k;
        let y = combine(x, hh, [(A21, &k[0])]);
        f(tc(C2), &y, &mut k[1])?;
        let y = combine(x, hh, [(A31, &k[0]), (A32, &k[1])]);
        f(tc(C3), &y, &mut k[2])?;
        let y = combine(x, hh, [(A41, &k[0]), (A43, &k[2])]);
        f(tc(C4), &y, &mut k[3])?;
        let y = combine(x, hh, [(A51, &k[0]), (A53, &k[2]), (A54, &k[3])]);
        f(tc(C5), &y, &mut k[4])?;
        let y = combine(x, hh, [(A61, &k[0]), (A64, &k[3]), (A65, &k[4])]);
        f(tc(C6), &y, &mut k[5])?;
        let y = combine(
            x,
            hh,
            [(A71, &k[0]), (A74, &k[3]), (A75, &k[4]), (A76, &k[5])],
        );
        f(tc(C7), &y, &mut k[6])?;
        let y = combine(
            x,
            hh,
            [
                (A81, &k[0]),
                (A84, &k[3]),
                (A85, &k[4]),
                (A86, &k[5]),
                (A87, &k[6]),
            ],
        );
        f(tc(C8), &y, &mut k[7])?;
        let y = combine(
            x,
            hh,
            [
                (A91, &k[0]),
                (A94, &k[3]),
                (A95, &k[4]),
                (A96, &k[5]),
                (A97, &k[6]),
                (A98, &k[7]),
            ],
        );
        f(tc(C9), &y, &mut k[8])?;
        let y = combine(
            x,
            hh,
            [
                (A101, &k[0]),
                (A104, &k[3]),
                (A105, &k[4]),
                (A106, &k[5]),
                (A107, &k[6]),
                (A108, &k[7]),
                (A109, &k[8]),
            ],
        );
        f(tc(C10), &y, &mut k[9])?;
        let y = combine(
            x,
            hh,
            [
                (A111, &k[0]),
                (A114, &k[3]),
                (A115, &k[4]),
                (A116, &k[5]),
                (A117, &k[6]),
                (A118, &k[7]),
                (A119, &k[8]),
                (A1110, &k[9]),
            ],
        );
        f(tc(C11), &y, &mut k[10])?;
        let y = combine(
            x,
            hh,
            [
                (A121, &k[0]),
                (A124, &k[3]),
                (A125, &k[4]),
                (A126, &k[5]),
                (A127, &k[6]),
                (A128, &k[7]),
                (A129, &k[8]),
                (A1210, &k[9]),
                (A1211, &k[10]),
            ],
        );
        f(T::from_f64(t + hs), &y, &mut k[11])?;
        Ok(combine(
            x,
            hh,
            [
                (B1, &k[0]),
                (B6, &k[5]),
                (B7, &k[6]),
                (B8, &k[7]),
                (B9, &k[8]),
                (B10, &k[9]),
                (B11, &k[10]),
                (B12, &k[11]),
            ],
        ))
    }

    /// The combined 5th/3rd-order error norm of a step of size `hs`.
    fn error_norm<T: Scalar, const S: usize>(
        &self,
        hs: f64,
        x: &[T; S],
        x_new: &[T; S],
        k: &[[T; S]; 16],
    ) -> f64 {
        let (mut e5, mut e3) = (0.0, 0.0);
        for i in 0..S {
            let kr = |j: usize| k[j][i].re();
            let sk = self.scale(x[i].re(), x_new[i].re());
            let bsum = B1 * kr(0)
                + B6 * kr(5)
                + B7 * kr(6)
                + B8 * kr(7)
                + B9 * kr(8)
                + B10 * kr(9)
                + B11 * kr(10)
                + B12 * kr(11);
            let d3 = (bsum - BHH1 * kr(0) - BHH2 * kr(8) - BHH3 * kr(11)) / sk;
            let d5 = (ER1 * kr(0)
                + ER6 * kr(5)
                + ER7 * kr(6)
                + ER8 * kr(7)
                + ER9 * kr(8)
                + ER10 * kr(9)
                + ER11 * kr(10)
                + ER12 * kr(11))
                / sk;
            e3 += d3 * d3;
            e5 += d5 * d5;
        }
        if S == 0 {
            return 0.0;
        }
        let mut deno = e5 + 0.01 * e3;
        if deno <= 0.0 {
            deno = 1.0;
        }
        hs.abs() * e5 / libm::sqrt(S as f64 * deno)
    }

    /// The dense output of an accepted step (stages 1 to 13 in `st`): the
    /// three extra stages 14 to 16, then the polynomial coefficients.
    #[allow(clippy::too_many_arguments)]
    fn dense<T, F, const S: usize>(
        f: &mut F,
        t: f64,
        hs: f64,
        x: &[T; S],
        x_new: &[T; S],
        st: &mut Stages<T, S>,
        stats: &mut Stats,
    ) -> Result<Dense<T, S>, IntegrateError>
    where
        T: Scalar,
        F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
    {
        let hh = T::from_f64(hs);
        let k = &mut st.k;
        stats.rhs_calls += 3;
        let y = combine(
            x,
            hh,
            [
                (A141, &k[0]),
                (A147, &k[6]),
                (A148, &k[7]),
                (A149, &k[8]),
                (A1410, &k[9]),
                (A1411, &k[10]),
                (A1412, &k[11]),
                (A1413, &k[12]),
            ],
        );
        f(T::from_f64(t + C14 * hs), &y, &mut k[13])?;
        let y = combine(
            x,
            hh,
            [
                (A151, &k[0]),
                (A156, &k[5]),
                (A157, &k[6]),
                (A158, &k[7]),
                (A1511, &k[10]),
                (A1512, &k[11]),
                (A1513, &k[12]),
                (A1514, &k[13]),
            ],
        );
        f(T::from_f64(t + C15 * hs), &y, &mut k[14])?;
        let y = combine(
            x,
            hh,
            [
                (A161, &k[0]),
                (A166, &k[5]),
                (A167, &k[6]),
                (A168, &k[7]),
                (A169, &k[8]),
                (A1613, &k[12]),
                (A1614, &k[13]),
                (A1615, &k[14]),
            ],
        );
        f(T::from_f64(t + C16 * hs), &y, &mut k[15])?;
        if !(all_finite(&k[13]) && all_finite(&k[14]) && all_finite(&k[15])) {
            return Err(IntegrateError::NonFinite { t });
        }
        const STAGE: [usize; 12] = [0, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15];
        let mut r = [*x; 8];
        for i in 0..S {
            let ydiff = x_new[i] - x[i];
            let bspl = hh * k[0][i] - ydiff;
            r[1][i] = ydiff;
            r[2][i] = bspl;
            r[3][i] = ydiff - hh * k[12][i] - bspl;
            for (j, row) in D.iter().enumerate() {
                let mut acc = T::zero();
                for (w, &s) in row.iter().zip(STAGE.iter()) {
                    acc += T::from_f64(*w) * k[s][i];
                }
                r[4 + j][i] = hh * acc;
            }
        }
        Ok(Dense { t, h: hs, r })
    }

    /// The integration loop behind every `solve*`.
    fn run<T, F, K, const S: usize>(
        &self,
        mut f: F,
        t0: f64,
        x0: &[T; S],
        t_end: f64,
        sink: &mut K,
        mut event: Option<&mut EventFn<'_, T, S>>,
    ) -> Result<Solution<T, S>, IntegrateError>
    where
        T: Scalar,
        F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
        K: Sink<T, S>,
    {
        self.check_settings()?;
        if !t0.is_finite() || !t_end.is_finite() {
            return Err(IntegrateError::InvalidInput {
                what: "t0 and t_end must be finite",
            });
        }
        let dir = if t_end >= t0 { 1.0 } else { -1.0 };
        // Output times: finite, ordered, inside [t0, t_end].
        let n_out = sink.len();
        let mut prev = t0;
        for i in 0..n_out {
            let ti = sink.time(i);
            if !ti.is_finite() || (ti - prev) * dir < 0.0 || (ti - t_end) * dir > 0.0 {
                return Err(IntegrateError::InvalidInput {
                    what: "output times must be finite, ordered and within [t0, t_end]",
                });
            }
            prev = ti;
        }
        if !all_finite(x0) {
            return Err(IntegrateError::NonFinite { t: t0 });
        }

        let mut stats = Stats::default();
        let mut t = t0;
        let mut x = *x0;
        let mut next_out = 0;
        while next_out < n_out && sink.time(next_out) == t0 {
            sink.put(next_out, &x);
            next_out += 1;
        }
        let mut g_old = match event.as_mut() {
            Some(g) => {
                let v = g(t, &x);
                if !v.is_finite() {
                    return Err(IntegrateError::NonFinite { t });
                }
                v
            }
            None => 0.0,
        };
        let finish = |t, x, stats, event, outputs, h_next| {
            Ok(Solution {
                t,
                x,
                stats,
                event,
                outputs,
                h_next,
            })
        };
        if t_end == t0 {
            return finish(t, x, stats, false, next_out, 0.0);
        }

        let mut st = Stages {
            k: [[T::zero(); S]; 16],
        };
        stats.rhs_calls += 1;
        f(T::from_f64(t), &x, &mut st.k[0])?;
        if !all_finite(&st.k[0]) {
            return Err(IntegrateError::NonFinite { t });
        }
        let span = (t_end - t0).abs();
        let h_max = if self.adaptive {
            self.h_max.unwrap_or(f64::INFINITY).min(span)
        } else {
            span
        };
        let mut h = match self.h_init {
            Some(h) => h.abs().min(h_max),
            None => self.initial_step(&mut f, t, &x, &st.k[0], dir, h_max, &mut stats)?,
        };
        let h_fixed = h;
        let expo1 = 0.125 - 0.2 * self.beta;
        let mut fac_old: f64 = 1e-4;
        let mut last_rejected = false;
        let mut steps = 0usize;

        loop {
            if steps >= self.max_steps {
                return Err(IntegrateError::TooManySteps { t, steps });
            }
            let h_floor = self
                .h_min
                .max(16.0 * f64::EPSILON * t.abs())
                .max(f64::MIN_POSITIVE);
            let remaining = (t_end - t).abs();
            let last = 1.01 * h >= remaining;
            if !last && h < h_floor {
                return Err(IntegrateError::StepSizeTooSmall { t, h });
            }
            if last {
                h = remaining;
            }
            steps += 1;
            let hs = dir * h;
            let t_new = if last { t_end } else { t + hs };

            // Stages 2..12, then the FSAL stage 13 at the new state.
            stats.rhs_calls += 11;
            let x_new = Self::stages(&mut f, t, hs, &x, &mut st)?;
            let mut finite = all_finite(&x_new);
            let err = if self.adaptive {
                self.error_norm(hs, &x, &x_new, &st.k)
            } else {
                0.0
            };
            finite &= err.is_finite();
            if finite && err <= 1.0 {
                stats.rhs_calls += 1;
                f(T::from_f64(t_new), &x_new, &mut st.k[12])?;
                finite &= all_finite(&st.k[12]);
            }
            if !finite {
                // A non-finite stage: retry with a much smaller step.
                stats.rejected += 1;
                last_rejected = true;
                h *= FAC_NON_FINITE;
                if !self.adaptive || h < h_floor {
                    return Err(IntegrateError::NonFinite { t });
                }
                continue;
            }

            let fac11 = libm::pow(err, expo1);
            if err <= 1.0 {
                // Accepted.
                stats.accepted += 1;
                let mut h_new = if self.adaptive {
                    let fac = fac11 / libm::pow(fac_old, self.beta);
                    let fac = (fac / SAFETY).clamp(1.0 / FAC_MAX, 1.0 / FAC_MIN);
                    fac_old = err.max(1e-4);
                    h / fac
                } else {
                    h_fixed
                };
                if last_rejected {
                    h_new = h_new.min(h);
                }
                last_rejected = false;

                // Event at the end of the step.
                let mut crossed = false;
                let mut g_new = 0.0;
                if let Some(g) = event.as_mut() {
                    g_new = g(t_new, &x_new);
                    if !g_new.is_finite() {
                        return Err(IntegrateError::NonFinite { t });
                    }
                    crossed = g_old != 0.0 && (g_new == 0.0 || (g_new > 0.0) != (g_old > 0.0));
                }
                let need_dense = (crossed && g_new != 0.0)
                    || (next_out < n_out && (sink.time(next_out) - t_new) * dir < 0.0);
                let dense = if need_dense {
                    Some(Self::dense(&mut f, t, hs, &x, &x_new, &mut st, &mut stats)?)
                } else {
                    None
                };

                let mut stop: Option<(f64, [T; S])> = None;
                if crossed {
                    if let (Some(g), Some(d)) = (event.as_mut(), dense.as_ref()) {
                        stop = Some(self.locate(&mut **g, d, t, g_old, t_new, g_new, &x_new)?);
                    } else {
                        // g is exactly zero at the end of the step.
                        stop = Some((t_new, x_new));
                    }
                }
                g_old = g_new;

                // Outputs up to the end of the step (or the event).
                let t_stop = stop.as_ref().map_or(t_new, |s| s.0);
                while next_out < n_out && (sink.time(next_out) - t_stop) * dir <= 0.0 {
                    let to = sink.time(next_out);
                    let xo = match dense.as_ref() {
                        Some(d) if to != t_new => d.at(to),
                        _ => x_new,
                    };
                    if !all_finite(&xo) {
                        return Err(IntegrateError::NonFinite { t });
                    }
                    sink.put(next_out, &xo);
                    next_out += 1;
                }
                let h_next = if self.adaptive {
                    h_new.min(h_max)
                } else {
                    h_fixed
                };
                if let Some((te, xe)) = stop {
                    return finish(te, xe, stats, true, next_out, h_next);
                }

                t = t_new;
                x = x_new;
                st.k[0] = st.k[12];
                h = h_next;
                if last {
                    return finish(t, x, stats, false, next_out, h);
                }
            } else {
                // Rejected.
                stats.rejected += 1;
                last_rejected = true;
                h /= (fac11 / SAFETY).min(1.0 / FAC_MIN);
            }
        }
    }

    /// Illinois root finding of `g` on the dense output over `[a, b]` (in
    /// the direction of integration), `g(a) = ga`, `g(b) = gb` of opposite
    /// signs or `gb = 0`. Returns the far end of the final bracket.
    #[allow(clippy::too_many_arguments)]
    fn locate<T: Scalar, const S: usize>(
        &self,
        g: &mut dyn FnMut(f64, &[T; S]) -> f64,
        dense: &Dense<T, S>,
        a: f64,
        ga: f64,
        b: f64,
        gb: f64,
        xb: &[T; S],
    ) -> Result<(f64, [T; S]), IntegrateError> {
        let (mut lo, mut glo) = (a, ga);
        let (mut hi, mut ghi, mut xhi) = (b, gb, *xb);
        if ghi == 0.0 {
            return Ok((hi, xhi));
        }
        let mut side = 0i8;
        for _ in 0..EVENT_MAX_ITER {
            let tol = self
                .event_tol
                .max(4.0 * f64::EPSILON * lo.abs().max(hi.abs()));
            if (hi - lo).abs() <= tol {
                break;
            }
            let mut tc = (lo * ghi - hi * glo) / (ghi - glo);
            let (mn, mx) = (lo.min(hi), lo.max(hi));
            if !(tc > mn && tc < mx) {
                tc = 0.5 * (lo + hi);
                if !(tc > mn && tc < mx) {
                    break;
                }
            }
            let xc = dense.at(tc);
            let gc = g(tc, &xc);
            if !gc.is_finite() {
                return Err(IntegrateError::NonFinite { t: tc });
            }
            if gc == 0.0 {
                return Ok((tc, xc));
            }
            if (gc > 0.0) == (ghi > 0.0) {
                hi = tc;
                ghi = gc;
                xhi = xc;
                if side == -1 {
                    glo *= 0.5;
                }
                side = -1;
            } else {
                lo = tc;
                glo = gc;
                if side == 1 {
                    ghi *= 0.5;
                }
                side = 1;
            }
        }
        Ok((hi, xhi))
    }
}
