//! The SVG: ground grid, contact tracks, bodies and a time readout, moved
//! by SMIL `animate` and `animateTransform` elements (any browser plays
//! them; a viewer without SMIL shows the first frame).

use std::fmt::Write;

use super::geometry::{self, Pose, Projection, Scene};
use super::Frame;
use appell_core::dynamic::DynModel;
use appell_core::ModelError;

/// How the motion is looked at.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// Along the N axis the bodies' centres do not move along, when there
    /// is one (a planar motion), else [`View::Oblique`].
    Auto,
    /// Along N's axis 0, 1 or 2: along z shows x right and y up.
    Along(usize),
    /// From 30° off the side and 25° above the ground (see
    /// [`SvgOptions::up`]).
    Oblique,
}

/// Size, title, speed and view of an animation.
#[derive(Clone, Debug)]
pub struct SvgOptions {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The title written in the top left corner.
    pub title: String,
    /// Seconds of motion per second of animation (1: real time).
    pub playback: f64,
    /// The view.
    pub view: View,
    /// Up in an oblique view, N components (default z up; `[0, 0, -1]`
    /// for a model written z down).
    pub up: [f64; 3],
    /// Keep the bodies' mean centre in the middle of the picture (the
    /// ground moves under them): for vehicles that travel far.
    pub follow: bool,
    /// Lines drawn between two bodies' centres (indices into
    /// [`ModelInfo::bodies`](appell_core::ModelInfo); None: N's origin O): a
    /// pendulum's massless links, a robot's chain.
    pub connectors: Vec<(Option<usize>, Option<usize>)>,
    /// Bodies whose centre's path is drawn (a wheel's track without a
    /// `rolls` contact).
    pub traces: Vec<usize>,
    /// Rigid bodies drawn as dots instead of their ellipsoids (a robot as
    /// a stick figure, with `connectors`).
    pub dots: Vec<usize>,
}

impl Default for SvgOptions {
    /// 640 × 480, no title, real time, [`View::Auto`], z up, fixed, no
    /// connectors, traces or dots.
    fn default() -> Self {
        SvgOptions {
            width: 640,
            height: 480,
            title: String::new(),
            playback: 1.0,
            view: View::Auto,
            up: [0.0, 0.0, 1.0],
            follow: false,
            connectors: Vec::new(),
            traces: Vec::new(),
            dots: Vec::new(),
        }
    }
}

const COLOURS: [&str; 6] = [
    "#3b6ea5", "#c8553d", "#4f9d69", "#8e5ea2", "#d9a441", "#5b8c9e",
];
const MARGIN: f64 = 24.0;

