//! Pictures of the motion: a self-contained SVG that plays a simulated
//! trajectory (SMIL animation, no script), drawn from the model's own
//! geometry.
//!
//! [`simulate`] integrates every coordinate (cyclic ones included, with
//! q̇ from [`Model::driven_coordinate_rates`](appell_core::Model::driven_coordinate_rates), so a driven coordinate moves
//! at its commanded rate) and returns evenly spaced
//! [`Frame`]s; [`svg`] draws them. Each rigid body is its equivalent
//! inertia ellipsoid (the uniform solid ellipsoid with the body's mass and
//! central inertia: a thin disc shows as a disc, a rod as a cigar) with a
//! spoke along its longest axis so that a spin shows, each particle a dot,
//! each rolling contact's path a track on the ground, under a ground grid
//! and a time readout. [`line_plot`] draws curves, such as eigenvalues
//! against a parameter. A model with contacts is watched frame by frame
//! ([`appell_integrate::contact_watch`]): a disc that falls flat stops the picture
//! where it would go through the floor.
//!
//! ```
//! use appell_tools::animate::{simulate, svg, SvgOptions};
//! # use appell_core::{check_len, BodyInfo, Model, ModelError, ModelInfo, OpCounts, Scalar};
//! # /// A particle on a light rod (the pendulum of the `Model` docs).
//! # struct Pendulum;
//! # static INFO: ModelInfo = ModelInfo {
//! #     name: "Pendulum", parameters: &[], coordinates: &["q"], speeds: &["q"],
//! #     dependent: &[], cyclic: &[], ignorable: &[], retained: &["q"], inputs: &[],
//! #     effects: &["gravity"], outputs: &[], row_sources: &[], contacts: &[], holonomic: 0,
//! #     constraints: 0, bodies: &[BodyInfo { name: "P", rigid: false }], force_points: 1,
//! #     torques: 0, form: "closed form", symbolic_elimination: true,
//! #     rhs_ops: OpCounts { add: 0, mul: 1, div: 0, calls: 1, total: 2 }, jacobian: None, equations: "",
//! # };
//! # impl Model for Pendulum {
//! #     type Prepared<T: Scalar> = ();
//! #     fn info() -> &'static ModelInfo { &INFO }
//! #     fn parameter_values(&self, _: &mut [f64]) -> Result<(), ModelError> { Ok(()) }
//! #     fn set_parameter(&mut self, _: &str, _: f64) -> bool { false }
//! #     fn prepare<T: Scalar>(&self) {}
//! #     fn rhs<T: Scalar>(&self, _: &(), _: T, s: &[T], _: &[T], d: &mut [T]) -> Result<(), ModelError> {
//! #         d[0] = s[1]; d[1] = -T::from_f64(9.81) * s[0].sin(); Ok(())
//! #     }
//! #     fn mass_matrix_and_forcing<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { Ok(()) }
//! #     fn speed_transform<T: Scalar>(&self, _: T, _: &[T], c: &mut [T], c0: &mut [T]) -> Result<(), ModelError> { c[0] = T::one(); c0[0] = T::zero(); Ok(()) }
//! #     fn coordinate_rates<T: Scalar>(&self, _: T, _: &[T], u: &[T], qd: &mut [T]) -> Result<(), ModelError> { qd[0] = u[0]; Ok(()) }
//! #     fn constraint_residuals<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { Ok(()) }
//! #     fn kinetic_energy<T: Scalar>(&self, _: T, _: &[T], u: &[T]) -> Result<T, ModelError> { Ok(u[0] * u[0] * T::from_f64(0.5)) }
//! #     fn mass_properties(&self, m: &mut [f64], i: &mut [[f64; 9]]) -> Result<(), ModelError> { m[0] = 1.0; i[0] = [0.0; 9]; Ok(()) }
//! #     fn body_poses<T: Scalar>(&self, _: T, q: &[T], p: &mut [[T; 3]], r: &mut [[T; 9]]) -> Result<(), ModelError> {
//! #         p[0] = [q[0].sin(), -q[0].cos(), T::zero()];
//! #         let (o, z) = (T::one(), T::zero());
//! #         r[0] = [o, z, z, z, o, z, z, z, o]; Ok(())
//! #     }
//! #     fn constraint_rows<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { Ok(()) }
//! #     fn load_geometry<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { Ok(()) }
//! #     fn load_values<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [[T; 3]], _: &mut [[T; 3]]) -> Result<(), ModelError> { Ok(()) }
//! # }
//! // Two seconds of a pendulum released at 1 rad, 41 frames.
//! let frames = simulate(&Pendulum, 0.0, &[1.0], &[0.0], &[], 2.0, 40).unwrap();
//! assert_eq!(frames.len(), 41);
//! assert!((frames[40].t - 2.0).abs() < 1e-12);
//! let picture = svg(&Pendulum, &frames, &SvgOptions::default()).unwrap();
//! assert!(picture.starts_with("<svg") && picture.contains("<animateTransform"));
//! ```

