//! What accuracy costs: work–precision sweeps of the integrators over a
//! derived model, against a reference solution computed far more
//! accurately.
//!
//! [`Problem::sweep`] runs each [`Method`] at each of its settings (a step count for
//! the fixed-step methods, a tolerance for the adaptive one), measures the
//! error at the final time and the largest error at evenly spaced
//! checkpoints, and the wall time (median of repeated runs).
//! [`Problem::reference`] computes the reference with DOP853 at a tight
//! tolerance and checks it against a second run ten times looser (the
//! difference bounds the reference's own error).

use std::time::Instant;

use appell_core::dynamic::{DynRhs, Prepared};
use appell_core::{Model, ModelError};
use appell_integrate::{
    heun_step_fn, midpoint_step_fn, rk4_step_fn, Dop853, Dopri5, IntegrateError, Radau5, TrBdf2,
};

/// An integrator and its setting.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method {
    /// Classical RK4 with this many fixed steps.
    Rk4(usize),
    /// Heun (explicit trapezoid) with this many fixed steps.
    Heun(usize),
    /// Explicit midpoint with this many fixed steps.
    Midpoint(usize),
    /// Dormand–Prince 5(4) with this relative tolerance (absolute = relative
    /// × 1e-2).
    Dopri5(f64),
    /// DOP853 (Dormand–Prince 8(5,3)) with this relative tolerance
    /// (absolute = relative × 1e-2).
    Dop853(f64),
    /// TR-BDF2 (implicit, L-stable, order 2, Jacobian by dual numbers) with
    /// this relative tolerance (absolute = relative × 1e-2). Its rhs count
    /// includes the dual-number evaluations of the Jacobians.
    TrBdf2(f64),
    /// Radau IIA of order 5 (RADAU5: implicit, L-stable, Jacobian by dual
    /// numbers, reused across steps) with this relative tolerance (absolute
    /// = relative × 1e-2). Its rhs count includes the Jacobians'.
    Radau5(f64),
}

impl Method {
    /// The method's name.
    pub fn name(&self) -> &'static str {
        match self {
            Method::Rk4(_) => "rk4",
            Method::Heun(_) => "heun",
            Method::Midpoint(_) => "midpoint",
            Method::Dopri5(_) => "dopri5",
            Method::Dop853(_) => "dop853",
            Method::TrBdf2(_) => "trbdf2",
            Method::Radau5(_) => "radau5",
        }
    }

    /// The setting as a number (steps, or tolerance).
    pub fn setting(&self) -> f64 {
        match *self {
            Method::Rk4(n) | Method::Heun(n) | Method::Midpoint(n) => n as f64,
            Method::Dopri5(tol)
            | Method::Dop853(tol)
            | Method::TrBdf2(tol)
            | Method::Radau5(tol) => tol,
        }
    }
}

/// One point of a work–precision chart.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// The method.
    pub method: Method,
    /// Largest relative error (per component, relative to 1 + |reference|)
    /// at the final time.
    pub error_final: f64,
    /// The same, largest over the checkpoints.
    pub error_max: f64,
    /// Median wall time of one integration, in seconds.
    pub seconds: f64,
    /// Right-hand-side evaluations of one integration.
    pub rhs_calls: u64,
    /// Steps of one integration (accepted and rejected).
    pub steps: u64,
}

/// An initial-value problem on a derived model: from `x0` at t = 0 to
/// `t_end`, errors measured at `checkpoints` evenly spaced times.
#[derive(Clone, Copy, Debug)]
pub struct Problem<'a, M: Model, const S: usize> {
    /// The model.
    pub model: &'a M,
    /// The initial reduced state.
    pub x0: [f64; S],
    /// The horizon, in seconds.
    pub t_end: f64,
    /// Constant inputs.
    pub inputs: &'a [f64],
    /// How many evenly spaced checkpoints the errors are measured at.
    pub checkpoints: usize,
}