/// The frames drawn as an animated SVG (see the module documentation).
///
/// Errors: fewer than two frames or times not increasing
/// ([`ModelError::NonFinite`] naming them), wrong coordinate lengths, and
/// any error of the model's geometry functions.
pub fn svg<K: DynModel + ?Sized>(
    model: &K,
    frames: &[Frame],
    options: &SvgOptions,
) -> Result<String, ModelError> {
    let increasing = frames.windows(2).all(|w| w[1].t > w[0].t);
    let playback_ok = options.playback.is_finite() && options.playback > 0.0;
    if frames.len() < 2 || !increasing || !playback_ok {
        return Err(ModelError::NonFinite {
            what: "the frames (at least two, times increasing) or the playback rate",
        });
    }
    let scene = geometry::scene(model, frames)?;
    let projection = match options.view {
        View::Auto => geometry::auto_projection(&scene, options.up),
        View::Along(k) => Projection::along(k.min(2)),
        View::Oblique => Projection::oblique(options.up),
    };
    let grid = ground_grid(&scene, &projection, options);
    let canvas = Canvas::fit(&scene, &projection, &grid, options);
    let timing = Timing::new(frames, options.playback);
    let mut out = String::new();
    let (w, h) = (options.width, options.height);
    let _ = writeln!(
        out,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\" font-family=\"sans-serif\" font-size=\"13\">"
    );
    let _ = writeln!(out, "<rect width=\"{w}\" height=\"{h}\" fill=\"#ffffff\"/>");
    // The moving scene: following, it shifts so that each frame's mean
    // centre stays where the first frame's is.
    out.push_str("<g>");
    if options.follow {
        let means = frame_means(&scene, &projection);
        let mut shifts = String::new();
        for (k, m) in means.iter().enumerate() {
            let sep = if k == 0 { "" } else { ";" };
            let dx = -(m[0] - means[0][0]) * canvas.scale;
            let dy = (m[1] - means[0][1]) * canvas.scale;
            let _ = write!(shifts, "{sep}{dx:.1} {dy:.1}");
        }
        out.push_str(&timing.transform("translate", &shifts));
    }
    out.push('\n');
    for (a, b) in &grid {
        let (p, q) = (canvas.px(a), canvas.px(b));
        let _ = writeln!(
            out,
            "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"#dcdcdc\" stroke-width=\"1\"/>",
            p[0], p[1], q[0], q[1]
        );
    }
    tracks(&mut out, &scene, &canvas);
    traces(&mut out, &scene, &options.traces, &canvas)?;
    connectors(&mut out, &scene, &options.connectors, &canvas, &timing)?;
    for b in body_order(&scene, &projection) {
        let dot = options.dots.contains(&b);
        body(&mut out, &scene, (b, dot), &canvas, &timing);
    }
    out.push_str("</g>\n");
    readout(&mut out, frames, &timing, h);
    if !options.title.is_empty() {
        let _ = writeln!(
            out,
            "<text x=\"10\" y=\"20\" font-weight=\"bold\">{}</text>",
            escape(&options.title)
        );
    }
    out.push_str("</svg>\n");
    Ok(out)
}

/// Grid lines in N: on the ground plane under the motion for an oblique
/// view, in the picture's plane otherwise.
fn ground_grid(
    scene: &Scene,
    projection: &Projection,
    options: &SvgOptions,
) -> Vec<([f64; 3], [f64; 3])> {
    let (up, follow) = (options.up, options.follow);
    let oblique = projection.along.is_none();
    let points: Vec<[f64; 3]> = scene
        .poses
        .iter()
        .flatten()
        .map(|p| p.centre)
        .chain(scene.contacts.iter().flatten().copied())
        .collect();
    let size = scene
        .poses
        .iter()
        .flatten()
        .map(|p| (0..3).map(|k| p.axes.column(k).norm()).fold(0.0, f64::max))
        .fold(0.0, f64::max);
    // The plane's two axes and its height along the third.
    let vertical = (0..3)
        .max_by(|&a, &b| up[a].abs().total_cmp(&up[b].abs()))
        .unwrap_or(2);
    let normal = projection.along.unwrap_or(vertical);
    let (u, v) = ((normal + 1) % 3, (normal + 2) % 3);
    let range = |axis: usize| {
        let lo = points.iter().map(|p| p[axis]).fold(f64::INFINITY, f64::min);
        let hi = points
            .iter()
            .map(|p| p[axis])
            .fold(f64::NEG_INFINITY, f64::max);
        (lo - size, hi + size)
    };
    // An oblique view's ground is under the lowest contact (the x-y plane
    // without contacts); a planar view's grid is the picture's plane.
    let heights = scene.contacts.iter().flatten().map(|p| p[normal]);
    let lowest = if up[normal] >= 0.0 {
        heights.fold(f64::INFINITY, f64::min)
    } else {
        heights.fold(f64::NEG_INFINITY, f64::max)
    };
    let height = if oblique && lowest.is_finite() {
        lowest
    } else {
        0.0
    };
    let ((u0, u1), (v0, v1)) = (range(u), range(v));
    // Following, the grid is spaced for the picture, not the whole path.
    let span = if follow {
        let means: Vec<[f64; 3]> = scene.poses.iter().map(|f| mean_centre(f)).collect();
        let reach = scene
            .poses
            .iter()
            .zip(&means)
            .flat_map(|(f, m)| {
                f.iter()
                    .map(move |p| super::geometry::distance(&p.centre, m))
            })
            .fold(0.0, f64::max);
        2.0 * (reach + size)
    } else {
        (u1 - u0).max(v1 - v0)
    };
    let step = nice_step(span / 8.0);
    let mut lines = Vec::new();
    let at = |a: f64, b: f64| {
        let mut p = [0.0; 3];
        p[u] = a;
        p[v] = b;
        p[normal] = height;
        p
    };
    let (a0, b0) = ((u0 / step).floor() * step, (v0 / step).floor() * step);
    let (a1, b1) = ((u1 / step).ceil() * step, (v1 / step).ceil() * step);
    let mut a = a0;
    while a <= a1 + 0.5 * step {
        lines.push((at(a, b0), at(a, b1)));
        a += step;
    }
    let mut b = b0;
    while b <= b1 + 0.5 * step {
        lines.push((at(a0, b), at(a1, b)));
        b += step;
    }
    lines
}

