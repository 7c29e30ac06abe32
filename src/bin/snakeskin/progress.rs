//! Progress for the long commands (generate, figures, sheet, preview, bench render): a bar or
//! spinner on a terminal, nothing when stderr is redirected, so logs and tests stay clean.

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressStyle};

pub struct Progress(Option<ProgressBar>);

/// How often a bar or spinner is redrawn between updates.
const TICK: std::time::Duration = std::time::Duration::from_millis(120);

/// `eprintln!`, but a reader that went away (`2>&1 | head`) loses the line and the run goes
/// on, as the batch's lines on stdout do (`cmd::batch`'s `JobLog`): under an ignored SIGPIPE
/// (a batch, which must not die mid-commit) a whole batch that had made every set and
/// written its index exited 1 without a word at its last note. Where SIGPIPE is the default
/// the process ends at the write as every command's does. Any other failure (`2> /dev/full`)
/// panics as `eprintln!` does (`output::stdout_failure_is_an_error` ends the run).
pub fn eprintln_unless_closed(line: &str) {
    use std::io::Write;
    match writeln!(std::io::stderr(), "{line}") {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => panic!("failed printing to stderr: {e}"),
        _ => {}
    }
}

impl Progress {
    /// A bar counting `{pos}/{len}` units; `template` is an indicatif template. It is drawn
    /// at once and ticks (its spinner, its `{elapsed}`) between updates: drawn only at an
    /// update, a batch's bar first showed when its first job ended, minutes in (a sweep).
    pub fn counting(template: &str) -> Progress {
        Progress(std::io::stderr().is_terminal().then(|| {
            let bar = ProgressBar::new(1);
            if let Ok(style) = ProgressStyle::with_template(template) {
                bar.set_style(style);
            }
            bar.enable_steady_tick(TICK);
            bar
        }))
    }

    /// A spinner with a message, for work without a count.
    pub fn spinner(message: &str) -> Progress {
        Progress(std::io::stderr().is_terminal().then(|| {
            let bar = ProgressBar::new_spinner();
            if let Ok(style) = ProgressStyle::with_template("{spinner} {msg} {elapsed}") {
                bar.set_style(style);
            }
            bar.set_message(message.to_string());
            bar.enable_steady_tick(TICK);
            bar
        }))
    }

    pub fn update(&self, done: usize, total: usize) {
        if let Some(bar) = &self.0 {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
        }
    }

    pub fn message(&self, message: &str) {
        if let Some(bar) = &self.0 {
            bar.set_message(message.to_string());
        }
    }

    /// A line on stderr above the bar (a warning while it runs), escaped as every printed
    /// line is (`output::printable`: a batch's warnings naming a preset's path wrote its
    /// bidirectional controls raw, and its note of an earlier index's jobs file everything).
    pub fn println(&self, line: &str) {
        let line = &crate::output::printable(line);
        match &self.0 {
            Some(bar) => bar.println(line),
            None => eprintln_unless_closed(line),
        }
    }

    /// Runs `f` (a line on stdout) with the bar kept out of its way.
    pub fn suspend<R>(&self, f: impl FnOnce() -> R) -> R {
        match &self.0 {
            Some(bar) => bar.suspend(f),
            None => f(),
        }
    }

    pub fn finish(self) {
        if let Some(bar) = self.0 {
            bar.finish_and_clear();
        }
    }
}
