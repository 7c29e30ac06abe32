//! What the binary prints, and how: errors once each and free of terminal control codes,
//! notes about what a command did on the user's behalf, and the usual behaviour of a Unix
//! tool whose reader goes away (`snakeskin presets list | head -1` ends quietly) or that
//! is interrupted (Ctrl-C leaves no unfinished files behind).

use std::path::Path;

/// A closed pipe ends the process quietly by SIGPIPE (exit status 141 in a shell), as `cat`
/// or `ls` do. Rust ignores SIGPIPE by default, which turns every `println!` into a panic
/// ("failed printing to stdout: Broken pipe", exit 101) once the reader has gone.
pub fn restore_default_sigpipe() {
    #[cfg(unix)]
    // SAFETY: called first thing in `main`, before any other thread exists; SIG_DFL is a
    // valid disposition for SIGPIPE.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// SIGPIPE ignored from here on: a write to a closed pipe fails with `BrokenPipe`, for a
/// command that writes while it works (`batch`'s job lines) to stop writing and go on.
pub fn ignore_sigpipe() {
    #[cfg(unix)]
    // SAFETY: SIG_IGN is a valid disposition for SIGPIPE; `signal` is process-wide and may
    // be called from any thread.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_IGN);
    }
}

/// A file that outgrows the file-size limit (`ulimit -f`) fails its write with "File too
/// large" (EFBIG), an error like a full disk's: the run removes its unfinished files and
/// says which file, and the earlier set stays. By default the kernel's SIGXFSZ ended the
/// process there instead (exit 153, nothing said), leaving the temporaries and the set's
/// lock file until the next run in that folder.
pub fn file_size_limit_is_an_error() {
    #[cfg(unix)]
    // SAFETY: called in `main` before any other thread exists; SIG_IGN is a valid
    // disposition for SIGXFSZ, under which write(2) returns EFBIG at the limit.
    unsafe {
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
}

/// Ctrl-C, SIGTERM or SIGHUP end the run without leaving its unfinished files: a commit in
/// progress ends first (a set is never left mixed), the run's temporaries, its set lock
/// files and the empty folders it made are removed (`export::clean_up_before_exit`), one
/// line says so, and the exit status is 128 + the
/// signal's number, as a shell reports a process that a signal ended (or the run's own, if
/// it finished meanwhile). Before, the hidden temporaries (up to a set's size) stayed until
/// the next run in that folder. A second signal exits at once, but not in the middle of a
/// commit's renames: it waits for them, at most `SECOND_SIGNAL_COMMIT_WAIT` (a commit takes
/// milliseconds; the limit is the way out of a rename that hangs). A signal that was ignored
/// when the process started (`nohup` ignores SIGHUP; a non-interactive shell's background
/// job, SIGINT) stays ignored.
pub fn clean_up_on_interrupt() {
    #[cfg(unix)]
    {
        use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
        let caught: Vec<i32> = [SIGINT, SIGTERM, SIGHUP].into_iter().filter(|s| !ignored_from_the_start(*s)).collect();
        let Ok(mut signals) = signal_hook::iterator::Signals::new(caught) else {
            return;
        };
        std::thread::spawn(move || {
            if let Some(signal) = signals.forever().next() {
                // A second signal ends the run at once, should the clean-up wait on a commit
                // that hangs (a rename on a stalled network drive).
                std::thread::spawn(move || {
                    if let Some(again) = signals.forever().next() {
                        snakeskin::export::wait_for_commit(SECOND_SIGNAL_COMMIT_WAIT);
                        std::process::exit(128 + again);
                    }
                });
                let removed = snakeskin::export::clean_up_before_exit();
                let name = match signal {
                    SIGINT => "SIGINT",
                    SIGTERM => "SIGTERM",
                    _ => "SIGHUP",
                };
                let what = if removed > 0 { format!(": removed {removed} unfinished file(s)") } else { String::new() };
                use std::io::Write;
                let _ = writeln!(std::io::stderr(), "interrupted ({name}){what}");
                std::process::exit(128 + signal);
            }
        });
    }
}

/// How long a second signal waits for a commit's renames to end (`clean_up_on_interrupt`).
const SECOND_SIGNAL_COMMIT_WAIT: std::time::Duration = std::time::Duration::from_secs(10);

/// Whether `signal`'s disposition is "ignore", as the process inherited it (called before
/// any handler is installed).
#[cfg(unix)]
fn ignored_from_the_start(signal: i32) -> bool {
    // SAFETY: a query (no new action) into a zeroed `sigaction`, which is plain data.
    unsafe {
        let mut current: libc::sigaction = std::mem::zeroed();
        libc::sigaction(signal, std::ptr::null(), &mut current) == 0 && current.sa_sigaction == libc::SIG_IGN
    }
}

/// A standard output that fails for another reason than a closed pipe (a full disk,
/// `> /dev/full`, an I/O error) is an error like any other: one line on stderr and exit
/// status 1, not a panic (exit 101). `println!` panics with std's message "failed printing to
/// stdout: REASON"; the hook turns exactly that panic into the error, at every print site
/// alike, and leaves every other panic to the default hook. A standard error that fails
/// (`2> /dev/full`) while a run goes on (a note, a warning) ends it with status 1 too, saying
/// nothing (there is nowhere to say it): `eprintln!` panicked and the default hook's message
/// failed as well, exit 101. Either way its unfinished files are removed first, as on a
/// signal. A run's final error is written without `eprintln!` (`main`), so
/// its exit code stays the error's own.
pub fn stdout_failure_is_an_error() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let message = payload.downcast_ref::<String>().map(String::as_str).or(payload.downcast_ref::<&str>().copied());
        // Both exits leave what a signal's leaves (`clean_up_before_exit`): a batch whose
        // warning failed mid-run left its running jobs' lock files and the folders made for
        // them. No print happens under the clean-up's locks (the library prints nothing).
        if let Some(reason) = message.and_then(|m| m.strip_prefix("failed printing to stdout: ")) {
            snakeskin::export::clean_up_before_exit();
            use std::io::Write;
            let _ = writeln!(std::io::stderr(), "error: cannot write to standard output: {}", printable(reason));
            std::process::exit(1);
        }
        if message.is_some_and(|m| m.starts_with("failed printing to stderr: ")) {
            snakeskin::export::clean_up_before_exit();
            std::process::exit(1);
        }
        default(info);
    }));
}