/// The mean of a frame's body centres, in N.
fn mean_centre(frame: &[Pose]) -> [f64; 3] {
    let n = frame.len().max(1) as f64;
    frame.iter().fold([0.0; 3], |acc, p| {
        core::array::from_fn(|k| acc[k] + p.centre[k] / n)
    })
}

/// 1, 2 or 5 times a power of ten, at least `x`.
fn nice_step(x: f64) -> f64 {
    if x.is_nan() || x <= 0.0 || x.is_infinite() {
        return 1.0;
    }
    let p = 10f64.powf(x.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * p)
        .find(|&s| s >= x)
        .unwrap_or(10.0 * p)
}

/// Each frame's mean of the bodies' centres, projected.
fn frame_means(scene: &Scene, projection: &Projection) -> Vec<[f64; 2]> {
    scene
        .poses
        .iter()
        .map(|frame| {
            let n = frame.len().max(1) as f64;
            frame.iter().fold([0.0, 0.0], |acc, p| {
                let q = projection.point(&p.centre);
                [acc[0] + q[0] / n, acc[1] + q[1] / n]
            })
        })
        .collect()
}

/// From N (projected) to pixels: the whole motion fits the picture, or
/// with `follow` every frame around its mean centre.
struct Canvas {
    projection: Projection,
    origin: [f64; 2],
    scale: f64,
    height: f64,
    /// A particle's radius in pixels.
    dot: f64,
}

impl Canvas {
    fn fit(
        scene: &Scene,
        projection: &Projection,
        grid: &[([f64; 3], [f64; 3])],
        options: &SvgOptions,
    ) -> Canvas {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        let mut grow = |p: [f64; 2], r: f64| {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k] - r);
                hi[k] = hi[k].max(p[k] + r);
            }
        };
        // Following, the picture holds every frame around its mean centre.
        let means = frame_means(scene, projection);
        let relative = |k: usize, p: [f64; 2]| match options.follow {
            true => [
                p[0] - means[k][0] + means[0][0],
                p[1] - means[k][1] + means[0][1],
            ],
            false => p,
        };
        for (k, frame) in scene.poses.iter().enumerate() {
            for pose in frame {
                let (major, _, _) = projection.ellipse(&pose.axes);
                grow(relative(k, projection.point(&pose.centre)), major);
            }
        }
        for (k, frame) in scene.contacts.iter().enumerate() {
            for p in frame {
                grow(relative(k, projection.point(p)), 0.0);
            }
        }
        if !options.follow {
            for (a, b) in grid {
                grow(projection.point(a), 0.0);
                grow(projection.point(b), 0.0);
            }
        }
        let (w, h) = (f64::from(options.width), f64::from(options.height));
        let span = [(hi[0] - lo[0]).max(1e-9), (hi[1] - lo[1]).max(1e-9)];
        let scale = ((w - 2.0 * MARGIN) / span[0]).min((h - 3.0 * MARGIN) / span[1]);
        // Centred in the picture.
        let origin = [
            lo[0] - ((w - 2.0 * MARGIN) / scale - span[0]) / 2.0,
            lo[1] - ((h - 3.0 * MARGIN) / scale - span[1]) / 2.0,
        ];
        Canvas {
            projection: *projection,
            origin,
            scale,
            height: h,
            dot: 0.012 * w.min(h),
        }
    }

    /// A point of N in pixels (y down).
    fn px(&self, p: &[f64; 3]) -> [f64; 2] {
        let s = self.projection.point(p);
        [
            MARGIN + (s[0] - self.origin[0]) * self.scale,
            self.height - 2.0 * MARGIN - (s[1] - self.origin[1]) * self.scale,
        ]
    }
}