mod draw;
mod geometry;
mod plot;

pub use draw::{svg, SvgOptions, View};
pub use plot::{line_plot, Curve};

use appell_core::dynamic::{DynModel, DynRhs};
use appell_core::{check_len, ModelError};
pub use appell_dynamics::motion::Frame;
use appell_integrate::contact_watch::ContactWatch;

/// The largest step [`simulate`] takes.
pub const MAX_STEP: f64 = 1e-3;

/// How many RK4 steps [`simulate`] takes from `t0` to `t_end` in `frames`
/// frames: whole steps of at most [`MAX_STEP`] per frame, at least one.
/// A float, so that a huge span is counted without overflow (to check it
/// against a budget before starting).
pub fn steps_needed(t0: f64, t_end: f64, frames: usize) -> f64 {
    let per_frame = (t_end - t0) / frames as f64;
    frames as f64 * (per_frame / MAX_STEP).ceil().max(1.0)
}

/// Simulates the model from every coordinate `q0` and the privileged
/// speeds `u0`, with `inputs` held, from `t0` to `t_end`, and returns
/// `frames + 1` frames evenly spaced in time (the first at `t0`).
///
/// Fourth-order Runge–Kutta on the full coordinates (q̇ from
/// [`Model::coordinate_rates`](appell_core::Model::coordinate_rates), u̇ from [`Model::rhs`](appell_core::Model::rhs)), at most
/// [`MAX_STEP`] per step ([`steps_needed`] steps in all): accurate enough
/// for a picture, not a reference (use the adaptive integrators for that).
///
/// A model with `rolls` contacts is checked by a stopping
/// [`ContactWatch`] at the start and at every frame: where a contact's
/// normal force turns negative or the body leaves the region where the
/// model holds (a disc past lean ±π/2) the simulation ends with
/// [`ModelError::ContactLost`] naming the contact
/// ([`simulate_watched`] takes a watch of one's own, one that warns).
///
/// Errors: wrong lengths, `frames == 0`, a non-finite argument or
/// `t_end <= t0` (as [`ModelError::NonFinite`] naming it), a contact lost,
/// and any error of the model along the way (a singular configuration
/// reached).
pub fn simulate<K: DynModel + ?Sized>(
    model: &K,
    t0: f64,
    q0: &[f64],
    u0: &[f64],
    inputs: &[f64],
    t_end: f64,
    frames: usize,
) -> Result<Vec<Frame>, ModelError> {
    let mut watch = ContactWatch::new(model).inputs(inputs);
    simulate_watched(model, t0, q0, u0, inputs, t_end, frames, &mut watch)
}

/// [`simulate`] with the contacts checked by `watch` at the start and at
/// every frame: a warning watch records the contacts lost in its
/// [`ContactWatch::events`] and the simulation goes on. The watch should
/// have the same `inputs`.
///
/// ```
/// # use appell_core::__doc_model::Oscillator;
/// use appell_tools::animate::simulate_watched;
/// use appell_integrate::contact_watch::ContactWatch;
///
/// // A free particle has no contacts: every frame is checked, nothing found.
/// let free = Oscillator { w: 0.0 }; // x'' = 0
/// let mut watch = ContactWatch::new(&free).warn();
/// let frames = simulate_watched(&free, 0.0, &[0.0], &[1.0], &[], 1.0, 10, &mut watch).unwrap();
/// assert_eq!(frames.len(), 11);
/// assert_eq!(watch.checks, 11);
/// assert!(watch.events.is_empty());
/// ```
#[allow(clippy::too_many_arguments)] // simulate's arguments and the watch
pub fn simulate_watched<K: DynModel + ?Sized>(
    model: &K,
    t0: f64,
    q0: &[f64],
    u0: &[f64],
    inputs: &[f64],
    t_end: f64,
    frames: usize,
    watch: &mut ContactWatch<'_, K>,
) -> Result<Vec<Frame>, ModelError> {
    run(
        model,
        t0,
        q0,
        u0,
        inputs,
        t_end,
        frames,
        watch,
        &mut |_, _| {},
    )
}