impl<M: Model, const S: usize> Problem<'_, M, S> {
    /// The reference states at the checkpoints `t_end · k / checkpoints`
    /// (k = 1..=checkpoints), by DOP853 at rtol 1e-15, and an estimate of
    /// their error (the largest relative difference from a run at rtol
    /// 1e-14).
    #[allow(clippy::type_complexity)] // (states at the checkpoints, error estimate)
    pub fn reference(&self) -> Result<(Vec<[f64; S]>, f64), IntegrateError> {
        self.run().reference(&Prepared::new(self.model))
    }

    /// Runs every method against `reference`; the wall time is the median
    /// of `repeats` runs; `progress(done, total)` is called before each
    /// method. Methods that fail (a step size underflow, say) are skipped,
    /// so a sweep returns what it could measure.
    pub fn sweep(
        &self,
        reference: &[[f64; S]],
        methods: &[Method],
        repeats: usize,
        progress: impl FnMut(usize, usize),
    ) -> Vec<Point> {
        self.run().sweep(
            &Prepared::new(self.model),
            reference,
            methods,
            repeats,
            progress,
        )
    }

    fn run(&self) -> Run<'_, S> {
        Run {
            x0: self.x0,
            t_end: self.t_end,
            inputs: self.inputs,
            checkpoints: self.checkpoints,
        }
    }
}

/// A [`Problem`] without its model: what [`Problem::reference`] and
/// [`Problem::sweep`] run on a prepared rhs (the command line's sweep runs
/// it on a `dyn DynRhs`, compiled once).
pub(crate) struct Run<'a, const S: usize> {
    pub(crate) x0: [f64; S],
    pub(crate) t_end: f64,
    pub(crate) inputs: &'a [f64],
    pub(crate) checkpoints: usize,
}

impl<const S: usize> Run<'_, S> {
    /// [`Problem::reference`].
    #[allow(clippy::type_complexity)] // (states at the checkpoints, error estimate)
    pub(crate) fn reference<R: DynRhs + ?Sized>(
        &self,
        rhs: &R,
    ) -> Result<(Vec<[f64; S]>, f64), IntegrateError> {
        let tight = integrate(rhs, self, Method::Dop853(1e-15))?.0;
        let loose = integrate(rhs, self, Method::Dop853(1e-14))?.0;
        let estimate = tight
            .iter()
            .zip(&loose)
            .map(|(a, b)| relative_error(a, b))
            .fold(0.0, f64::max);
        Ok((tight, estimate))
    }

    /// [`Problem::sweep`].
    pub(crate) fn sweep<R: DynRhs + ?Sized>(
        &self,
        rhs: &R,
        reference: &[[f64; S]],
        methods: &[Method],
        repeats: usize,
        mut progress: impl FnMut(usize, usize),
    ) -> Vec<Point> {
        let mut points = Vec::with_capacity(methods.len());
        for (i, &method) in methods.iter().enumerate() {
            progress(i, methods.len());
            let Ok((states, rhs_calls, steps)) = integrate(rhs, self, method) else {
                continue;
            };
            let mut times = Vec::with_capacity(repeats.max(1));
            for _ in 0..repeats.max(1) {
                let start = Instant::now();
                let r = integrate(rhs, self, method);
                times.push(start.elapsed().as_secs_f64());
                std::hint::black_box(r.ok());
            }
            times.sort_by(f64::total_cmp);
            let errors: Vec<f64> = states
                .iter()
                .zip(reference)
                .map(|(x, r)| relative_error(x, r))
                .collect();
            points.push(Point {
                method,
                error_final: *errors.last().unwrap_or(&f64::NAN),
                error_max: errors.iter().copied().fold(0.0, f64::max),
                seconds: times[times.len() / 2],
                rhs_calls,
                steps,
            });
        }
        progress(methods.len(), methods.len());
        points
    }
}

fn relative_error<const S: usize>(x: &[f64; S], reference: &[f64; S]) -> f64 {
    x.iter()
        .zip(reference)
        .map(|(a, b)| (a - b).abs() / (1.0 + b.abs()))
        .fold(0.0, f64::max)
}