/// Times of the frames as fractions of the animation, and its duration.
struct Timing {
    key_times: String,
    duration: f64,
}

impl Timing {
    fn new(frames: &[Frame], playback: f64) -> Timing {
        let (t0, t1) = (frames[0].t, frames[frames.len() - 1].t);
        let step = (t1 - t0) / (frames.len() - 1) as f64;
        let even = frames
            .windows(2)
            .all(|w| ((w[1].t - w[0].t) - step).abs() <= 1e-9 * step);
        // Evenly spaced frames need no keyTimes: SMIL spaces values evenly.
        let mut key_times = String::new();
        if !even {
            key_times.push_str(" keyTimes=\"");
            for (k, f) in frames.iter().enumerate() {
                let sep = if k == 0 { "" } else { ";" };
                let x = if k + 1 == frames.len() {
                    1.0
                } else {
                    (f.t - t0) / (t1 - t0)
                };
                let _ = write!(key_times, "{sep}{x:.5}");
            }
            key_times.push('"');
        }
        Timing {
            key_times,
            duration: (t1 - t0) / playback,
        }
    }

    /// An `animate` element of `attribute` through `values`.
    fn animate(&self, attribute: &str, values: &str) -> String {
        format!(
            "<animate attributeName=\"{attribute}\" dur=\"{:.3}s\" repeatCount=\"indefinite\"{} values=\"{values}\"/>",
            self.duration, self.key_times
        )
    }

    /// An `animateTransform` element of `kind` through `values`.
    fn transform(&self, kind: &str, values: &str) -> String {
        format!(
            "<animateTransform attributeName=\"transform\" type=\"{kind}\" dur=\"{:.3}s\" repeatCount=\"indefinite\"{} values=\"{values}\"/>",
            self.duration, self.key_times
        )
    }
}

/// Each contact point's path, on the ground.
fn tracks(out: &mut String, scene: &Scene, canvas: &Canvas) {
    let count = scene.contacts.first().map_or(0, Vec::len);
    for c in 0..count {
        let mut points = String::new();
        for frame in &scene.contacts {
            let p = canvas.px(&frame[c]);
            let _ = write!(points, "{:.1},{:.1} ", p[0], p[1]);
        }
        let _ = writeln!(
            out,
            "<polyline points=\"{}\" fill=\"none\" stroke=\"#b0413e\" stroke-width=\"1.5\" stroke-opacity=\"0.7\"/>",
            points.trim_end()
        );
    }
}

/// The paths of the chosen bodies' centres.
fn traces(
    out: &mut String,
    scene: &Scene,
    bodies: &[usize],
    canvas: &Canvas,
) -> Result<(), ModelError> {
    for &b in bodies {
        if b >= scene.rigid.len() {
            return Err(ModelError::Length {
                argument: "traces (body index)",
                expected: scene.rigid.len(),
                found: b + 1,
            });
        }
        let mut points = String::new();
        for frame in &scene.poses {
            let p = canvas.px(&frame[b].centre);
            let _ = write!(points, "{:.1},{:.1} ", p[0], p[1]);
        }
        let _ = writeln!(
            out,
            "<polyline points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"1.5\" stroke-dasharray=\"4 3\"/>",
            points.trim_end(),
            COLOURS[b % COLOURS.len()]
        );
    }
    Ok(())
}