/// [`simulate`], calling `progress(done, frames)` after each frame (for a
/// progress bar on a long run).
#[allow(clippy::too_many_arguments)] // simulate's arguments and the callback
pub fn simulate_with_progress<K: DynModel + ?Sized>(
    model: &K,
    t0: f64,
    q0: &[f64],
    u0: &[f64],
    inputs: &[f64],
    t_end: f64,
    frames: usize,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Vec<Frame>, ModelError> {
    let mut watch = ContactWatch::new(model).inputs(inputs);
    run(
        model, t0, q0, u0, inputs, t_end, frames, &mut watch, progress,
    )
}

/// The simulation itself: RK4 steps, the watch and `progress` at every
/// frame.
#[allow(clippy::too_many_arguments)] // simulate's arguments, the watch and the callback
fn run<K: DynModel + ?Sized>(
    model: &K,
    t0: f64,
    q0: &[f64],
    u0: &[f64],
    inputs: &[f64],
    t_end: f64,
    frames: usize,
    watch: &mut ContactWatch<'_, K>,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Vec<Frame>, ModelError> {
    let info = model.dyn_info();
    let (n, l) = (info.coordinates.len(), info.speeds.len());
    check_len("q", q0, n)?;
    check_len("u", u0, l)?;
    check_len("inputs", inputs, info.inputs.len())?;
    let finite = |x: &[f64]| x.iter().all(|v| v.is_finite());
    if !(finite(q0) && finite(u0) && finite(inputs)) {
        return Err(ModelError::NonFinite {
            what: "initial state or inputs",
        });
    }
    if frames == 0 || !(t0.is_finite() && t_end.is_finite() && t_end > t0) {
        return Err(ModelError::NonFinite {
            what: "the time span (t_end after t0) or the frame count (at least 1)",
        });
    }
    let rates = FullRates::new(model, inputs)?;
    let per_frame = (t_end - t0) / frames as f64;
    let steps = (per_frame / MAX_STEP).ceil().max(1.0) as usize;
    let h = per_frame / steps as f64;
    let mut x: Vec<f64> = q0.iter().chain(u0).copied().collect();
    watch.check_motion(t0, q0, u0)?;
    let mut out = Vec::with_capacity(frames + 1);
    out.push(Frame {
        t: t0,
        q: q0.to_vec(),
    });
    for k in 0..frames {
        let start = t0 + k as f64 * per_frame;
        for s in 0..steps {
            x = rates.rk4_step(start + s as f64 * h, h, &x)?;
        }
        let t = t0 + (k + 1) as f64 * per_frame;
        watch.check_motion(t, &x[..n], &x[n..])?;
        out.push(Frame {
            t,
            q: x[..n].to_vec(),
        });
        progress(k + 1, frames);
    }
    Ok(out)
}

/// q̇ and u̇ of the full state x = (q, u), the model prepared once.
struct FullRates<'m, K: DynModel + ?Sized> {
    model: &'m K,
    rhs: Box<dyn DynRhs + 'm>,
    inputs: &'m [f64],
    retained: Vec<usize>,
    n: usize,
}

impl<'m, K: DynModel + ?Sized> FullRates<'m, K> {
    fn new(model: &'m K, inputs: &'m [f64]) -> Result<Self, ModelError> {
        let info = model.dyn_info();
        let retained = info
            .retained
            .iter()
            .map(|name| {
                info.coordinate_index(name).ok_or(ModelError::NonFinite {
                    what: "a retained coordinate not among the coordinates",
                })
            })
            .collect::<Result<_, _>>()?;
        Ok(FullRates {
            model,
            rhs: model.dyn_prepare(),
            inputs,
            retained,
            n: info.coordinates.len(),
        })
    }

    fn rates(&self, t: f64, x: &[f64]) -> Result<Vec<f64>, ModelError> {
        let (q, u) = x.split_at(self.n);
        let mut state: Vec<f64> = self.retained.iter().map(|&i| q[i]).collect();
        state.extend_from_slice(u);
        let mut dstate = vec![0.0; state.len()];
        self.rhs.rhs(t, &state, self.inputs, &mut dstate)?;
        let mut dx = vec![0.0; x.len()];
        self.model
            .dyn_driven_coordinate_rates(t, q, u, self.inputs, &mut dx[..self.n])?;
        dx[self.n..].copy_from_slice(&dstate[self.retained.len()..]);
        Ok(dx)
    }

    fn rk4_step(&self, t: f64, h: f64, x: &[f64]) -> Result<Vec<f64>, ModelError> {
        let along = |x: &[f64], k: &[f64], c: f64| -> Vec<f64> {
            x.iter().zip(k).map(|(a, b)| a + c * b).collect()
        };
        let k1 = self.rates(t, x)?;
        let k2 = self.rates(t + h / 2.0, &along(x, &k1, h / 2.0))?;
        let k3 = self.rates(t + h / 2.0, &along(x, &k2, h / 2.0))?;
        let k4 = self.rates(t + h, &along(x, &k3, h))?;
        let next: Vec<f64> = (0..x.len())
            .map(|i| x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
            .collect();
        if next.iter().all(|v| v.is_finite()) {
            Ok(next)
        } else {
            Err(ModelError::NonFinite { what: "state" })
        }
    }
}
