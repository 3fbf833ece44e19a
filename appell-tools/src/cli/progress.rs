//! A progress bar for a long `animate` run, drawn on one line of a
//! terminal (`\r` rewrites it), without a dependency.

use std::io::Write;

/// Width of the bar in characters.
const WIDTH: usize = 30;

/// A bar from 0 to `total`, redrawn only when its percentage changes.
pub(super) struct Bar<'w> {
    out: &'w mut dyn Write,
    label: &'static str,
    total: usize,
    shown: Option<usize>,
}

impl<'w> Bar<'w> {
    /// A bar for `total` units of work, labelled `label`; nothing is drawn
    /// until the first [`Bar::set`].
    pub(super) fn new(out: &'w mut dyn Write, label: &'static str, total: usize) -> Self {
        Bar {
            out,
            label,
            total: total.max(1),
            shown: None,
        }
    }

    /// Draws the bar at `done` of the total (the last draw ends the line).
    /// A failed write to the terminal is ignored: the bar is a courtesy.
    pub(super) fn set(&mut self, done: usize) {
        let done = done.min(self.total);
        let percent = done * 100 / self.total;
        if self.shown == Some(percent) {
            return;
        }
        self.shown = Some(percent);
        let filled = done * WIDTH / self.total;
        let _ = write!(
            self.out,
            "\r{}: [{}{}] {percent:3}%",
            self.label,
            "#".repeat(filled),
            ".".repeat(WIDTH - filled)
        );
        if done == self.total {
            let _ = writeln!(self.out);
        }
        let _ = self.out.flush();
    }
}

#[cfg(test)]
mod tests {
    use super::Bar;

    #[test]
    fn the_bar_is_redrawn_when_its_percentage_changes_and_ends_its_line() {
        let mut out = Vec::new();
        let mut bar = Bar::new(&mut out, "animate", 400);
        for done in 1..=400 {
            bar.set(done);
        }
        let text = String::from_utf8(out).unwrap();
        // 0 % to 100 %, once each.
        assert_eq!(text.matches('\r').count(), 101, "{text:?}");
        assert!(text.starts_with("\ranimate: [..............................]   0%"));
        assert!(text.ends_with("\ranimate: [##############################] 100%\n"));
        assert!(text.contains("\ranimate: [###############...............]  50%"));
    }
}