/// The connectors' lines, their ends following the bodies.
fn connectors(
    out: &mut String,
    scene: &Scene,
    pairs: &[(Option<usize>, Option<usize>)],
    canvas: &Canvas,
    timing: &Timing,
) -> Result<(), ModelError> {
    let bodies = scene.rigid.len();
    for &(a, b) in pairs {
        if a.max(b).is_some_and(|i| i >= bodies) {
            return Err(ModelError::Length {
                argument: "connectors (body index)",
                expected: bodies,
                found: a.max(b).unwrap_or(0) + 1,
            });
        }
        let end =
            |frame: &[Pose], i: Option<usize>| canvas.px(&i.map_or([0.0; 3], |i| frame[i].centre));
        let mut values: [String; 4] = Default::default();
        for (k, frame) in scene.poses.iter().enumerate() {
            let (p, q) = (end(frame, a), end(frame, b));
            let sep = if k == 0 { "" } else { ";" };
            for (v, x) in values.iter_mut().zip([p[0], p[1], q[0], q[1]]) {
                let _ = write!(v, "{sep}{x:.1}");
            }
        }
        let (p, q) = (end(&scene.poses[0], a), end(&scene.poses[0], b));
        let _ = writeln!(
            out,
            "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"#555555\" stroke-width=\"2.5\" stroke-linecap=\"round\">{}{}{}{}</line>",
            p[0],
            p[1],
            q[0],
            q[1],
            timing.animate("x1", &values[0]),
            timing.animate("y1", &values[1]),
            timing.animate("x2", &values[2]),
            timing.animate("y2", &values[3])
        );
    }
    Ok(())
}

/// Bodies far from the eye first (their depth at the first frame).
fn body_order(scene: &Scene, projection: &Projection) -> Vec<usize> {
    let toward_eye = projection.right.cross(&projection.up);
    let depth = |p: &Pose| toward_eye.dot(&nalgebra::Vector3::from(p.centre));
    let mut order: Vec<usize> = (0..scene.rigid.len()).collect();
    order.sort_by(|&a, &b| depth(&scene.poses[0][a]).total_cmp(&depth(&scene.poses[0][b])));
    order
}

