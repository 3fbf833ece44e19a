//! A static SVG plot of curves against one parameter: linear axes with
//! ticks at 1, 2 or 5 times a power of ten, a legend, and each curve as
//! markers (eigenvalues sorted by size swap places where two cross, so
//! markers read right where lines would jump).

use std::fmt::Write;

use super::draw::escape;

/// One series of a [`line_plot`].
#[derive(Clone, Debug)]
pub struct Curve {
    /// Its name in the legend.
    pub label: String,
    /// (x, y) points; non-finite ones are left out.
    pub points: Vec<(f64, f64)>,
}

const COLOURS: [&str; 4] = ["#3b6ea5", "#c8553d", "#4f9d69", "#8e5ea2"];

/// The curves on linear axes, 640 × 420 pixels, with `title` and the axes'
/// labels.
///
/// ```
/// use appell_tools::animate::{line_plot, Curve};
/// let square = Curve {
///     label: "x²".into(),
///     points: (0..=10).map(|i| (i as f64, (i * i) as f64)).collect(),
/// };
/// let svg = line_plot("squares", "x", "y", &[square]);
/// // Eleven markers and the legend's.
/// assert!(svg.starts_with("<svg") && svg.matches("<circle").count() == 12);
/// ```
pub fn line_plot(title: &str, x_label: &str, y_label: &str, curves: &[Curve]) -> String {
    let (w, h) = (640.0, 420.0);
    let (left, right, top, bottom) = (64.0, 150.0, 36.0, 48.0);
    let finite: Vec<(f64, f64)> = curves
        .iter()
        .flat_map(|c| c.points.iter().copied())
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .collect();
    let range = |pick: fn(&(f64, f64)) -> f64| {
        let lo = finite.iter().map(pick).fold(f64::INFINITY, f64::min);
        let hi = finite.iter().map(pick).fold(f64::NEG_INFINITY, f64::max);
        if lo.is_finite() && hi > lo {
            (lo, hi)
        } else if lo.is_finite() {
            (lo - 1.0, lo + 1.0)
        } else {
            (0.0, 1.0)
        }
    };
    let (xs, ys) = (ticks(range(|p| p.0)), ticks(range(|p| p.1)));
    let (x0, x1) = (xs[0], xs[xs.len() - 1]);
    let (y0, y1) = (ys[0], ys[ys.len() - 1]);
    let px = |x: f64| left + (x - x0) / (x1 - x0) * (w - left - right);
    let py = |y: f64| h - bottom - (y - y0) / (y1 - y0) * (h - top - bottom);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"{w}\" height=\"{h}\" fill=\"#ffffff\"/>"
    );
    for &x in &xs {
        let _ = writeln!(
            s,
            "<line x1=\"{0:.1}\" y1=\"{top}\" x2=\"{0:.1}\" y2=\"{1:.1}\" stroke=\"#e4e4e4\"/><text x=\"{0:.1}\" y=\"{2:.1}\" text-anchor=\"middle\">{3}</text>",
            px(x),
            h - bottom,
            h - bottom + 16.0,
            tick_label(x)
        );
    }
    for &y in &ys {
        let _ = writeln!(
            s,
            "<line x1=\"{left}\" y1=\"{0:.1}\" x2=\"{1:.1}\" y2=\"{0:.1}\" stroke=\"{2}\"/><text x=\"{3:.1}\" y=\"{4:.1}\" text-anchor=\"end\">{5}</text>",
            py(y),
            w - right,
            if y == 0.0 { "#999999" } else { "#e4e4e4" },
            left - 6.0,
            py(y) + 4.0,
            tick_label(y)
        );
    }
    let _ = writeln!(
        s,
        "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{}</text>\n<text x=\"14\" y=\"{:.1}\" text-anchor=\"middle\" transform=\"rotate(-90 14 {:.1})\">{}</text>\n<text x=\"{left}\" y=\"22\" font-weight=\"bold\">{}</text>",
        (left + w - right) / 2.0,
        h - 10.0,
        escape(x_label),
        (top + h - bottom) / 2.0,
        (top + h - bottom) / 2.0,
        escape(y_label),
        escape(title)
    );
    for (k, c) in curves.iter().enumerate() {
        let colour = COLOURS[k % COLOURS.len()];
        for &(x, y) in c
            .points
            .iter()
            .filter(|(x, y)| x.is_finite() && y.is_finite())
        {
            let _ = write!(
                s,
                "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"1.8\" fill=\"{colour}\"/>",
                px(x),
                py(y)
            );
        }
        let ly = top + 10.0 + 20.0 * k as f64;
        let _ = writeln!(
            s,
            "\n<circle cx=\"{:.1}\" cy=\"{ly:.1}\" r=\"4\" fill=\"{colour}\"/><text x=\"{:.1}\" y=\"{:.1}\">{}</text>",
            w - right + 16.0,
            w - right + 26.0,
            ly + 4.0,
            escape(&c.label)
        );
    }
    s.push_str("</svg>\n");
    s
}

/// Tick values covering `(lo, hi)`: 1, 2 or 5 times a power of ten apart,
/// about six of them.
fn ticks((lo, hi): (f64, f64)) -> Vec<f64> {
    let raw = (hi - lo) / 6.0;
    let p = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * p)
        .min_by(|a, b| (a / raw).ln().abs().total_cmp(&(b / raw).ln().abs()))
        .unwrap_or(p);
    let first = (lo / step).floor() as i64;
    let last = (hi / step).ceil() as i64;
    (first..=last).map(|i| i as f64 * step).collect()
}

/// A tick's text: no trailing zeros.
fn tick_label(x: f64) -> String {
    let text = format!("{x:.6}");
    let trimmed = text.trim_end_matches('0').trim_end_matches('.');
    if trimmed == "-0" {
        "0".into()
    } else {
        trimmed.into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_cover_the_range_at_a_round_step() {
        let t = ticks((-3.2, 9.7));
        assert!(t[0] <= -3.2 && *t.last().unwrap() >= 9.7);
        assert_eq!(t[1] - t[0], 2.0);
        assert_eq!(tick_label(2.5), "2.5");
        assert_eq!(tick_label(-0.0), "0");
    }
}