/// Mesa's Vulkan `device_select` layer (an implicit layer, loaded into every Vulkan program)
/// connects to the Wayland display to order the GPUs; without `XDG_RUNTIME_DIR` libwayland
/// prints "error: XDG_RUNTIME_DIR is invalid or not set in the environment." twice per run
/// (found with a breakpoint on `wl_display_connect`). The layer's ordering is not needed —
/// wgpu picks the adapter itself — so where that message would appear the layer is switched
/// off with Mesa's own `NODEVICE_SELECT`, unless the user has set it.
pub fn quiet_vulkan_device_select() {
    let runtime_dir_usable = std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| Path::new(&d).is_dir());
    let user_chose =
        std::env::var_os("NODEVICE_SELECT").is_some() || std::env::var_os("MESA_VK_DEVICE_SELECT").is_some();
    if !runtime_dir_usable && !user_chose {
        // SAFETY: called first thing in `main`, before any other thread exists.
        unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
    }
}

/// The error and its causes, each said once: a cause whose text its parent already
/// includes (thiserror's "cannot write X: {source}" wrapping an OS error) is not repeated.
/// Control characters (e.g. ANSI escapes copied from a preset) are shown escaped, never
/// sent raw to the terminal.
pub fn error_message(err: &anyhow::Error) -> String {
    let mut message = String::new();
    let mut parent = String::new();
    for cause in err.chain() {
        let text = cause.to_string();
        if parent.contains(&text) {
            continue;
        }
        parent = text.clone();
        if !message.is_empty() {
            message.push_str(": ");
        }
        message.push_str(&text);
    }
    printable(&message).lines().map(shortened).collect::<Vec<_>>().join("\n")
}

/// Characters of an error's line kept at its start and at its end when it is longer than
/// both with `LINE_GAP_AT_LEAST` between: a value repeated from the input can be as long as
/// the input (a jobs file's 400,000-character preset name made an 800 KB message, the name
/// twice). A line of two paths at their longest (4096 bytes each on Linux) is whole.
const LINE_HEAD_CHARS: usize = 8192;
const LINE_TAIL_CHARS: usize = 1024;
const LINE_GAP_AT_LEAST: usize = 1024;

