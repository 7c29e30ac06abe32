//! `snakeskin batch JOBS.toml -o DIR [--shard K/N] [--concurrent N] [--list]`: many sets, resumable, with a
//! progress bar over jobs and one summary line.

use anyhow::Result;

use crate::cli::BatchArgs;
use crate::output::path_line;
use crate::progress::Progress;
use snakeskin::batch::{self, BatchProgress, JobStatus, Shard};

pub fn run(args: BatchArgs) -> Result<()> {
    let jobs = batch::load_jobs(&args.jobs).map_err(snakeskin::Error::from)?;
    let shard = args.shard.unwrap_or(Shard::ALL);
    if args.list {
        let listed = batch::list(&args.jobs, &jobs, &args.out, shard)?;
        for job in &listed {
            println!("{:>6}  {:<9}  {}", job.index, job.status, path_line(&args.out.join(&job.folder)));
        }
        if listed.is_empty() {
            // It printed nothing at all (a shard past the file's last job).
            eprintln!("note: no jobs in shard {shard} ({} in the file)", counted(jobs.len(), "job"));
        }
        return Ok(());
    }
    // The job lines below are written while jobs run: a reader that goes away (`| head`)
    // must not end the batch by SIGPIPE mid-commit, with its locks and temporaries left.
    crate::output::ignore_sigpipe();
    let mut log = JobLog::default();
    let had_folder = args.out.is_dir();
    let bar = Progress::counting("{spinner} batch [{bar:30}] {pos}/{len} jobs {elapsed} {msg}");
    // Said while the jobs are planned (each preset loaded, each set there already hashed:
    // 100,000 jobs took 46 s) and while they run, which jobs: the bar showed nothing until
    // the first job ended, and stood still between jobs (an 8K set: 85 s; a sweep).
    bar.update(0, jobs.len());
    bar.message(&format!("planning {} (loading presets, checking the sets there)", counted(jobs.len(), "job")));
    let mut making: Vec<String> = Vec::new();
    // The set `folder` is no longer being made (it ended, failed or never began).
    let made = |making: &mut Vec<String>, folder: &std::path::Path| {
        let folder = path_line(folder);
        making.retain(|f| *f != folder);
        bar.message(&making_words(making));
    };
    let concurrency = args.concurrent.map_or_else(batch::default_concurrency, |n| n as usize);
    let mut warn = |warning: &str| bar.println(warning);
    let result = batch::run(&args.jobs, &jobs, &args.out, shard, concurrency, &mut warn, &mut |event| match event {
        BatchProgress::Planned { total } => {
            bar.update(0, total);
            bar.message("");
        }
        BatchProgress::Started { outcome } => {
            making.push(path_line(&outcome.folder));
            bar.message(&making_words(&making));
        }
        // (A failed job's error ends the run; the bar stops saying it makes the set.)
        BatchProgress::Left { outcome } => made(&mut making, &outcome.folder),
        BatchProgress::Ended { done, total, outcome } => {
            bar.update(done, total);
            made(&mut making, &outcome.folder);
            // One line a job on stdout as well, as `generate` prints the paths it wrote: a
            // redirected run (an array job's log) said nothing until its summary, and nothing
            // of what it had finished when a signal ended it.
            bar.suspend(|| {
                log.line(&format!("{done}/{total} {} {}", outcome.status, path_line(&args.out.join(&outcome.folder))))
            });
            for kept in &outcome.kept {
                bar.println(&format!("warning: {}", crate::output::kept_words(kept)));
            }
        }
    });
    // A run a job stopped still ends with its summary (what ran, what failed, what never
    // started: the index says which), then the job's error.
    let (index, index_error, failure) = match result {
        Ok(index) => (index, None, None),
        Err(snakeskin::Error::Batch(batch::BatchError::Stopped { index, index_error, source })) => {
            (*index, index_error, Some(*source))
        }
        Err(e) => return Err(e.into()),
    };
    bar.finish();
    if !had_folder && args.out.is_dir() {
        crate::progress::eprintln_unless_closed(&format!("note: created folder {}", path_line(&args.out)));
    }
    let count = |status: JobStatus| index.jobs.iter().filter(|j| j.status == status).count();
    let mut counts = format!("{} run, {} already done", count(JobStatus::Done), count(JobStatus::Skipped));
    let duplicates = count(JobStatus::Duplicate);
    if duplicates > 0 {
        // "1 duplicate of another job", not "1 duplicates" (a hostile-input sweep's nit).
        counts.push_str(&format!(", {} of another job", counted(duplicates, "duplicate")));
    }
    for (status, words) in [(JobStatus::Failed, "failed"), (JobStatus::NotRun, "not run")] {
        if count(status) > 0 {
            counts.push_str(&format!(", {} {words}", count(status)));
        }
    }
    let index_file = path_line(&args.out.join(batch::index_file_name(shard)));
    let index_said = match index_error {
        // The file there is the index the run started with (its jobs `to do`).
        Some(e) => format!("the index was not written ({e}): {index_file} lists the jobs as the run started"),
        None => format!("index: {index_file}"),
    };
    log.line(&format!(
        "{} of {} in shard {}, up to {} at once: {counts}; {index_said}",
        counted(index.jobs.len(), "job"),
        jobs.len(),
        index.shard,
        index.concurrency,
    ));
    if let Some(failure) = failure {
        return Err(failure.into());
    }
    log.finish()
}

/// The batch's lines on stdout. A write that fails stops the lines, not the batch (its jobs
/// run on); afterwards a closed pipe ends the run quietly, and another failure (a full
/// disk, `> /dev/full`) is the run's error, as for every command.
#[derive(Default)]
struct JobLog {
    failed: Option<std::io::Error>,
}

impl JobLog {
    fn line(&mut self, line: &str) {
        use std::io::Write;
        if self.failed.is_none()
            && let Err(e) = writeln!(std::io::stdout(), "{line}")
        {
            self.failed = Some(e);
        }
    }

    fn finish(self) -> Result<()> {
        match self.failed {
            Some(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
                Err(anyhow::anyhow!("cannot write to standard output: {e}"))
            }
            _ => Ok(()),
        }
    }
}

/// The bar's words for the sets being made: the first, and how many more.
fn making_words(making: &[String]) -> String {
    match making {
        [] => String::new(),
        [one] => format!("making {one}"),
        [first, rest @ ..] => format!("making {first} and {} more", rest.len()),
    }
}

/// `1 job`, `2 jobs`.
fn counted(n: usize, what: &str) -> String {
    if n == 1 { format!("1 {what}") } else { format!("{n} {what}s") }
}