/// One integration with `method`: the states at the checkpoints, the number
/// of rhs calls and the number of steps.
fn integrate<R: DynRhs + ?Sized, const S: usize>(
    rhs: &R,
    pb: &Run<'_, S>,
    method: Method,
) -> Result<(Vec<[f64; S]>, u64, u64), IntegrateError> {
    let (inputs, checkpoints, t_end) = (pb.inputs, pb.checkpoints.max(1), pb.t_end);
    let expected = rhs.state_len();
    if S != expected {
        return Err(ModelError::Length {
            argument: "state",
            expected,
            found: S,
        }
        .into());
    }
    let mut f = |t: f64, x: &[f64; S], dx: &mut [f64; S]| rhs.rhs(t, x, inputs, dx);
    match method {
        Method::Dopri5(tol) | Method::Dop853(tol) => {
            let mut out: Vec<(f64, [f64; S])> = (1..=checkpoints)
                .map(|k| (t_end * k as f64 / checkpoints as f64, [0.0; S]))
                .collect();
            let (rtol, atol, max_steps) = (tol, tol * 1e-2, 10_000_000);
            let stats = if let Method::Dopri5(_) = method {
                let solver = Dopri5::new().rtol(rtol).atol(atol).max_steps(max_steps);
                solver.solve_at(f, 0.0, &pb.x0, &mut out)?.stats
            } else {
                let solver = Dop853::new().rtol(rtol).atol(atol).max_steps(max_steps);
                solver.solve_at(f, 0.0, &pb.x0, &mut out)?.stats
            };
            Ok((
                out.into_iter().map(|(_, x)| x).collect(),
                stats.rhs_calls as u64,
                (stats.accepted + stats.rejected) as u64,
            ))
        }
        Method::TrBdf2(tol) | Method::Radau5(tol) => {
            let mut out: Vec<(f64, Vec<f64>)> = (1..=checkpoints)
                .map(|k| (t_end * k as f64 / checkpoints as f64, Vec::new()))
                .collect();
            // (rhs calls with the Jacobians', steps)
            let (calls, steps) = if let Method::TrBdf2(_) = method {
                let st = TrBdf2::new()
                    .rtol(tol)
                    .atol(tol * 1e-2)
                    .max_steps(10_000_000)
                    .solve_prepared_at(rhs, inputs, 0.0, &pb.x0, &mut out)?
                    .stats;
                (
                    st.rhs_calls + st.jacobian_rhs_calls,
                    st.accepted + st.rejected,
                )
            } else {
                let st = Radau5::new()
                    .rtol(tol)
                    .atol(tol * 1e-2)
                    .max_steps(10_000_000)
                    .solve_prepared_at(rhs, inputs, 0.0, &pb.x0, &mut out)?
                    .stats;
                (
                    st.rhs_calls + st.jacobian_rhs_calls,
                    st.accepted + st.rejected,
                )
            };
            let states = out
                .iter()
                .map(|(_, x)| {
                    let mut state = [0.0; S];
                    state.copy_from_slice(x);
                    state
                })
                .collect();
            Ok((states, calls as u64, steps as u64))
        }
        Method::Rk4(n) | Method::Heun(n) | Method::Midpoint(n) => {
            // Round the step count up to a multiple of the checkpoints.
            let per = n.div_ceil(checkpoints).max(1);
            let steps = per * checkpoints;
            let h = t_end / steps as f64;
            let stages = match method {
                Method::Rk4(_) => 4,
                _ => 2,
            };
            let mut x = pb.x0;
            let mut out = Vec::with_capacity(checkpoints);
            for k in 0..steps {
                let t = k as f64 * h;
                x = match method {
                    Method::Rk4(_) => rk4_step_fn(&mut f, t, h, &x)?,
                    Method::Heun(_) => heun_step_fn(&mut f, t, h, &x)?,
                    _ => midpoint_step_fn(&mut f, t, h, &x)?,
                };
                if (k + 1) % per == 0 {
                    out.push(x);
                }
            }
            Ok((out, (steps * stages) as u64, steps as u64))
        }
    }
}

