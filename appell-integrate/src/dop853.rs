//! Adaptive Dormand–Prince 8(5,3) integration (`DOP853`) with dense output of
//! order 7 and event location, on fixed-size arrays and without allocation.

// The coefficients are kept with the digits they are published with.
#![allow(clippy::excessive_precision)]

use super::check_model;
use super::explicit::{
    self, all_finite, CallbackSink, DenseOutput, EmbeddedPair, Settings, Sink, SliceSink,
};
use super::solution::{EventFn, IntegrateError, ProjectFn, Solution, Stats};
use appell_core::Scalar;
use appell_core::{Model, ModelError};

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
/// use appell_integrate::Dop853;
/// use appell_core::ModelError;
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
#[derive(Clone, Copy, PartialEq)]
pub struct Dop853 {
    set: Settings,
}

impl core::fmt::Debug for Dop853 {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        self.set.debug("Dop853", f)
    }
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

/// Smallest factor `h_new / h`.
const FAC_MIN: f64 = 1.0 / 3.0;
/// Largest factor `h_new / h`.
const FAC_MAX: f64 = 6.0;

/// The extra stages 14 to 16 of the dense output: the node, and the weights
/// with the (0-based) stages they multiply.
const EXTRA: [(f64, [(f64, usize); 8]); 3] = [
    (
        C14,
        [
            (A141, 0),
            (A147, 6),
            (A148, 7),
            (A149, 8),
            (A1410, 9),
            (A1411, 10),
            (A1412, 11),
            (A1413, 12),
        ],
    ),
    (
        C15,
        [
            (A151, 0),
            (A156, 5),
            (A157, 6),
            (A158, 7),
            (A1511, 10),
            (A1512, 11),
            (A1513, 12),
            (A1514, 13),
        ],
    ),
    (
        C16,
        [
            (A161, 0),
            (A166, 5),
            (A167, 6),
            (A168, 7),
            (A169, 8),
            (A1613, 12),
            (A1614, 13),
            (A1615, 14),
        ],
    ),
];

/// The continuous extension (order 7) of one accepted step.
struct Dense<T, const S: usize> {
    t: f64,
    h: f64,
    r: [[T; S]; 8],
}

impl<T: Scalar, const S: usize> DenseOutput<T, S> for Dense<T, S> {
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

impl<T: Scalar, const S: usize> EmbeddedPair<T, S> for Stages<T, S> {
    const EXPO: f64 = 1.0 / 8.0;
    const BETA_WEIGHT: f64 = 0.2;
    const FAC_MIN: f64 = FAC_MIN;
    const FAC_MAX: f64 = FAC_MAX;
    const BETA_CLOSED: bool = true;
    type Dense = Dense<T, S>;

    fn new(k1: [T; S]) -> Self {
        let mut k = [[T::zero(); S]; 16];
        k[0] = k1;
        Stages { k }
    }

    fn k1(&self) -> &[T; S] {
        &self.k[0]
    }

    /// Stages 2 to 12, then the FSAL stage 13 at the new state only when
    /// the step is accepted (a rejected step costs 11 rhs calls).
    #[inline]
    fn step<F>(
        &mut self,
        f: &mut F,
        set: &Settings,
        t: f64,
        hs: f64,
        t_new: f64,
        x: &[T; S],
        stats: &mut Stats,
    ) -> Result<Option<([T; S], f64)>, ModelError>
    where
        F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
    {
        stats.rhs_calls += 11;
        let x_new = stages(f, t, hs, x, &mut self.k)?;
        let mut finite = all_finite(&x_new);
        let err = if set.adaptive {
            error_norm(set, hs, x, &x_new, &self.k)
        } else {
            0.0
        };
        finite &= err.is_finite();
        if finite && err <= 1.0 {
            stats.rhs_calls += 1;
            f(T::from_f64(t_new), &x_new, &mut self.k[12])?;
            finite &= all_finite(&self.k[12]);
        }
        Ok(if finite { Some((x_new, err)) } else { None })
    }

    fn accept(&mut self) {
        self.k[0] = self.k[12];
    }

    /// The dense output of an accepted step (stages 1 to 13): the three
    /// extra stages 14 to 16, then the polynomial coefficients.
    fn dense<F>(
        &mut self,
        f: &mut F,
        t: f64,
        hs: f64,
        x: &[T; S],
        x_new: &[T; S],
        stats: &mut Stats,
    ) -> Result<Dense<T, S>, IntegrateError>
    where
        F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
    {
        let hh = T::from_f64(hs);
        let k = &mut self.k;
        stats.rhs_calls += 3;
        for (j, (c, w)) in EXTRA.iter().enumerate() {
            let y = combine(x, hh, w.map(|(a, s)| (a, &k[s])));
            f(T::from_f64(t + c * hs), &y, &mut k[13 + j])?;
        }
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
}

/// Stages 2 to 12 (`k[0]` holds stage 1); returns the new state.
fn stages<T, F, const S: usize>(
    f: &mut F,
    t: f64,
    hs: f64,
    x: &[T; S],
    k: &mut [[T; S]; 16],
) -> Result<[T; S], ModelError>
where
    T: Scalar,
    F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
{
    let hh = T::from_f64(hs);
    let tc = |c: f64| T::from_f64(t + c * hs);
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
    set: &Settings,
    hs: f64,
    x: &[T; S],
    x_new: &[T; S],
    k: &[[T; S]; 16],
) -> f64 {
    let (mut e5, mut e3) = (0.0, 0.0);
    for i in 0..S {
        let kr = |j: usize| k[j][i].re();
        let sk = set.scale(x[i].re(), x_new[i].re());
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
    hs.abs() * e5 / explicit::sqrt(S as f64 * deno)
}

impl Dop853 {
    /// The integrator with the documented defaults ([`Dop853`]).
    pub const fn new() -> Self {
        Dop853 {
            set: Settings::new(0.0),
        }
    }

    /// The first step size (magnitude), or `None` (default) for Hairer's
    /// automatic choice. With [`Dop853::adaptive`]`(false)` it is the size
    /// of every step and must be given.
    pub const fn h_init(mut self, h_init: Option<f64>) -> Self {
        self.set.h_init = h_init;
        self
    }

    /// The controller's β (default `0`, the elementary controller of
    /// `DOP853`; must be in `[0, 0.2]`).
    pub const fn beta(mut self, beta: f64) -> Self {
        self.set.beta = beta;
        self
    }

    explicit::explicit_api!(Dop853, Stages);
}
