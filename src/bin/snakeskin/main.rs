//! The `snakeskin` binary: parse the command line into typed values (`cli`), call the
//! library (`cmd/`, one file per command), print, and map errors to exit codes — 2 when the
//! user's input is at fault, 1 for anything else. The library neither parses arguments nor
//! prints; everything a user sees on a terminal is written from here.

mod cli;
mod cmd;
mod output;
mod progress;

use std::process::ExitCode;

fn main() -> ExitCode {
    output::restore_default_sigpipe();
    output::file_size_limit_is_an_error();
    output::stdout_failure_is_an_error();
    output::quiet_vulkan_device_select();
    snakeskin::memory::bound_arenas_under_address_limit();
    // Spawns a thread: after the calls above, which need the process single-threaded.
    output::clean_up_on_interrupt();
    let cli = cli::Cli::try_parse_checked_from(std::env::args_os().collect()).unwrap_or_else(|e| e.exit());
    match cmd::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            // A failed run leaves no empty folder it made for its outputs (`preview --out
            // new/x.png` that failed left `new`).
            snakeskin::export::remove_empty_made_folders();
            // A standard error that cannot be written does not change the run's exit code (an
            // `eprintln!` there was status 1 from the panic hook, where invalid input is 2).
            use std::io::Write;
            let _ = writeln!(std::io::stderr(), "error: {}", output::error_message(&err));
            ExitCode::from(output::exit_code(&err))
        }
    }
}