/// The methods of a standard sweep: RK4, Heun and midpoint at step counts
/// doubling from `min_steps` (`levels` of them), Dormand–Prince 5(4) and
/// DOP853 at tolerances from 1e-3 down by factors of 10 (`levels + 2` of
/// them, to 1e-12 for 8 levels) and TR-BDF2 at the first `levels` of those
/// tolerances.
pub fn standard_methods(min_steps: usize, levels: usize) -> Vec<Method> {
    let mut v = Vec::new();
    for k in 0..levels {
        let n = min_steps << k;
        v.push(Method::Rk4(n));
        v.push(Method::Heun(n));
        v.push(Method::Midpoint(n));
    }
    for k in 0..levels + 2 {
        v.push(Method::Dopri5(10f64.powi(-3 - k as i32)));
        v.push(Method::Dop853(10f64.powi(-3 - k as i32)));
    }
    for k in 0..levels {
        v.push(Method::TrBdf2(10f64.powi(-3 - k as i32)));
    }
    for k in 0..levels + 2 {
        v.push(Method::Radau5(10f64.powi(-3 - k as i32)));
    }
    v
}

/// A log–log chart (error against time) as a self-contained SVG document,
/// one polyline per method name; `title` on top.
pub fn svg_chart(title: &str, points: &[Point]) -> String {
    let series: Vec<(&str, Vec<(f64, f64)>)> = method_names(points)
        .into_iter()
        .map(|name| {
            let line = points
                .iter()
                .filter(|p| p.method.name() == name)
                .map(|p| (p.seconds, p.error_final))
                .collect();
            (name, line)
        })
        .collect();
    svg_loglog(
        title,
        "wall time per integration [s]",
        "relative error at the final time",
        &series,
    )
}

/// A log–log line chart as a self-contained SVG document: one polyline per
/// named series of `(x, y)` points (sorted by x; points that are not
/// positive and finite are left out), decade grid lines, axis labels and a
/// legend.
///
/// ```
/// use appell_tools::accuracy::svg_loglog;
/// let f64_line = vec![(100.0, 7.6e-7), (200.0, 4.7e-8), (400.0, 2.9e-9)];
/// let f32_line = vec![(100.0, 5.3e-7), (200.0, 8.1e-7), (400.0, 6.9e-7)];
/// let svg = svg_loglog("RK4", "steps", "error", &[("f64", f64_line), ("f32", f32_line)]);
/// assert!(svg.starts_with("<svg") && svg.matches("<polyline").count() == 2);
/// ```
pub fn svg_loglog(
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[(&str, Vec<(f64, f64)>)],
) -> String {
    let (w, h, left, bottom, top, right) = (720.0, 480.0, 80.0, 60.0, 40.0, 150.0);
    let good = |&(x, y): &(f64, f64)| x > 0.0 && y > 0.0 && x.is_finite() && y.is_finite();
    let lx = |p: &(f64, f64)| p.0.log10();
    let ly = |p: &(f64, f64)| p.1.max(1e-17).log10();
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    let mut any = false;
    for p in series
        .iter()
        .flat_map(|(_, line)| line.iter())
        .filter(|p| good(p))
    {
        any = true;
        x0 = x0.min(lx(p).floor());
        x1 = x1.max(lx(p).ceil());
        y0 = y0.min(ly(p).floor());
        y1 = y1.max(ly(p).ceil());
    }
    if !any {
        (x0, x1, y0, y1) = (-6.0, 0.0, -16.0, 0.0);
    }
    if x1 <= x0 {
        x1 = x0 + 1.0;
    }
    if y1 <= y0 {
        y1 = y0 + 1.0;
    }
    let sx = |v: f64| left + (v - x0) / (x1 - x0) * (w - left - right);
    let sy = |v: f64| h - bottom - (v - y0) / (y1 - y0) * (h - bottom - top);
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" font-family=\"sans-serif\" font-size=\"12\">\n\
         <rect width=\"{w}\" height=\"{h}\" fill=\"white\"/>\n\
         <text x=\"{}\" y=\"24\" text-anchor=\"middle\" font-size=\"15\">{}</text>\n",
        w / 2.0,
        escape(title)
    );
    for d in (x0 as i32)..=(x1 as i32) {
        let x = sx(d as f64);
        s += &format!(
            "<line x1=\"{x}\" y1=\"{}\" x2=\"{x}\" y2=\"{}\" stroke=\"#ddd\"/><text x=\"{x}\" y=\"{}\" text-anchor=\"middle\">1e{d}</text>\n",
            sy(y0),
            sy(y1),
            sy(y0) + 18.0
        );
    }
    for d in (y0 as i32)..=(y1 as i32) {
        let y = sy(d as f64);
        s += &format!(
            "<line x1=\"{}\" y1=\"{y}\" x2=\"{}\" y2=\"{y}\" stroke=\"#ddd\"/><text x=\"{}\" y=\"{}\" text-anchor=\"end\">1e{d}</text>\n",
            sx(x0),
            sx(x1),
            sx(x0) - 6.0,
            y + 4.0
        );
    }
    s += &format!(
        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n\
         <text x=\"18\" y=\"{}\" text-anchor=\"middle\" transform=\"rotate(-90 18 {})\">{}</text>\n",
        (sx(x0) + sx(x1)) / 2.0,
        h - 12.0,
        escape(x_label),
        (sy(y0) + sy(y1)) / 2.0,
        (sy(y0) + sy(y1)) / 2.0,
        escape(y_label)
    );
    let colors = [
        "#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b",
    ];
    for (k, (name, line)) in series.iter().enumerate() {
        let color = colors[k % colors.len()];
        let mut line: Vec<&(f64, f64)> = line.iter().filter(|p| good(p)).collect();
        line.sort_by(|a, b| a.0.total_cmp(&b.0));
        let path: Vec<String> = line
            .iter()
            .map(|p| format!("{:.2},{:.2}", sx(lx(p)), sy(ly(p))))
            .collect();
        s += &format!(
            "<polyline fill=\"none\" stroke=\"{color}\" stroke-width=\"2\" points=\"{}\"/>\n",
            path.join(" ")
        );
        for p in &line {
            s += &format!(
                "<circle cx=\"{:.2}\" cy=\"{:.2}\" r=\"3\" fill=\"{color}\"/>\n",
                sx(lx(p)),
                sy(ly(p))
            );
        }
        let ly_legend = top + 20.0 + 20.0 * k as f64;
        s += &format!(
            "<line x1=\"{}\" y1=\"{ly_legend}\" x2=\"{}\" y2=\"{ly_legend}\" stroke=\"{color}\" stroke-width=\"2\"/><text x=\"{}\" y=\"{}\">{}</text>\n",
            w - right + 15.0,
            w - right + 40.0,
            w - right + 46.0,
            ly_legend + 4.0,
            escape(name)
        );
    }
    s += "</svg>\n";
    s
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The points as CSV: `method,setting,error_final,error_max,seconds,rhs_calls,steps`.
pub fn csv(points: &[Point]) -> String {
    let mut s = String::from("method,setting,error_final,error_max,seconds,rhs_calls,steps\n");
    for p in points {
        s += &format!(
            "{},{:e},{:e},{:e},{:e},{},{}\n",
            p.method.name(),
            p.method.setting(),
            p.error_final,
            p.error_max,
            p.seconds,
            p.rhs_calls,
            p.steps
        );
    }
    s
}

