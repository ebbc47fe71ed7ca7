//! `reproduce all`'s progress bar ([`Overall`]): one span per target, advanced by its frames; it
//! draws what it is given (labels, spans, frames), not a command's types.

use std::sync::Mutex;

/// `reproduce all`'s progress bar: one span per target, advanced by its frames.
pub struct Overall {
    bar: indicatif::ProgressBar,
    state: Mutex<Span>,
}

#[derive(Default)]
struct Span {
    start: u64,
    len: u64,
    frames: u64,
    done: u64,
    label: String,
}

impl Overall {
    pub fn new(quiet: bool, total: u64) -> Overall {
        let bar = if quiet {
            indicatif::ProgressBar::hidden()
        } else {
            indicatif::ProgressBar::new(total.max(1))
        };
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{msg:<44} [{bar:30}] {percent:>3}% {elapsed_precise} (ETA {eta_precise})",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        Overall {
            bar,
            state: Mutex::new(Span::default()),
        }
    }

    /// The next target: `len` of the bar, `frames` frames.
    pub fn start(&self, label: &str, len: u64, frames: u64) {
        if let Ok(mut s) = self.state.lock() {
            let start = s.start + s.len;
            *s = Span {
                start,
                len,
                frames,
                done: 0,
                label: label.to_string(),
            };
            self.bar.set_position(start);
        }
        self.bar.set_message(label.to_string());
    }

    /// A technique's pass starts.
    pub fn technique(&self, name: &str) {
        if let Ok(s) = self.state.lock() {
            self.bar.set_message(format!("{} · {name}", s.label));
        }
    }

    /// A frame was rendered.
    pub fn frame(&self) {
        if let Ok(mut s) = self.state.lock() {
            s.done += 1;
            if s.frames > 0 {
                let part = s.len as f64 * (s.done.min(s.frames) as f64 / s.frames as f64);
                self.bar.set_position(s.start + part as u64);
            }
        }
    }

    /// A line above the bar.
    pub fn note(&self, line: &str) {
        if self.bar.is_hidden() {
            eprintln!("{line}");
        } else {
            self.bar.println(line);
        }
    }

    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