/// One body: a group moved to its centre, holding its ellipse (turned and
/// resized) and spoke, or a dot for a particle.
fn body(
    out: &mut String,
    scene: &Scene,
    (b, dot): (usize, bool),
    canvas: &Canvas,
    timing: &Timing,
) {
    let colour = COLOURS[b % COLOURS.len()];
    let mut moves = String::new();
    let (mut turns, mut rx, mut ry, mut sx, mut sy) = (
        String::new(),
        String::new(),
        String::new(),
        String::new(),
        String::new(),
    );
    let mut previous: Option<f64> = None;
    let mut first = None;
    for (k, frame) in scene.poses.iter().enumerate() {
        let pose = &frame[b];
        let c = canvas.px(&pose.centre);
        let sep = if k == 0 { "" } else { ";" };
        let _ = write!(moves, "{sep}{:.1} {:.1}", c[0], c[1]);
        let (major, minor, angle) = canvas.projection.ellipse(&pose.axes);
        // The ellipse is the same turned by π: keep the angle continuous.
        let mut degrees = -angle.to_degrees();
        if let Some(p) = previous {
            degrees += 180.0 * ((p - degrees) / 180.0).round();
        }
        previous = Some(degrees);
        // A flat body seen edge-on is still drawn: at least a pixel across.
        let (a, bb) = (
            (major * canvas.scale).max(1.0),
            (minor * canvas.scale).max(1.0),
        );
        let longest = (0..3)
            .max_by(|&i, &j| {
                pose.axes
                    .column(i)
                    .norm()
                    .total_cmp(&pose.axes.column(j).norm())
            })
            .unwrap_or(0);
        let tip: [f64; 3] = core::array::from_fn(|i| pose.centre[i] + pose.axes[(i, longest)]);
        let t = canvas.px(&tip);
        let spoke = [t[0] - c[0], t[1] - c[1]];
        let _ = write!(turns, "{sep}{degrees:.1}");
        let _ = write!(rx, "{sep}{a:.1}");
        let _ = write!(ry, "{sep}{bb:.1}");
        let _ = write!(sx, "{sep}{:.1}", spoke[0]);
        let _ = write!(sy, "{sep}{:.1}", spoke[1]);
        if k == 0 {
            first = Some((c, degrees, a, bb, spoke));
        }
    }
    let Some((c, degrees, a, bb, spoke)) = first else {
        return;
    };
    let _ = writeln!(
        out,
        "<g transform=\"translate({:.1} {:.1})\">{}",
        c[0],
        c[1],
        timing.transform("translate", &moves)
    );
    if scene.rigid[b] && !dot {
        let _ = writeln!(
            out,
            "<g transform=\"rotate({degrees:.1})\">{}<ellipse rx=\"{a:.1}\" ry=\"{bb:.1}\" fill=\"{colour}\" fill-opacity=\"0.55\" stroke=\"{colour}\" stroke-width=\"1.5\">{}{}</ellipse></g>",
            timing.transform("rotate", &turns),
            timing.animate("rx", &rx),
            timing.animate("ry", &ry)
        );
        let _ = writeln!(
            out,
            "<line x1=\"0\" y1=\"0\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"#222222\" stroke-width=\"1.5\">{}{}</line>",
            spoke[0],
            spoke[1],
            timing.animate("x2", &sx),
            timing.animate("y2", &sy)
        );
    } else {
        let _ = writeln!(
            out,
            "<circle r=\"{:.1}\" fill=\"{colour}\" stroke=\"#222222\"/>",
            canvas.dot
        );
    }
    out.push_str("</g>\n");
}

/// The time, one text per frame, each shown while its frame is.
fn readout(out: &mut String, frames: &[Frame], timing: &Timing, height: u32) {
    let n = frames.len();
    let (t0, t1) = (frames[0].t, frames[n - 1].t);
    let y = f64::from(height) - 10.0;
    for (k, f) in frames.iter().enumerate() {
        let start = (f.t - t0) / (t1 - t0);
        let end = frames.get(k + 1).map_or(1.0, |g| (g.t - t0) / (t1 - t0));
        let (values, times) = match k {
            0 => ("visible;hidden".to_string(), format!("0;{end:.5}")),
            _ if k + 1 == n => ("hidden;visible".to_string(), format!("0;{start:.5}")),
            _ => (
                "hidden;visible;hidden".to_string(),
                format!("0;{start:.5};{end:.5}"),
            ),
        };
        let initial = if k == 0 { "visible" } else { "hidden" };
        let _ = writeln!(
            out,
            "<text x=\"10\" y=\"{y:.0}\" visibility=\"{initial}\">t = {:.2} s<animate attributeName=\"visibility\" calcMode=\"discrete\" dur=\"{:.3}s\" repeatCount=\"indefinite\" keyTimes=\"{times}\" values=\"{values}\"/></text>",
            f.t, timing.duration
        );
    }
}

/// Text safe inside an SVG element.
pub(super) fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_are_one_two_or_five_times_a_power_of_ten() {
        assert_eq!(nice_step(0.7), 1.0);
        assert_eq!(nice_step(1.3), 2.0);
        assert_eq!(nice_step(3.0), 5.0);
        assert!((nice_step(0.012) - 0.02).abs() < 1e-15);
    }

    #[test]
    fn text_is_escaped() {
        assert_eq!(escape("a < b & c"), "a &lt; b &amp; c");
    }
}