/// The names of the methods among `points`, in order of first appearance.
///
/// ```
/// use appell_tools::accuracy::{method_names, Method, Point};
/// let p = |method| Point { method, error_final: 1e-6, error_max: 1e-6, seconds: 1e-5, rhs_calls: 40, steps: 10 };
/// let points = [p(Method::Rk4(10)), p(Method::Dopri5(1e-6)), p(Method::Rk4(20))];
/// assert_eq!(method_names(&points), ["rk4", "dopri5"]);
/// ```
pub fn method_names(points: &[Point]) -> Vec<&'static str> {
    let mut names: Vec<&'static str> = Vec::new();
    for p in points {
        if !names.contains(&p.method.name()) {
            names.push(p.method.name());
        }
    }
    names
}

/// For each method, the least time that reached a relative error at or below
/// each target (`None` where no setting did).
pub fn time_to_reach(points: &[Point], targets: &[f64]) -> Vec<(&'static str, Vec<Option<f64>>)> {
    method_names(points)
        .into_iter()
        .map(|n| {
            let times = targets
                .iter()
                .map(|&target| {
                    points
                        .iter()
                        .filter(|p| p.method.name() == n && p.error_max <= target)
                        .map(|p| p.seconds)
                        .min_by(f64::total_cmp)
                })
                .collect();
            (n, times)
        })
        .collect()
}