/// `line`, or its head and tail with how much was left out between them.
fn shortened(line: &str) -> String {
    let count = line.chars().count();
    if count <= LINE_HEAD_CHARS + LINE_GAP_AT_LEAST + LINE_TAIL_CHARS {
        return line.to_string();
    }
    let head: String = line.chars().take(LINE_HEAD_CHARS).collect();
    let tail: String = line.chars().skip(count - LINE_TAIL_CHARS).collect();
    format!("{head} [... {} characters left out ...] {tail}", count - LINE_HEAD_CHARS - LINE_TAIL_CHARS)
}

/// 2 when the user's input is at fault, 1 for the environment and internal failures: the
/// first typed library error in the chain decides.
pub fn exit_code(err: &anyhow::Error) -> u8 {
    use snakeskin::export::ExportError;
    for cause in err.chain() {
        if let Some(e) = cause.downcast_ref::<snakeskin::Error>() {
            return if e.is_invalid_input() { 2 } else { 1 };
        }
        if cause.is::<snakeskin::preset::PresetError>() {
            return 2;
        }
        if let Some(e) = cause.downcast_ref::<ExportError>() {
            return if e.is_invalid_input() { 2 } else { 1 };
        }
    }
    1
}

/// `text` with every control character but newline and tab, and every character that
/// reorders text or breaks its lines (`export::reshapes_text`), written as `\u{..}`.
pub fn printable(text: &str) -> String {
    let hidden = |c: char| (c.is_control() && c != '\n' && c != '\t') || snakeskin::export::reshapes_text(c);
    text.chars().map(|c| if hidden(c) { c.escape_unicode().to_string() } else { c.to_string() }).collect()
}

/// A path for a line of its own (stdout lists one file per line): newlines escaped too.
pub fn path_line(path: &Path) -> String {
    printable(&path.display().to_string()).replace('\n', "\\n")
}

/// A file of the set's names that stayed beside the new set (`GenerateReport::kept`), in words:
/// its path escaped as every listed path is, and why.
pub fn kept_words(kept: &snakeskin::export::KeptFile) -> String {
    let which = match kept.by {
        snakeskin::export::Earlier::Set => "which this set does not write",
        snakeskin::export::Earlier::Export => "which this export does not reference",
    };
    format!("kept {}, {which}: {}", path_line(&kept.path), kept.reason())
}

/// Creates the folder a single output file goes into when it is missing, and says so on
/// stderr; refuses a folder standing where the file goes, and one that takes no new file
/// (`export::check_writable`), before any work is done for it. Every command treats output
/// paths alike: `generate -o DIR`, `preview --out`, `preview --reference`, `sheet -o` and the
/// rest create missing folders with this note.
pub fn ensure_parent_folder(file: &Path) -> anyhow::Result<()> {
    // The file first: a refused name leaves no folder made for it.
    snakeskin::export::check_target(file)?;
    if let Some(folder) = file.parent().filter(|p| !p.as_os_str().is_empty()) {
        ensure_folder(folder)?;
    }
    // A read-only folder was found after the work: seconds of rendering (minutes with a
    // preview's CPU reference), then "cannot write ro: Permission denied".
    snakeskin::export::check_writable(file)?;
    Ok(())
}

/// Creates an output folder when it is missing, with a note on stderr; a path that exists
/// but is not a folder is refused, naming it. The folders made are noted
/// (`export::create_folder_noted`): a run that fails or is interrupted takes them away again
/// when they are still empty (`main`, `clean_up_before_exit`).
pub fn ensure_folder(folder: &Path) -> anyhow::Result<()> {
    if snakeskin::export::create_folder_noted(folder)? {
        eprintln!("note: created folder {}", path_line(folder));
    }
    Ok(())
}

/// Prints the preset's warnings (`LoadedPreset::warnings`): colours the layer stack cannot
/// show and what they were clamped to, once per key, and where the model is darker than
/// the physics.
pub fn report_warnings(preset: &str, loaded: &snakeskin::preset::LoadedPreset) {
    for warning in loaded.warnings(preset, snakeskin::preset::SET_FLAG) {
        eprintln!("{}", printable(&warning));
    }
}

/// A warning when `memory` is close to what is available (`MemoryCheck::is_tight`): `what`
/// ("this set") needs about N MiB at its peak, and where the limit comes from.
pub fn report_tight_memory(memory: &snakeskin::memory::MemoryCheck, what: &str) {
    if memory.is_tight() {
        eprintln!(
            "warning: {what} needs about {} MiB at its peak; {} MiB are available {}",
            memory.needed_mib(),
            memory.available_mib(),
            memory.bound.place()
        );
    }
}
