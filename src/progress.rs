//! Progress bars on standard error, the same look in both tools; hidden with `--quiet` and when
//! standard error is not a terminal (indicatif's default).

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};

fn style(template: &str) -> ProgressStyle {
    ProgressStyle::with_template(template).unwrap_or_else(|_| ProgressStyle::default_bar()).progress_chars("=> ")
}

/// A bar that counts items (`12/200 runs`), with elapsed time and an estimate of what is left.
pub fn count(len: usize, prefix: &str, unit: &str, quiet: bool) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(len as u64), ProgressDrawTarget::stderr());
    bar.set_style(style(&format!("{{prefix:>12}} [{{bar:30.cyan/blue}}] {{pos}}/{{len}} {unit}  {{elapsed_precise}} (eta {{eta}})  {{msg}}")));
    bar.set_prefix(prefix.to_string());
    bar
}

/// One bar per simulated run, in simulated milliseconds, under one [`MultiProgress`].
pub struct RunBars {
    multi: MultiProgress,
    style: ProgressStyle,
}

impl RunBars {
    pub fn new(quiet: bool) -> Self {
        let target = if quiet { ProgressDrawTarget::hidden() } else { ProgressDrawTarget::stderr() };
        Self {
            multi: MultiProgress::with_draw_target(target),
            style: style("{prefix:>12} [{bar:30.cyan/blue}] {msg:>9} simulated  {elapsed_precise}"),
        }
    }

    /// A bar for a run named `name` of `duration_s` simulated seconds.
    pub fn add(&self, name: &str, duration_s: f64) -> ProgressBar {
        let b = self.multi.add(ProgressBar::new((duration_s * 1e3).round() as u64));
        b.set_style(self.style.clone());
        b.set_prefix(name.to_string());
        b.set_message("0.000 s");
        b
    }
}

/// Sets a run bar to simulated time `t_s`.
pub fn set_time(bar: &ProgressBar, t_s: f64) {
    bar.set_position((t_s * 1e3).round() as u64);
    bar.set_message(format!("{t_s:.3} s"));
}
