//! `snakeskin batch`: a batch killed with SIGKILL and run again redoes only the jobs that had
//! not finished, leaves the finished ones untouched, and ends with exactly the files of an
//! uninterrupted run; shards split the jobs with nothing run twice or left out.

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant, SystemTime};

use common::{snakeskin, spawn_paused_at_commit, stderr, stdout, test_hooks_exist, write_preset};

/// Every file under `dir` (relative path → bytes), index files left out (they record what
/// each run did, which differs between the runs compared).
fn tree(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<PathBuf, Vec<u8>>) {
        for entry in std::fs::read_dir(dir).unwrap().flatten() {
            let path = entry.path();
            if path.is_dir() {
                walk(root, &path, out);
            } else if !path.file_name().unwrap().to_string_lossy().starts_with("index") {
                out.insert(path.strip_prefix(root).unwrap().into(), std::fs::read(&path).unwrap());
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

/// The manifests under `dir` with each file's modification time, for "left untouched".
/// Safe while a batch is writing there: files that vanish between listing and reading
/// (its temporaries, renamed into place) are passed over.
fn manifests(dir: &Path) -> BTreeMap<PathBuf, SystemTime> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<PathBuf, SystemTime>) {
        let Ok(entries) = std::fs::read_dir(dir) else { return };
        for entry in entries.flatten() {
            let path = entry.path();
            let Ok(meta) = std::fs::symlink_metadata(&path) else { continue };
            if meta.is_dir() {
                walk(root, &path, out);
            } else if path.to_string_lossy().ends_with(".material.json")
                && let Ok(modified) = meta.modified()
            {
                out.insert(path.strip_prefix(root).unwrap().into(), modified);
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

fn jobs_file(dir: &Path, species: &[&str], seeds: &str, size: u32) -> PathBuf {
    let text: String =
        species.iter().map(|s| format!("[[job]]\npreset = \"{s}\"\nseeds = {seeds}\nsizes = [{size}]\n\n")).collect();
    let path = dir.join("jobs.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// The index a run wrote into `out` (`index.json`).
fn read_index(out: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(out.join("index.json")).unwrap()).unwrap()
}

/// Each job's status in an index, in its order.
fn statuses(index: &serde_json::Value) -> Vec<&str> {
    index["jobs"].as_array().unwrap().iter().map(|j| j["status"].as_str().unwrap()).collect()
}

/// Another preset's set of the name `preset_file` gives (seed 1, size 16), made apart, as
/// another run would make it: `preset_file` in `dir/other` holding `text`, its set under the
/// folder returned (`dir/other/out`), to be put where a test's run makes its own.
fn set_made_apart(dir: &Path, preset_file: &str, text: &str) -> PathBuf {
    let other = dir.join("other");
    std::fs::create_dir(&other).unwrap();
    std::fs::write(other.join(preset_file), text).unwrap();
    let jobs = other.join("jobs.toml");
    std::fs::write(&jobs, format!("[[job]]\npreset = \"{preset_file}\"\nseeds = [1]\nsizes = [16]\n")).unwrap();
    let out = other.join("out");
    let made = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert!(made.status.success(), "{}", stderr(&made));
    out
}

/// A `batch` run whose stderr is read on a thread of its own, so that a test can wait for
/// what it says while it runs (a job that waits for a lock the test holds), and a run that
/// never says it, or never ends, is stopped after a minute instead of hanging the test.
struct WatchedRun {
    run: std::process::Child,
    log: std::sync::mpsc::Receiver<String>,
    reader: std::thread::JoinHandle<()>,
    /// Its stderr so far.
    said: String,
}

impl WatchedRun {
    fn start(args: &[&str]) -> WatchedRun {
        let mut run = Command::new(env!("CARGO_BIN_EXE_snakeskin"))
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let (lines, log) = std::sync::mpsc::channel::<String>();
        let stderr_pipe = std::io::BufReader::new(run.stderr.take().unwrap());
        let reader = std::thread::spawn(move || {
            use std::io::BufRead;
            for line in stderr_pipe.lines().map_while(Result::ok) {
                let _ = lines.send(line + "\n");
            }
        });
        WatchedRun { run, log, reader, said: String::new() }
    }

    /// Returns once the run has said `text` `times` times on stderr.
    fn until_said(&mut self, text: &str, times: usize) {
        while self.said.matches(text).count() < times {
            match self.log.recv_timeout(Duration::from_secs(60)) {
                Ok(line) => self.said += &line,
                Err(e) => {
                    let _ = self.run.kill();
                    let _ = self.run.wait();
                    panic!("the run did not say {text:?} {times} times ({e:?}): {}", self.said);
                }
            }
        }
    }

    /// Waits for the run to end: its status, all it said on stderr and its stdout.
    fn end(mut self) -> (std::process::ExitStatus, String, String) {
        let start = Instant::now();
        let status = loop {
            if let Some(status) = self.run.try_wait().unwrap() {
                break status;
            }
            if start.elapsed() > Duration::from_secs(60) {
                let _ = self.run.kill();
                let _ = self.run.wait();
                panic!("the run went on after a minute: {}", self.said);
            }
            std::thread::sleep(Duration::from_millis(20));
        };
        self.reader.join().unwrap();
        let said = self.said + &self.log.try_iter().collect::<String>();
        let stdout = std::io::read_to_string(self.run.stdout.take().unwrap()).unwrap();
        (status, said, stdout)
    }
}

fn summary_counts(out: &std::process::Output) -> (usize, usize) {
    // "40 jobs of 40 in shard 0/1, up to 2 at once: 33 run, 7 already done; index: …"
    let text = stdout(out);
    let summary = text.lines().last().unwrap_or_default();
    let after = summary.split(": ").nth(1).unwrap_or_else(|| panic!("no summary in {text:?}"));
    let numbers: Vec<usize> =
        after.split(|c: char| !c.is_ascii_digit()).filter_map(|n| n.parse().ok()).take(2).collect();
    (numbers[0], numbers[1])
}

const SPECIES: [&str; 20] = [
    "acanthophis-antarcticus",
    "ahaetulla-nasuta",
    "bitis-arietans",
    "bitis-gabonica",
    "boa-constrictor",
    "bothrops-alternatus",
    "bungarus-fasciatus",
    "corallus-caninus",
    "crotalus-atrox",
    "dendroaspis-polylepis",
    "diadophis-punctatus",
    "elaphe-climacophora",
    "epicrates-cenchria",
    "hydrophis-platurus",
    "lampropeltis-triangulum",
    "liasis-mackloti",
    "micrurus-diastema",
    "natrix-natrix",
    "python-regius",
    "xenopeltis-unicolor",
];

/// Every file and folder under `dir`, relative to it.
fn entries(dir: &Path) -> Vec<PathBuf> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap().flatten() {
            let path = entry.path();
            out.push(path.strip_prefix(root).unwrap().into());
            if path.is_dir() {
                walk(root, &path, out);
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

/// Under `out`, nothing hidden (a lock file, a temporary) and no folder that holds no
/// finished set: what an ended batch may leave.
fn only_finished_sets_in(out: &Path) {
    let finished = manifests(out);
    for path in entries(out) {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        assert!(!name.starts_with('.'), "{} was left", path.display());
        assert!(
            !out.join(&path).is_dir() || finished.keys().any(|m| m.starts_with(&path)),
            "{} holds no finished set: {:?}",
            path.display(),
            entries(out)
        );
    }
}

/// A log reader that goes away (`batch ... | head -1`) does not end the batch: the job lines
/// stop and every job still runs (by SIGPIPE, the batch ended at its second line with its
/// running jobs' locks and temporaries left; the review).
#[test]
fn a_closed_log_pipe_does_not_stop_the_batch() {
    use std::io::BufRead;
    let dir = tempfile::tempdir().unwrap();
    let jobs = jobs_file(dir.path(), &SPECIES[..3], "[1, 2]", 128);
    let out = dir.path().join("out");
    let mut child = Command::new(env!("CARGO_BIN_EXE_snakeskin"))
        .args(["batch", jobs.to_str().unwrap(), "-o", out.to_str().unwrap()])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut first = String::new();
    std::io::BufReader::new(child.stdout.take().unwrap()).read_line(&mut first).unwrap();
    assert!(first.starts_with("1/6 done "), "{first}");
    // The reader is dropped here: the pipe is closed.
    let status = child.wait().unwrap();
    assert!(status.success(), "{status:?}");
    assert_eq!(manifests(&out).len(), 6);
    assert!(entries(&out).iter().all(|p| !p.file_name().unwrap().to_string_lossy().starts_with('.')));
    // Its notes and its lines in one pipe whose reader went away (`2>&1 | head`): a whole
    // batch, every set made and its index written, exited 1 without a word at its last note
    // ("created folder"). The reader is gone before the run starts, so that every line and
    // note meets the closed pipe however fast the run is.
    std::fs::remove_dir_all(&out).unwrap();
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let mut child = {
        let mut command = Command::new(env!("CARGO_BIN_EXE_snakeskin"));
        command.args(["batch", jobs.to_str().unwrap(), "-o", out.to_str().unwrap()]);
        command.stdout(writer.try_clone().unwrap()).stderr(writer);
        command.spawn().unwrap()
    };
    let status = child.wait().unwrap();
    assert!(status.success(), "2>&1: {status:?}");
    assert_eq!(manifests(&out).len(), 6);
}

/// Ctrl-C or SIGTERM: the batch ends with 128 + the signal and leaves its finished sets and
/// nothing else: no lock file in a set's folder, no folder holding a lock alone (both were
/// left until a later run took the lock), no temporary; and its log has a line for each set
/// it finished, but for one whose commit the signal waited for (its job ends after the
/// clean-up, at most one a running job).
#[cfg(unix)]
#[test]
fn an_interrupted_batch_leaves_its_finished_sets_and_nothing_else() {
    let dir = tempfile::tempdir().unwrap();
    let jobs = jobs_file(dir.path(), &SPECIES[..6], "[1, 2]", 256);
    let out = dir.path().join("out");
    for signal in [libc::SIGINT, libc::SIGTERM] {
        let _ = std::fs::remove_dir_all(&out);
        let child = Command::new(env!("CARGO_BIN_EXE_snakeskin"))
            .args(["batch", jobs.to_str().unwrap(), "-o", out.to_str().unwrap()])
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let start = Instant::now();
        while manifests(&out).len() < 2 {
            assert!(start.elapsed() < Duration::from_secs(300), "the batch made no progress");
            std::thread::sleep(Duration::from_millis(10));
        }
        // SAFETY: `kill` with a child's own pid and a valid signal number.
        assert_eq!(unsafe { libc::kill(child.id() as i32, signal) }, 0);
        let ended = child.wait_with_output().unwrap();
        let finished = manifests(&out);
        assert!(finished.len() < 12, "the signal came too late to test anything");
        assert_eq!(ended.status.code(), Some(128 + signal), "{}", stderr(&ended));
        only_finished_sets_in(&out);
        // The index written as the run started: this jobs file's twelve jobs.
        let index = read_index(&out);
        assert_eq!((index["jobs_file"].as_str(), index["jobs"].as_array().map(Vec::len)), (jobs.to_str(), Some(12)));
        // Every set logged is there; a set whose commit the signal waited for is whole but
        // may go unlogged (its job ends after the clean-up), one a job at most.
        let log = stdout(&ended);
        let logged: Vec<&str> = log.lines().filter_map(|l| l.split_once(" done ").map(|(_, folder)| folder)).collect();
        for folder in &logged {
            assert!(finished.keys().any(|m| out.join(m).starts_with(folder)), "{folder} logged, not there");
        }
        assert!(finished.len() - logged.len() <= 2, "{} sets, {} logged", finished.len(), logged.len());
    }
}

/// A standard error that fails while jobs run (`2> /dev/full`, a warning of a file kept
/// beside a finished set) ends the batch with status 1 and leaves its finished sets and
/// nothing else, as a signal does: the running job's lock file and the folder made for it
/// stayed (the panic hook exited without the clean-up).
#[cfg(target_os = "linux")]
#[test]
fn a_failing_standard_error_mid_batch_leaves_nothing_unfinished() {
    let dir = tempfile::tempdir().unwrap();
    let jobs = dir.path().join("jobs.toml");
    // The first job finishes long before the second (a larger set), which is running when
    // the first one's warning is written.
    let text = "[[job]]\npreset = \"natrix-natrix\"\nseeds = [1]\nsizes = [16]\n\n\
                [[job]]\npreset = \"python-regius\"\nseeds = [1]\nsizes = [1024]\n";
    std::fs::write(&jobs, text).unwrap();
    let out = dir.path().join("out");
    let first = out.join("natrix-natrix/tile-16-seed1-png");
    std::fs::create_dir_all(&first).unwrap();
    std::fs::write(first.join("natrix-natrix_color.exr"), b"not this set's").unwrap();
    let full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
    let ended = Command::new(env!("CARGO_BIN_EXE_snakeskin"))
        .args(["batch", jobs.to_str().unwrap(), "-o", out.to_str().unwrap(), "--concurrent", "2"])
        .stdout(Stdio::piped())
        .stderr(full)
        .output()
        .unwrap();
    assert_eq!(ended.status.code(), Some(1), "{}", stdout(&ended));
    let finished = manifests(&out);
    assert!(!finished.keys().any(|m| m.starts_with("python-regius")), "the second job ended first: {finished:?}");
    only_finished_sets_in(&out);
}

#[test]
fn a_killed_batch_resumes_with_only_the_unfinished_jobs_and_the_same_files() {
    let dir = tempfile::tempdir().unwrap();
    let jobs = jobs_file(dir.path(), &SPECIES, "[1, 2]", 512);
    let (whole, resumed) = (dir.path().join("whole"), dir.path().join("resumed"));

    // The reference: one uninterrupted run.
    let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", whole.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(summary_counts(&out), (40, 0), "{}", stdout(&out));
    assert_eq!(manifests(&whole).len(), 40);
    // Redirected, it still says each job as it ends (it said nothing before its summary):
    // one line a job, counting up, with the set's folder.
    let lines: Vec<String> = stdout(&out).lines().map(str::to_string).collect();
    assert_eq!(lines.len(), 41, "{}", stdout(&out));
    for (k, line) in lines[..40].iter().enumerate() {
        let folder = line.strip_prefix(&format!("{}/40 done ", k + 1)).unwrap_or_else(|| panic!("{line}"));
        assert!(Path::new(folder).is_dir() && folder.starts_with(whole.to_str().unwrap()), "{line}");
    }

    // The same batch, killed with SIGKILL once a few sets are complete.
    let mut child = Command::new(env!("CARGO_BIN_EXE_snakeskin"))
        .args(["batch", jobs.to_str().unwrap(), "-o", resumed.to_str().unwrap()])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while manifests(&resumed).len() < 6 {
        assert!(start.elapsed() < Duration::from_secs(300), "the batch made no progress");
        assert!(child.try_wait().unwrap().is_none(), "the batch ended before it could be killed");
        std::thread::sleep(Duration::from_millis(20));
    }
    child.kill().unwrap(); // SIGKILL: no destructor, no cleanup
    child.wait().unwrap();
    let finished = manifests(&resumed);
    assert!(finished.len() < 40, "the kill came too late to test anything");

    // Run again: only the unfinished jobs run, and the finished sets are not rewritten.
    let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", resumed.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let (ran, skipped) = summary_counts(&out);
    assert_eq!(skipped, finished.len(), "{}", stdout(&out));
    assert_eq!(ran + skipped, 40);
    let after = manifests(&resumed);
    for (manifest, modified) in &finished {
        assert_eq!(after[manifest], *modified, "{} was rewritten", manifest.display());
    }

    // Every file as in the uninterrupted run, and nothing else (no temporaries, no locks).
    let (a, b) = (tree(&whole), tree(&resumed));
    let only_whole: Vec<_> = a.keys().filter(|k| !b.contains_key(*k)).collect();
    let only_resumed: Vec<_> = b.keys().filter(|k| !a.contains_key(*k)).collect();
    assert!(
        only_whole.is_empty() && only_resumed.is_empty(),
        "only in the uninterrupted run: {only_whole:?}; only in the resumed one: {only_resumed:?}"
    );
    for (path, bytes) in &a {
        assert!(b[path] == *bytes, "{} differs from the uninterrupted run", path.display());
    }

    // A third run has nothing to do; the index lists all 40 jobs.
    let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", resumed.to_str().unwrap()]);
    assert_eq!(summary_counts(&out), (0, 40), "{}", stdout(&out));
    let index = read_index(&resumed);
    assert_eq!(index["jobs"].as_array().unwrap().len(), 40);
}

#[test]
fn shards_split_the_jobs_without_overlap_and_a_changed_job_is_redone() {
    let dir = tempfile::tempdir().unwrap();
    let jobs = jobs_file(dir.path(), &["natrix-natrix", "python-regius", "vipera-berus"], "[1, 2, 3]", 32);
    let out_dir = dir.path().join("out");
    let mut total = 0;
    for k in 0..4 {
        let shard = format!("{k}/4");
        let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", out_dir.to_str().unwrap(), "--shard", &shard]);
        assert!(out.status.success(), "{}", stderr(&out));
        let (ran, skipped) = summary_counts(&out);
        assert_eq!(skipped, 0, "shard {shard} found another shard's job done: {}", stdout(&out));
        total += ran;
        assert!(out_dir.join(format!("index.shard-{k}-of-4.json")).is_file());
    }
    assert_eq!(total, 9);
    assert_eq!(manifests(&out_dir).len(), 9);

    // The same jobs with a different preset value are different jobs: a set written for
    // other options is not taken for this one.
    let text =
        std::fs::read_to_string(&jobs).unwrap().replace("sizes = [32]", "sizes = [32]\nset = { \"scales.rows\" = 17 }");
    std::fs::write(&jobs, text).unwrap();
    let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", out_dir.to_str().unwrap()]);
    assert_eq!(summary_counts(&out), (9, 0), "{}", stdout(&out));

    // A bad jobs file is refused with its line, exit 2, and nothing written.
    std::fs::write(&jobs, "[[job]]\npreset = \"natrix-natrix\"\nseed = [1]\n").unwrap();
    let empty = dir.path().join("empty");
    let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", empty.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("jobs.toml:3:"), "{}", stderr(&out));
    assert!(!empty.exists());
    // A value of the wrong type names its key, not serde's Rust type.
    std::fs::write(&jobs, "[[job]]\npreset = \"natrix-natrix\"\nsizes = \"big\"\n").unwrap();
    let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", empty.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("jobs.toml:3:9: [[job]] 1: key `sizes`: invalid type"), "{}", stderr(&out));
    assert!(stderr(&out).contains("expected an array") && !stderr(&out).contains("sequence"), "{}", stderr(&out));
    assert!(!empty.exists());
    // Tables and list items are counted from 1 in every message (a missing preset said
    // "key `job.2`" of the third table, an item "key `sizes.0`"), and `[job]` is told to
    // be `[[job]]` (it said "invalid type: table, expected an array").
    for (text, says) in [
        (
            "[[job]]\npreset = \"natrix-natrix\"\n[[job]]\nseeds = [1]\n",
            "jobs.toml:3:1: [[job]] 2: missing field `preset`: every job names its preset",
        ),
        (
            "[[job]]\npreset = \"natrix-natrix\"\nsizes = [64, \"a\"]\n",
            "jobs.toml:3:14: [[job]] 1: key `sizes`, item 2: invalid type: string \"a\"",
        ),
        ("[job]\npreset = \"natrix-natrix\"\n", "jobs.toml:1:1: write each job as a [[job]] table"),
        // A value repeated from the file is cut short in the message (400,000 characters of
        // preset name made 800 KB of it, the name twice).
        (&format!("[[job]]\npreset = \"{}\"\n", "a".repeat(400_000)), "characters left out ...] aaa"),
    ] {
        std::fs::write(&jobs, text).unwrap();
        let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", empty.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
        assert!(stderr(&out).contains(says), "{text}: {}", stderr(&out));
        assert!(stderr(&out).len() < 50_000, "{} bytes of message", stderr(&out).len());
        assert!(!empty.exists());
    }
    // A job written as an array is refused as one, not read field by field ("expected
    // struct JobTable with 9 elements").
    std::fs::write(&jobs, "job = [[\"natrix-natrix\", [1]]]\n").unwrap();
    let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", empty.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("jobs.toml:1:8: [[job]] 1: invalid type: array, expected a table"),
        "{}",
        stderr(&out)
    );
    assert!(!empty.exists());

    // A job that cannot run (an unknown preset) stops the batch before any job runs.
    std::fs::write(&jobs, "[[job]]\npreset = \"natrix-natrix\"\nsizes = [32]\n\n[[job]]\npreset = \"no-such-snake\"\n")
        .unwrap();
    let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", empty.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("no-such-snake"), "{}", stderr(&out));
    // ... and the message names the jobs file, the line of the job's preset and the job.
    assert!(stderr(&out).contains("jobs.toml:6: [[job]] 2 (no-such-snake): unknown preset"), "{}", stderr(&out));
    assert!(manifests(&empty).is_empty(), "a set was written before the bad job was found");
    // A name one `.toml` from a file beside the jobs file (not in the working folder) is
    // told so; the file's name then runs.
    std::fs::write(dir.path().join("my-snake.toml"), "seed = 1\n").unwrap();
    std::fs::write(&jobs, "[[job]]\npreset = \"my-snake\"\nsizes = [16]\n").unwrap();
    let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", empty.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("to read the file my-snake.toml, give its name with .toml"), "{}", stderr(&out));
    std::fs::write(&jobs, "[[job]]\npreset = \"my-snake.toml\"\nsizes = [16]\n").unwrap();
    let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", empty.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    std::fs::remove_dir_all(&empty).unwrap();
    // A pack longer than its engine loads is warned of at the job's `sizes` line (208 x 8320
    // past Unreal's 8192: `Pack::size_problem`), and the set is still made.
    let long = "[[job]]\npreset = \"natrix-natrix\"\npack = \"unreal\"\nlayout = \"body\"\n\
                set = { \"body.length\" = 40 }\nsizes = [208]\n";
    std::fs::write(&jobs, long).unwrap();
    let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", empty.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let says = "jobs.toml:6: [[job]] 1 (natrix-natrix): the unreal textures are 208 x 8320, longer than the 8192 \
                texels a side";
    assert!(stderr(&out).starts_with("warning: ") && stderr(&out).contains(says), "{}", stderr(&out));
    assert!(stderr(&out).contains("give a size of 204 or less"), "{}", stderr(&out));
    std::fs::remove_dir_all(&empty).unwrap();

    // A bad override names its job and the line of its `set` too (they had no line); an
    // empty list of seeds or sizes is refused, not read as the default, at its line.
    for (table, says) in [
        ("set = { \"scales.rwos\" = 23 }", "jobs.toml:7: [[job]] 2 (natrix-natrix): set `scales.rwos=23`: unknown key"),
        (
            "set = { \"scales.rows\" = 0 }",
            "jobs.toml:7: [[job]] 2 (natrix-natrix): built-in preset natrix-natrix (with its `set` table): key \
             `scales.rows` must be",
        ),
        ("sizes = []", "jobs.toml:7: [[job]] 2 (natrix-natrix): sizes = []: list at least one"),
        ("seeds = []", "jobs.toml:7: [[job]] 2 (natrix-natrix): seeds = []: list at least one"),
        // Refused when the job is planned (they said `error: a body atlas ...`, with no file,
        // line or job, and named a `--size` that a jobs file does not have).
        (
            "layout = \"body\"\nsizes = [5500]",
            "jobs.toml:8: [[job]] 2 (natrix-natrix, seed 31, size 5500): a body atlas 5500 wide is 66000 tall (body.length widths), over \
             the 65535 rows a map may have; give size 5461 or less, or a shorter body.length",
        ),
    ] {
        let text = format!(
            "[[job]]\npreset = \"natrix-natrix\"\nsizes = [32]\n\n[[job]]\npreset = \"natrix-natrix\"\n{table}\n"
        );
        std::fs::write(&jobs, text).unwrap();
        let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", empty.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(2), "{table}: {}", stderr(&out));
        assert!(stderr(&out).contains(says), "{table}: {}", stderr(&out));
        assert!(manifests(&empty).is_empty(), "{table}: a set was written before the bad job was found");
        // `--list` refuses what a run would refuse (a job refused when planned was listed
        // "to do").
        let listed = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", empty.to_str().unwrap(), "--list"]);
        assert_eq!(listed.status.code(), Some(2), "{table}: {}", stdout(&listed));
        assert!(stderr(&listed).contains(says), "{table}: {}", stderr(&listed));
    }
    // More memory than there is: the job's size, not `--size`.
    std::fs::write(&jobs, "[[job]]\npreset = \"natrix-natrix\"\nsizes = [32]\n\n[[job]]\npreset = \"boa-constrictor\"\nsizes = [4096]\nformat = \"exr\"\n").unwrap();
    let out = common::snakeskin_env(
        &["batch", jobs.to_str().unwrap(), "-o", empty.to_str().unwrap()],
        &[("SNAKESKIN_MEMORY_LIMIT_MIB", "300")],
    );
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("jobs.toml:7: [[job]] 2 (boa-constrictor, seed 16, size 4096): size 4096 needs about"),
        "{}",
        stderr(&out)
    );
    assert!(manifests(&empty).is_empty(), "a set was written before the job too large was found");
    // `--list` does not hold the jobs to this machine's memory: a login node lists a
    // cluster's jobs (the review found them refused there).
    let listed = common::snakeskin_env(
        &["batch", jobs.to_str().unwrap(), "-o", empty.to_str().unwrap(), "--list"],
        &[("SNAKESKIN_MEMORY_LIMIT_MIB", "300")],
    );
    assert!(listed.status.success(), "{}", stderr(&listed));
    assert_eq!(stdout(&listed).lines().count(), 2, "{}", stdout(&listed));

    // A folder in a later job's way stops the batch before the first job's set is written
    // (it was found when that job ran, after the earlier sets), naming the job, its line and
    // the seed (a table of two seeds was named without it).
    std::fs::write(&jobs, "[[job]]\npreset = \"natrix-natrix\"\nseeds = [1, 2]\nsizes = [32]\n").unwrap();
    let in_the_way = empty.join("natrix-natrix/tile-32-seed2-png/natrix-natrix_color.png");
    std::fs::create_dir_all(&in_the_way).unwrap();
    let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", empty.to_str().unwrap(), "--concurrent", "1"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("jobs.toml:2: [[job]] 1 (natrix-natrix, seed 2, size 32): cannot write"),
        "{}",
        stderr(&out)
    );
    assert!(stderr(&out).contains("a folder is in the way"), "{}", stderr(&out));
    assert!(manifests(&empty).is_empty(), "the first job's set was written before the folder was found");
    let listed = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", empty.to_str().unwrap(), "--list"]);
    assert_eq!(listed.status.code(), Some(2), "{}", stdout(&listed));
    assert!(stderr(&listed).contains("a folder is in the way"), "{}", stderr(&listed));
    assert!(in_the_way.is_dir() && std::fs::read_dir(&in_the_way).unwrap().next().is_none());
}

/// A jobs file in its own output folder, run again, resumes: the second run read the set's
/// folder `natrix-natrix/` beside the jobs file as the preset `natrix-natrix` ("it is a
/// folder; a preset must be a regular file"). And `generate NAME -o NAME`, twice, the same.
#[test]
fn a_folder_named_like_a_preset_is_not_read_as_one() {
    let dir = tempfile::tempdir().unwrap();
    let jobs = jobs_file(dir.path(), &["natrix-natrix"], "[1]", 16);
    for run in 0..2 {
        let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", dir.path().to_str().unwrap()]);
        assert!(out.status.success(), "run {run}: {}", stderr(&out));
        assert_eq!(summary_counts(&out), if run == 0 { (1, 0) } else { (0, 1) }, "{}", stdout(&out));
    }
    for run in 0..2 {
        let out = Command::new(env!("CARGO_BIN_EXE_snakeskin"))
            .args(["generate", "natrix-natrix", "-o", "natrix-natrix", "--size", "16"])
            .current_dir(dir.path())
            .output()
            .unwrap();
        assert!(out.status.success(), "run {run}: {}", stderr(&out));
    }
}

/// Something other than an empty file at a later job's lock (`.NAME.lock`: a FIFO, a link,
/// a folder, a file with content) is refused before any job runs, and by `--list`: the run
/// wrote the earlier jobs' sets and then stopped at it, and `--list` called the job "to do"
/// (the QA review). Negative control: an empty file there is a lock left by a killed run.
#[test]
fn a_non_lock_at_a_later_jobs_lock_is_refused_before_anything_runs() {
    let dir = tempfile::tempdir().unwrap();
    let jobs = jobs_file(dir.path(), &["natrix-natrix"], "[1, 2]", 16);
    let out = dir.path().join("out");
    let folder = out.join("natrix-natrix/tile-16-seed2-png");
    let lock = folder.join(".natrix-natrix.lock");
    let plant: [(&str, &dyn Fn()); 4] = [
        ("a FIFO", &|| {
            let c = std::ffi::CString::new(lock.to_str().unwrap()).unwrap();
            assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o644) }, 0);
        }),
        ("a symbolic link", &|| std::os::unix::fs::symlink(dir.path().join("elsewhere"), &lock).unwrap()),
        ("a folder", &|| std::fs::create_dir(&lock).unwrap()),
        ("holds 2 bytes", &|| std::fs::write(&lock, "hi").unwrap()),
    ];
    let run = |list: bool| {
        let mut args = vec!["batch", jobs.to_str().unwrap(), "-o", out.to_str().unwrap()];
        args.extend(list.then_some("--list"));
        snakeskin(&args)
    };
    for (said, plant) in plant {
        let _ = std::fs::remove_dir_all(&out);
        std::fs::create_dir_all(&folder).unwrap();
        plant();
        for list in [true, false] {
            let refused = run(list);
            assert_eq!(refused.status.code(), Some(2), "{said} (list {list}): {}", stderr(&refused));
            assert!(stderr(&refused).contains(said), "{said} (list {list}): {}", stderr(&refused));
        }
        assert!(!out.join("natrix-natrix/tile-16-seed1-png").exists(), "{said}: the first job ran");
    }
    let _ = std::fs::remove_dir_all(&out);
    std::fs::create_dir_all(&folder).unwrap();
    std::fs::write(&lock, "").unwrap();
    let ran = run(false);
    assert!(ran.status.success(), "an empty lock: {}", stderr(&ran));
    assert_eq!(summary_counts(&ran), (2, 0), "{}", stdout(&ran));
}

/// A set another run finished after this one was planned is not generated again: two
/// batches over the same jobs into one folder each generated every set the other had not
/// finished when it started (the QA review: 36 generations for 24 sets). Here the second job
/// of the slow run (each commit paused three seconds, a debug-build hook) is finished by a
/// quick run meanwhile.
#[test]
fn a_set_finished_by_another_run_meanwhile_is_not_generated_again() {
    if !test_hooks_exist() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let both = dir.path().join("both.toml");
    let text = |seed: u32| format!("[[job]]\npreset = \"natrix-natrix\"\nseeds = [{seed}]\nsizes = [16]\n\n");
    std::fs::write(&both, text(1) + &text(2)).unwrap();
    let second = dir.path().join("second.toml");
    std::fs::write(&second, text(2)).unwrap();
    let slow = Command::new(env!("CARGO_BIN_EXE_snakeskin"))
        .args(["batch", both.to_str().unwrap(), "-o", out.to_str().unwrap(), "--concurrent", "1"])
        .env("SNAKESKIN_TEST_PAUSE_AT", "commit")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // While the slow run's first job waits at its commit.
    std::thread::sleep(std::time::Duration::from_millis(1000));
    let quick = snakeskin(&["batch", second.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert!(quick.status.success(), "{}", stderr(&quick));
    assert_eq!(summary_counts(&quick), (1, 0), "{}", stdout(&quick));
    let manifest = out.join("natrix-natrix/tile-16-seed2-png/natrix-natrix.material.json");
    let made = std::fs::metadata(&manifest).unwrap().modified().unwrap();
    let slow = slow.wait_with_output().unwrap();
    assert!(slow.status.success(), "{}", stderr(&slow));
    assert_eq!(summary_counts(&slow), (1, 1), "the slow run generated the quick one's set: {}", stdout(&slow));
    assert_eq!(std::fs::metadata(&manifest).unwrap().modified().unwrap(), made);
}

/// A file named like a built-in (here a gallery PNG written as `-o natrix-natrix`) does not
/// replace the built-in, for `generate` in the working folder nor for a jobs file beside it:
/// before, it was read instead ("not UTF-8 text"; a text file, silently). `./NAME` reads it.
#[test]
fn a_file_named_like_a_built_in_preset_does_not_replace_it() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("natrix-natrix"), b"\x89PNG not a preset").unwrap();
    let run = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_snakeskin")).args(args).current_dir(dir.path()).output().unwrap()
    };
    let out = run(&["generate", "natrix-natrix", "-o", "out", "--size", "16"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(dir.path().join("out/natrix-natrix.material.json").exists());
    let out = run(&["generate", "./natrix-natrix", "-o", "out", "--size", "16"]);
    assert_eq!(out.status.code(), Some(2), "./NAME reads the file: {}", stderr(&out));
    assert!(stderr(&out).contains("./natrix-natrix"), "{}", stderr(&out));
    std::fs::write(dir.path().join("jobs.toml"), "[[job]]\npreset = \"natrix-natrix\"\nsizes = [16]\n").unwrap();
    let out = run(&["batch", "jobs.toml", "-o", "batch"]);
    assert!(out.status.success(), "{}", stderr(&out));
}

/// A jobs file's entry with a `/` is a path in the jobs file's folder from any working folder,
/// even where it names a folder there (refused as one): it was looked for in the working
/// folder, which read a file of that path there, or said it had no such file. Negative
/// control: the same entry naming a preset file in the jobs file's folder runs.
#[test]
fn a_jobs_entry_with_a_slash_is_in_the_jobs_folder() {
    let dir = tempfile::tempdir().unwrap();
    let jobs_dir = dir.path().join("J");
    std::fs::create_dir_all(jobs_dir.join("sub/name")).unwrap();
    std::fs::write(jobs_dir.join("jobs.toml"), "[[job]]\npreset = \"sub/name\"\nsizes = [16]\n").unwrap();
    // A preset of that path in the working folder, which the batch must not read.
    std::fs::create_dir_all(dir.path().join("sub")).unwrap();
    std::fs::write(dir.path().join("sub/name"), "seed = 1\n").unwrap();
    let run = || {
        let args = ["batch", "J/jobs.toml", "-o", "out"];
        Command::new(env!("CARGO_BIN_EXE_snakeskin")).args(args).current_dir(dir.path()).output().unwrap()
    };
    let out = run();
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("J/sub/name is a folder: name a .toml file in it"), "{}", stderr(&out));
    std::fs::remove_dir(jobs_dir.join("sub/name")).unwrap();
    std::fs::write(jobs_dir.join("sub/name"), "seed = 2\n").unwrap();
    let out = run();
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(dir.path().join("out/name/tile-16-seed2-png").is_dir(), "{}", stdout(&out));
}

/// A jobs file reached through a symbolic link reads its presets beside the file itself, as
/// the run's index takes the link and the file for one jobs file: it looked beside the link
/// ("cannot read preset my.toml", a sweep). Control: a `my.toml` beside the link is not read.
#[cfg(unix)]
#[test]
fn a_jobs_file_through_a_link_reads_its_presets_beside_the_file() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    std::fs::write(dir.path().join("sub/my.toml"), "seed = 5\n").unwrap();
    std::fs::write(dir.path().join("sub/jobs.toml"), "[[job]]\npreset = \"my.toml\"\nsizes = [16]\n").unwrap();
    std::os::unix::fs::symlink("sub/jobs.toml", dir.path().join("link.toml")).unwrap();
    // A link to the link, from another folder.
    std::fs::create_dir(dir.path().join("other")).unwrap();
    std::os::unix::fs::symlink("../link.toml", dir.path().join("other/jobs.toml")).unwrap();
    std::fs::write(dir.path().join("other/my.toml"), "seed = 6\n").unwrap();
    for (jobs, out) in [("link.toml", "out1"), ("other/jobs.toml", "out2")] {
        let run = Command::new(env!("CARGO_BIN_EXE_snakeskin"))
            .args(["batch", jobs, "-o", out])
            .current_dir(dir.path())
            .output()
            .unwrap();
        assert!(run.status.success(), "{jobs}: {}", stderr(&run));
        assert!(dir.path().join(out).join("my/tile-16-seed5-png").is_dir(), "{jobs}: {}", stdout(&run));
    }
}

/// `ao = true` with a pack puts the ambient occlusion map in the pack's occlusion channel,
/// in a folder of its own, with the same bytes as `generate --pack gltf --ao` (a batch had
/// no way to ask for it); without a pack it is refused with the way to name the map.
#[test]
fn a_pack_job_can_ask_for_ambient_occlusion() {
    let dir = tempfile::tempdir().unwrap();
    let jobs = dir.path().join("jobs.toml");
    let job = |extra: &str| format!("[[job]]\npreset = \"crotalus-atrox\"\nsizes = [64]\nseeds = [3]\n{extra}");
    std::fs::write(&jobs, format!("{}\n{}", job("pack = \"gltf\"\nao = true\n"), job("pack = \"gltf\"\n"))).unwrap();
    let out_dir = dir.path().join("out");
    let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", out_dir.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let with = out_dir.join("crotalus-atrox/tile-64-seed3-pack-gltf-ao/crotalus-atrox_orm.png");
    let without = out_dir.join("crotalus-atrox/tile-64-seed3-pack-gltf/crotalus-atrox_orm.png");
    let direct = dir.path().join("direct");
    let args = ["generate", "crotalus-atrox", "--size", "64", "--seed", "3", "--pack", "gltf", "--ao", "-o"];
    assert!(snakeskin(&[&args[..], &[direct.to_str().unwrap()]].concat()).status.success());
    let orm = |path: &Path| image::open(path).unwrap().into_rgb8();
    assert_eq!(orm(&with), orm(&direct.join("crotalus-atrox_orm.png")), "the batch's pack is generate's");
    assert_ne!(orm(&with), orm(&without), "the occlusion channel holds the map, not 1");
    std::fs::write(&jobs, job("ao = true\n")).unwrap();
    let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", out_dir.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("jobs.toml:5: [[job]] 1 (crotalus-atrox): ao: the occlusion channel of a pack"),
        "{}",
        stderr(&out)
    );
}

/// A job rerun over its earlier set (the preset edited: its film gone, so no thickness
/// texture) warns of the earlier set's file that stays because it was edited by hand since,
/// as `generate` does (before, the batch said nothing and the file stayed under no manifest).
#[test]
fn a_batch_warns_of_an_earlier_file_that_stays() {
    let dir = tempfile::tempdir().unwrap();
    let preset =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("presets/xenopeltis-unicolor.toml"))
            .unwrap();
    std::fs::write(dir.path().join("p.toml"), &preset).unwrap();
    let jobs = dir.path().join("jobs.toml");
    std::fs::write(&jobs, "[[job]]\npreset = \"p.toml\"\nsizes = [32]\nseeds = [1]\npack = \"gltf\"\n").unwrap();
    let out_dir = dir.path().join("out");
    let run = || snakeskin(&["batch", jobs.to_str().unwrap(), "-o", out_dir.to_str().unwrap()]);
    assert!(run().status.success());
    let thickness = out_dir.join("p/tile-32-seed1-pack-gltf/p_thickness.png");
    let mut bytes = std::fs::read(&thickness).unwrap();
    bytes.push(0);
    std::fs::write(&thickness, &bytes).unwrap();
    assert!(preset.contains("\nspread_nm = 260\n") && preset.contains("\nfilm_thickness_nm = 420\n"));
    let without_film = preset
        .replace("\nspread_nm = 260\n", "\nspread_nm = 0\n")
        .replace("\nfilm_thickness_nm = 420\n", "\nfilm_thickness_nm = 0\n");
    std::fs::write(dir.path().join("p.toml"), without_film).unwrap();
    let out = run();
    assert!(out.status.success(), "{}", stderr(&out));
    let warning = format!("warning: kept {}, which this set does not write: it changed since", thickness.display());
    assert!(stderr(&out).contains(&warning) && stderr(&out).contains("it changed since"), "{}", stderr(&out));
    assert!(thickness.exists());
}

/// A second jobs file into the same folder replaces the first's index, and says so; the
/// same jobs file again (negative control) says nothing. It was replaced without a word.
#[test]
fn a_batch_says_when_it_replaces_another_jobs_files_index() {
    let dir = tempfile::tempdir().unwrap();
    let first = jobs_file(dir.path(), &["natrix-natrix"], "[1]", 16);
    let second = dir.path().join("second.toml");
    std::fs::write(&second, "[[job]]\npreset = \"natrix-natrix\"\nseeds = [2]\nsizes = [16]\n").unwrap();
    let out = dir.path().join("out");
    let run = |jobs: &Path| snakeskin(&["batch", jobs.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    for (jobs, says) in [(&first, false), (&first, false), (&second, true)] {
        let ran = run(jobs);
        assert!(ran.status.success(), "{}", stderr(&ran));
        let note = format!("listed the jobs of {}; it lists this run's now", first.display());
        assert_eq!(stderr(&ran).contains(&note), says, "{}: {}", jobs.display(), stderr(&ran));
    }
    assert_eq!(read_index(&out)["jobs_file"], second.to_str().unwrap());
    // The same file named from another folder is the same jobs file (the index holds its
    // canonical path; given as typed, `../second.toml` from a folder below was "another").
    let below = dir.path().join("below");
    std::fs::create_dir(&below).unwrap();
    for (folder, jobs, out) in [(dir.path(), "second.toml", "out"), (&below, "../second.toml", "../out")] {
        let ran = Command::new(env!("CARGO_BIN_EXE_snakeskin"))
            .args(["batch", jobs, "-o", out])
            .current_dir(folder)
            .output()
            .unwrap();
        assert!(ran.status.success(), "{}", stderr(&ran));
        assert!(!stderr(&ran).contains("listed the jobs of"), "{jobs}: {}", stderr(&ran));
    }
}

/// A second jobs file whose preset shares the first's name but not its content would write
/// the first's set with other output: refused before anything runs, sharded or not, and by
/// `--list`, naming the set's folder and the first jobs file, every file as it was (it was
/// replaced, and the note said the first's sets stayed: a hostile-input sweep; a sharded
/// run still replaced it: a review). Controls: the same preset's content under that name
/// shares the set (skipped); the first jobs file again, its preset edited, replaces its own
/// set.
#[test]
fn a_second_jobs_file_does_not_replace_the_firsts_set_with_other_output() {
    let dir = tempfile::tempdir().unwrap();
    let first = jobs_file(dir.path(), &["vipera-berus"], "[1]", 16);
    let built_in = stdout(&snakeskin(&["presets", "show", "vipera-berus"]));
    let other_folder = dir.path().join("x");
    std::fs::create_dir(&other_folder).unwrap();
    let second = dir.path().join("second.toml");
    std::fs::write(&second, "[[job]]\npreset = \"x/vipera-berus.toml\"\nseeds = [1]\nsizes = [16]\n").unwrap();
    let out = dir.path().join("out");
    let run = |jobs: &Path| snakeskin(&["batch", jobs.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert!(run(&first).status.success());
    // The same content under the name: the set is shared.
    std::fs::write(other_folder.join("vipera-berus.toml"), &built_in).unwrap();
    let before = tree(&out);
    let shared = run(&second);
    assert!(shared.status.success(), "{}", stderr(&shared));
    assert_eq!(statuses(&read_index(&out)), ["skipped"], "the control: the same output");
    // Other content under the name.
    assert!(built_in.contains("\nrows = 21"));
    std::fs::write(other_folder.join("vipera-berus.toml"), built_in.replace("\nrows = 21", "\nrows = 23")).unwrap();
    run(&first);
    let before_second = tree(&out);
    let folder = out.join("vipera-berus").join("tile-16-seed1-png");
    let said = format!(
        "would replace the set in {}, which a run of {} made from another preset of that name",
        folder.display(),
        first.display()
    );
    for extra in [&[][..], &["--shard", "0/2"], &["--shard", "1/2"], &["--list"]] {
        let mut args = vec!["batch", second.to_str().unwrap(), "-o", out.to_str().unwrap()];
        args.extend(extra);
        let refused = snakeskin(&args);
        // Shard 1/2 holds no job of this one-job file: nothing of the first's is replaced.
        if extra == ["--shard", "1/2"] {
            assert!(refused.status.success(), "{}", stderr(&refused));
            continue;
        }
        assert_eq!(refused.status.code(), Some(2), "{extra:?}: {}", stderr(&refused));
        assert!(stderr(&refused).contains(&said), "{extra:?}: {}", stderr(&refused));
        assert_eq!(tree(&out), before_second, "{extra:?}: a file changed");
    }
    // A third jobs file's run into the folder replaces the index, which carries the first's
    // set: the second is still refused (it replaced the first's set once a third had run: a
    // hostile-input sweep).
    let third = dir.path().join("third.toml");
    std::fs::write(&third, "[[job]]\npreset = \"natrix-natrix\"\nseeds = [1]\nsizes = [16]\n").unwrap();
    let ran = run(&third);
    assert!(ran.status.success(), "{}", stderr(&ran));
    assert!(stderr(&ran).contains("listed the jobs of"), "{}", stderr(&ran));
    let after_third = tree(&out);
    let refused = run(&second);
    assert_eq!(refused.status.code(), Some(2), "after a third jobs file: {}", stderr(&refused));
    assert!(stderr(&refused).contains(&said), "{}", stderr(&refused));
    assert_eq!(tree(&out), after_third, "after a third jobs file: a file changed");
    // The first jobs file's own set, its preset edited: replaced (the built-in cannot be
    // edited, so the first jobs file is pointed at the edited file).
    std::fs::write(&first, "[[job]]\npreset = \"x/vipera-berus.toml\"\nseeds = [1]\nsizes = [16]\n").unwrap();
    let replaced = run(&first);
    assert!(replaced.status.success(), "{}", stderr(&replaced));
    let colour = Path::new("vipera-berus/tile-16-seed1-png/vipera-berus_color.png");
    assert_ne!(tree(&out)[colour], before[colour], "the control: its own set is replaced");
}

/// Whose a set is survives a sharded run's older index beside a newer one, and a jobs file
/// that drops the set's job: another jobs file naming another preset `vipera-berus` is still
/// refused. Both let it through (a review): the older shard index's entry, read first, hid
/// the newer one; the dropped job's set was recorded as no one's. The control: the first
/// jobs file itself replaces its set.
#[test]
fn a_set_stays_its_jobs_files_across_shards_and_dropped_jobs() {
    let dir = tempfile::tempdir().unwrap();
    let built_in = stdout(&snakeskin(&["presets", "show", "vipera-berus"]));
    std::fs::create_dir(dir.path().join("x")).unwrap();
    let own = dir.path().join("x").join("vipera-berus.toml");
    let rows = |n: u32| built_in.replace("\nrows = 21", &format!("\nrows = {n}"));
    let first = dir.path().join("first.toml");
    let job = "[[job]]\npreset = \"x/vipera-berus.toml\"\nseeds = [1]\nsizes = [16]\n";
    let other_job = "[[job]]\npreset = \"natrix-natrix\"\nseeds = [1]\nsizes = [16]\n";
    let second = jobs_file(dir.path(), &["vipera-berus"], "[1]", 16);
    let out = dir.path().join("out");
    let run = |jobs: &Path, extra: &[&str]| {
        let mut args = vec!["batch", jobs.to_str().unwrap(), "-o", out.to_str().unwrap()];
        args.extend(extra);
        snakeskin(&args)
    };
    let refused = |why: &str| {
        let before = tree(&out);
        let ran = run(&second, &[]);
        assert_eq!(ran.status.code(), Some(2), "{why}: {}", stderr(&ran));
        assert!(stderr(&ran).contains("would replace the set in"), "{why}: {}", stderr(&ran));
        assert_eq!(tree(&out), before, "{why}: a file changed");
    };
    // A sharded run, then its preset edited and an unsharded run: two indexes list the set.
    std::fs::write(&own, rows(23)).unwrap();
    std::fs::write(&first, format!("{job}\n{other_job}")).unwrap();
    assert!(run(&first, &["--shard", "0/2"]).status.success());
    std::fs::write(&own, rows(25)).unwrap();
    let replaced = run(&first, &[]);
    assert!(replaced.status.success(), "the control: its own set: {}", stderr(&replaced));
    assert!(out.join("index.shard-0-of-2.json").exists() && out.join("index.json").exists());
    refused("after a sharded run");
    // The job dropped from the first jobs file, which runs again.
    std::fs::remove_file(out.join("index.shard-0-of-2.json")).unwrap();
    std::fs::write(&first, other_job).unwrap();
    assert!(run(&first, &[]).status.success());
    refused("after its job was dropped");
}

/// A run that only skips another jobs file's set (the same preset content) does not make it
/// its own: the maker's run, its preset edited, replaces it, and the skipping file's run,
/// its own copy edited, is refused. Before, the skipping run took the set over: the maker
/// was refused and the other replaced it (a review). The control: the skipping run skips.
#[test]
fn a_run_that_skips_another_files_set_does_not_take_it_over() {
    let dir = tempfile::tempdir().unwrap();
    let built_in = stdout(&snakeskin(&["presets", "show", "vipera-berus"]));
    for folder in ["x", "y"] {
        std::fs::create_dir(dir.path().join(folder)).unwrap();
        std::fs::write(dir.path().join(folder).join("vipera-berus.toml"), &built_in).unwrap();
    }
    let jobs = |name: &str, folder: &str| {
        let path = dir.path().join(name);
        std::fs::write(&path, format!("[[job]]\npreset = \"{folder}/vipera-berus.toml\"\nseeds = [1]\nsizes = [16]\n"))
            .unwrap();
        path
    };
    let (maker, same_file, copy) = (jobs("a.toml", "x"), jobs("b.toml", "x"), jobs("c.toml", "y"));
    let out = dir.path().join("out");
    let run = |jobs: &Path| snakeskin(&["batch", jobs.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    let edit = |folder: &str, rows: &str| {
        let text = built_in.replace("\nrows = 21", &format!("\nrows = {rows}"));
        std::fs::write(dir.path().join(folder).join("vipera-berus.toml"), text).unwrap();
    };
    assert!(run(&maker).status.success());
    for skipping in [&same_file, &copy] {
        let skipped = run(skipping);
        assert!(skipped.status.success(), "{}", stderr(&skipped));
        assert_eq!(statuses(&read_index(&out)), ["skipped"], "the control");
    }
    // The maker's preset edited (the same file the second jobs file names): its run replaces
    // its own set.
    edit("x", "23");
    let replaced = run(&maker);
    assert!(replaced.status.success(), "the maker's run: {}", stderr(&replaced));
    // The copy edited: the third jobs file's run would replace the maker's set, refused.
    edit("y", "25");
    let before = tree(&out);
    let refused = run(&copy);
    assert_eq!(refused.status.code(), Some(2), "{}", stderr(&refused));
    assert!(stderr(&refused).contains(&format!("which a run of {} made", maker.display())), "{}", stderr(&refused));
    assert_eq!(tree(&out), before);
}

/// A newline in a jobs file's preset string is escaped where a message names the job: it
/// printed a line of its own, which could pass for the tool's. Control: the job's place is
/// in the message.
#[test]
fn a_newline_in_a_jobs_preset_stays_on_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let jobs = dir.path().join("jobs.toml");
    std::fs::write(&jobs, "[[job]]\npreset = \"vipera-berus\\nok: all 40 jobs done\"\nsizes = [16]\n").unwrap();
    let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", dir.path().join("o").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("[[job]] 1 (vipera-berus\\u{a}ok: all 40 jobs done)"), "{}", stderr(&out));
    assert!(!stderr(&out).lines().any(|l| l.starts_with("ok:")), "{}", stderr(&out));
    // So is one in a key the file writes, unknown to a job or to its preset (a preset file
    // too), and in a `set` table's key: they printed `FAKE` and a made-up `1/1 done` line on
    // lines of their own (a hostile-input sweep).
    let preset = write_preset(dir.path(), "p.toml", "\"a\\nFAKE\" = 1\n");
    for (jobs_text, said) in [
        ("[[job]]\npreset = \"natrix-natrix\"\n\"a\\nFAKE\" = 1\n", "unknown key `a\\u{a}FAKE`"),
        (&format!("[[job]]\npreset = \"{preset}\"\n") as &str, "unknown key `a\\u{a}FAKE`"),
        ("[[job]]\npreset = \"natrix-natrix\"\nsizes = [16]\nset = { \"x\\nFAKE\" = 5 }\n", "set `x\\u{a}FAKE=5`"),
    ] {
        std::fs::write(&jobs, jobs_text).unwrap();
        let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", dir.path().join("o").to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
        assert!(stderr(&out).contains(said), "{said}: {}", stderr(&out));
        assert!(!stderr(&out).lines().any(|l| l.starts_with("FAKE")), "{}", stderr(&out));
    }
    // And one in the name of the folder a preset lies in, where the preset's own messages
    // name its path: a problem, a warning, a file missing (an independent review).
    let folder = dir.path().join("d\nFAKE");
    std::fs::create_dir(&folder).unwrap();
    std::fs::write(folder.join("bad.toml"), "[optics]\nfilm_ior = 7\n").unwrap();
    std::fs::write(folder.join("warned.toml"), "[optics]\nambient_ior = 1.8\n").unwrap();
    for (name, said) in [
        ("bad.toml", "d\\u{a}FAKE/bad.toml:2: key `optics.film_ior`"),
        ("warned.toml", "d\\u{a}FAKE/warned.toml:2: optics.pigment_ior"),
        ("missing.toml", "d\\u{a}FAKE/missing.toml: No such file"),
    ] {
        std::fs::write(&jobs, format!("[[job]]\npreset = \"d\\nFAKE/{name}\"\nsizes = [16]\n")).unwrap();
        let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", dir.path().join("o").to_str().unwrap()]);
        assert!(stderr(&out).contains(said), "{said}: {}", stderr(&out));
        assert!(!stderr(&out).lines().any(|l| l.starts_with("FAKE")), "{}", stderr(&out));
    }
}

/// A jobs file's preset written with a `/` is a path wherever the jobs file is named from:
/// `natrix-natrix/` beside a jobs file named without a folder (`jobs.toml`) read as the
/// built-in, silently, where `./jobs.toml` refused it (the join to an empty folder dropped the
/// slash; a hostile-input sweep). Control: the name without the slash is the built-in.
#[test]
fn a_jobs_preset_with_a_slash_is_a_path_however_the_jobs_file_is_named() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("jobs.toml"), "[[job]]\npreset = \"natrix-natrix/\"\nsizes = [16]\n").unwrap();
    let run = |jobs: &str| {
        Command::new(env!("CARGO_BIN_EXE_snakeskin"))
            .args(["batch", jobs, "-o", "o", "--list"])
            .current_dir(dir.path())
            .output()
            .unwrap()
    };
    for jobs in ["jobs.toml", "./jobs.toml"] {
        let out = run(jobs);
        assert_eq!(out.status.code(), Some(2), "{jobs}: {}", stderr(&out));
        assert!(stderr(&out).contains("cannot read preset ./natrix-natrix"), "{jobs}: {}", stderr(&out));
    }
    std::fs::write(dir.path().join("jobs.toml"), "[[job]]\npreset = \"natrix-natrix\"\nsizes = [16]\n").unwrap();
    assert!(run("jobs.toml").status.success(), "{}", stderr(&run("jobs.toml")));
}

/// A preset file's own problem is placed at the job's `preset` line, not at its `set` line
/// because the job has a `set` table (`set` named a key it had not written); one the table
/// wrote still is at `set`.
#[test]
fn a_preset_files_problem_is_placed_at_the_jobs_preset_line() {
    let dir = tempfile::tempdir().unwrap();
    let preset = write_preset(dir.path(), "bad.toml", "[optics]\nfilm_ior = 7\n");
    let jobs = dir.path().join("jobs.toml");
    let refused = |set: &str| {
        let text = format!("[[job]]\npreset = \"{preset}\"\nsizes = [16]\nset = {{ {set} }}\n");
        std::fs::write(&jobs, text).unwrap();
        let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", dir.path().join("o").to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
        stderr(&out)
    };
    let err = refused("\"scales.rows\" = 20");
    assert!(err.contains("jobs.toml:2: [[job]] 1") && err.contains("bad.toml:2: key `optics.film_ior`"), "{err}");
    let err = refused("\"optics.pigment_ior\" = 9");
    assert!(err.contains("jobs.toml:4: [[job]] 1") && err.contains("key `optics.pigment_ior`"), "{err}");
    // A key at its default refused for the other key of its check, which the table wrote
    // (spots at their default size, `amount` set): at `set` too, said to be the table's (it
    // went to the `preset` line and the file, once problems were placed by their own keys:
    // an independent review).
    let spots = write_preset(dir.path(), "sp.toml", "[[pattern]]\nkind = \"spots\"\ncolor = \"#101010\"\n");
    let text = format!("[[job]]\npreset = \"{spots}\"\nsizes = [16]\nset = {{ \"pattern.0.amount\" = 64 }}\n");
    std::fs::write(&jobs, text).unwrap();
    let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", dir.path().join("o").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let said = "(with its `set` table): key `pattern.0.size` (not written: its default) is 0.05 with 64 spots";
    assert!(stderr(&out).contains("jobs.toml:4: [[job]] 1") && stderr(&out).contains(said), "{}", stderr(&out));
}

/// A batch run in a folder whose path is not UTF-8 writes its index (the jobs file's path
/// recorded with the bytes outside UTF-8 as `\xNN`) and knows it again: the job is skipped
/// the second time, without a note of another jobs file. It failed with "internal error:
/// index: path contains invalid UTF-8 characters" (a hostile-input sweep). A preset file
/// named through that folder from outside it is refused, saying why (a review).
#[test]
fn a_batch_runs_in_a_folder_whose_path_is_not_utf8() {
    use std::os::unix::ffi::OsStrExt;
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join(std::ffi::OsStr::from_bytes(b"n\xfdu"));
    std::fs::create_dir(&folder).unwrap();
    jobs_file(&folder, &["vipera-berus"], "[1]", 16);
    let run = || {
        Command::new(env!("CARGO_BIN_EXE_snakeskin"))
            .args(["batch", "jobs.toml", "-o", "o"])
            .current_dir(&folder)
            .output()
            .unwrap()
    };
    for expected in ["done", "skipped"] {
        let ran = run();
        assert!(ran.status.success(), "{}", stderr(&ran));
        assert!(!stderr(&ran).contains("listed the jobs of"), "{}", stderr(&ran));
        let index = read_index(&folder.join("o"));
        assert_eq!(statuses(&index), [expected]);
        assert!(index["jobs_file"].as_str().unwrap().ends_with("/n\\xfdu/jobs.toml"), "{}", index["jobs_file"]);
    }
    // A preset file beside the jobs file, named through that folder from outside it: refused
    // with the key's line and what to do (it was read lossily, "cannot read preset n�/…").
    std::fs::write(folder.join("snake.toml"), "[scales]\nrows = 21\n").unwrap();
    std::fs::write(folder.join("jobs.toml"), "[[job]]\npreset = \"snake.toml\"\nsizes = [16]\n").unwrap();
    let outside = Command::new(env!("CARGO_BIN_EXE_snakeskin"))
        .arg("batch")
        .arg(folder.join("jobs.toml"))
        .arg("-o")
        .arg(dir.path().join("o"))
        .output()
        .unwrap();
    assert_eq!(outside.status.code(), Some(2), "{}", stderr(&outside));
    assert!(stderr(&outside).contains("jobs.toml:2: [[job]] 1 (snake.toml): preset: its path"), "{}", stderr(&outside));
    assert!(stderr(&outside).contains("is not UTF-8 text"), "{}", stderr(&outside));
    // The control: run from inside the folder, the same jobs file reads its preset.
    assert!(run().status.success());
}

#[test]
fn every_different_job_gets_its_own_folder_and_a_repeated_job_runs_once() {
    let dir = tempfile::tempdir().unwrap();
    let jobs = dir.path().join("jobs.toml");
    // Three different jobs of one preset (two differ only in their overrides), a fourth
    // that repeats the first, and a fifth that repeats the second in other words (a table
    // for the dotted key, which the README says is the same: it made a folder of its own with
    // the same bytes, a sweep), and a sixth whose empty table overrides nothing (the first's).
    std::fs::write(
        &jobs,
        "[[job]]\npreset = \"natrix-natrix\"\nsizes = [32]\n\n\
         [[job]]\npreset = \"natrix-natrix\"\nsizes = [32]\nset = { \"scales.rows\" = 17 }\n\n\
         [[job]]\npreset = \"natrix-natrix\"\nsizes = [32]\nset = { \"scales.rows\" = 23 }\n\n\
         [[job]]\npreset = \"natrix-natrix\"\nsizes = [32]\n\n\
         [[job]]\npreset = \"natrix-natrix\"\nsizes = [32]\nset = { scales = { rows = 17 } }\n\n\
         [[job]]\npreset = \"natrix-natrix\"\nsizes = [32]\nset = { scales = {} }\n",
    )
    .unwrap();
    let out_dir = dir.path().join("out");
    // `--list` names each job's state and writes nothing; after the run the three are done.
    let list = |jobs: &Path, out_dir: &Path| {
        let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", out_dir.to_str().unwrap(), "--list"]);
        assert!(out.status.success(), "{}", stderr(&out));
        stdout(&out).lines().map(|l| l.split_whitespace().nth(1).unwrap_or("").to_string()).collect::<Vec<_>>()
    };
    assert_eq!(list(&jobs, &out_dir), ["to", "to", "to", "duplicate", "duplicate", "duplicate"]);
    assert!(!out_dir.exists(), "--list wrote its output folder");
    let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", out_dir.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stdout(&out).contains("3 run, 0 already done, 3 duplicates of another job"), "{}", stdout(&out));
    assert_eq!(list(&jobs, &out_dir), ["done", "done", "done", "duplicate", "duplicate", "duplicate"]);
    let sets = manifests(&out_dir);
    assert_eq!(sets.len(), 3, "{sets:?}");
    // Each set is complete and is its own job's (a set overwritten by another job's maps
    // would fail its hashes or carry the other job's key).
    let index = read_index(&out_dir);
    let index = index["jobs"].as_array().unwrap();
    assert_eq!(index[3]["status"], "duplicate");
    assert_eq!(index[3]["duplicate_of"], 0);
    assert_eq!(index[4]["duplicate_of"], 1);
    assert_eq!(index[5]["duplicate_of"], 0);
    // A dotted key's folder is named as it was before tables were read as dotted keys: the
    // first 8 hex digits of the SHA-256 of the overrides' JSON (sets made then stay done).
    use sha2::Digest;
    let digest = sha2::Sha256::digest(br#"[["scales.rows","17"]]"#);
    let hash: String = digest.iter().take(4).map(|b| format!("{b:02x}")).collect();
    assert_eq!(index[1]["folder"], format!("natrix-natrix/tile-32-seed31-png-set{hash}"), "{index:?}");
    for job in &index[..3] {
        let manifest: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out_dir.join(job["manifest"].as_str().unwrap())).unwrap()).unwrap();
        assert_eq!(manifest["job"], job["key"]);
    }
    // The same run again has nothing to do: every set is settled (its files match the
    // hashes its manifest records).
    let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", out_dir.to_str().unwrap()]);
    assert!(stdout(&out).contains("0 run, 3 already done, 3 duplicates of another job"), "{}", stdout(&out));
    assert_eq!(manifests(&out_dir), sets, "a settled set was written again");

    // Two different preset files with one name would share a folder: refused, in every
    // shard, before anything is written.
    let preset =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("presets/natrix-natrix.toml")).unwrap();
    for (sub, rows) in [("a", 19), ("b", 21)] {
        std::fs::create_dir(dir.path().join(sub)).unwrap();
        let text = preset.replacen("rows = 19", &format!("rows = {rows}"), 1);
        std::fs::write(dir.path().join(sub).join("snake.toml"), text).unwrap();
    }
    std::fs::write(
        &jobs,
        "[[job]]\npreset = \"a/snake.toml\"\nsizes = [32]\n\n[[job]]\npreset = \"b/snake.toml\"\nsizes = [32]\n",
    )
    .unwrap();
    let empty = dir.path().join("empty");
    for shard in ["0/2", "1/2"] {
        let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", empty.to_str().unwrap(), "--shard", shard]);
        assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
        // Both jobs' `preset` lines and presets as written: the second where the message
        // starts, the first in it (both were named `(snake)`).
        let err = stderr(&out);
        assert!(
            err.contains("jobs.toml:6: [[job]] 2 (") && err.contains("/b/snake.toml): would write snake/tile-32"),
            "{err}"
        );
        assert!(
            err.contains("which [[job]] 1 (line 2, ") && err.contains("/a/snake.toml) writes with different"),
            "{err}"
        );
    }
    assert!(!empty.exists());

    // A preset named like the index would put its sets where the index goes: refused before
    // any job runs (before, every job ran and the index then failed, "a folder is in the way").
    for name in ["index.json", "index.shard-0-of-2.json"] {
        std::fs::write(dir.path().join(format!("{name}.toml")), &preset).unwrap();
        std::fs::write(&jobs, format!("[[job]]\nsizes = [32]\npreset = \"{name}.toml\"\n")).unwrap();
        let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", empty.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
        let expected = format!("/{name}.toml): its sets would go in the folder {name}, a name the batch keeps");
        assert!(stderr(&out).contains(&expected), "{}", stderr(&out));
        assert!(!empty.exists());
    }
}

#[test]
fn jobs_run_at_once_write_the_files_and_the_index_of_jobs_run_one_at_a_time() {
    let dir = tempfile::tempdir().unwrap();
    let species = ["natrix-natrix", "python-regius", "vipera-berus", "micrurus-diastema", "boa-constrictor"];
    let jobs = jobs_file(dir.path(), &species, "[1, 2]", 48);
    // The first job is the slowest, so with three at once it finishes after later ones: an
    // index in finishing order cannot pass by luck.
    let text = std::fs::read_to_string(&jobs).unwrap().replacen("sizes = [48]", "sizes = [384]", 1);
    std::fs::write(&jobs, text).unwrap();
    let (one, three) = (dir.path().join("one"), dir.path().join("three"));
    for (out_dir, n) in [(&one, "1"), (&three, "3")] {
        let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", out_dir.to_str().unwrap(), "--concurrent", n]);
        assert!(out.status.success(), "{}", stderr(&out));
        assert_eq!(summary_counts(&out), (10, 0), "{}", stdout(&out));
        assert!(stdout(&out).contains(&format!("up to {n} at once")), "{}", stdout(&out));
    }
    let (a, b) = (tree(&one), tree(&three));
    assert_eq!(a.len(), b.len());
    for (path, bytes) in &a {
        assert!(b.get(path) == Some(bytes), "{} differs between 1 and 3 jobs at once", path.display());
    }
    // The index lists the jobs in their order, not in the order they finished.
    let index = |d: &Path| std::fs::read(d.join("index.json")).unwrap();
    assert!(index(&one) == index(&three), "the index depends on how many jobs ran at once");

    let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", one.to_str().unwrap(), "--concurrent", "17"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("1..=16"), "{}", stderr(&out));
}

/// A set is done only when its manifest lists the files the job writes: a manifest that
/// lost a map's entry with the map was taken as done and never run again. Negative control:
/// the whole set is still taken as done.
#[test]
fn a_set_missing_a_map_is_not_done() {
    let dir = tempfile::tempdir().unwrap();
    let jobs = jobs_file(dir.path(), &["natrix-natrix"], "[31]", 32);
    let out_dir = dir.path().join("out");
    let run = || snakeskin(&["batch", jobs.to_str().unwrap(), "-o", out_dir.to_str().unwrap()]);
    assert_eq!(summary_counts(&run()), (1, 0));
    assert_eq!(summary_counts(&run()), (0, 1), "the whole set is done");
    let set = out_dir.join("natrix-natrix/tile-32-seed31-png");
    let manifest = set.join("natrix-natrix.material.json");
    let mut json: serde_json::Value = serde_json::from_slice(&std::fs::read(&manifest).unwrap()).unwrap();
    json["maps"].as_array_mut().unwrap().retain(|m| m["map"] != "height");
    std::fs::write(&manifest, serde_json::to_vec(&json).unwrap()).unwrap();
    std::fs::remove_file(set.join("natrix-natrix_height.png")).unwrap();
    snakeskin::export::verify_set(&manifest).expect("what the manifest lists is whole");
    let listed = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", out_dir.to_str().unwrap(), "--list"]);
    assert!(stdout(&listed).contains("to do"), "{}", stdout(&listed));
    assert_eq!(summary_counts(&run()), (1, 0));
    assert!(set.join("natrix-natrix_height.png").is_file());
}

/// A set's file replaced by a link to /dev/zero, a FIFO or a huge sparse file: `batch`
/// read each whole to hash it (memory until the kernel killed it, or a hang on the FIFO);
/// now it reads regular files within a set's size, never through a link, and such a set is
/// not done ("to do"), at once.
#[cfg(unix)]
#[test]
fn a_planted_file_in_a_set_is_not_read_through_and_the_set_is_not_done() {
    let dir = tempfile::tempdir().unwrap();
    let jobs = jobs_file(dir.path(), &["natrix-natrix"], "[31]", 16);
    let out_dir = dir.path().join("out");
    let run = |extra: &[&str]| {
        let mut args = vec!["batch", jobs.to_str().unwrap(), "-o", out_dir.to_str().unwrap()];
        args.extend_from_slice(extra);
        snakeskin(&args)
    };
    assert_eq!(summary_counts(&run(&[])), (1, 0));
    let set = out_dir.join("natrix-natrix/tile-16-seed31-png");
    let colour = set.join("natrix-natrix_color.png");
    let manifest = set.join("natrix-natrix.material.json");
    let kept_manifest = std::fs::read(&manifest).unwrap();
    let fifo = |path: &Path| {
        let c = std::ffi::CString::new(path.as_os_str().as_encoded_bytes()).unwrap();
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o644) }, 0);
    };
    let plants: [(&str, &dyn Fn()); 4] = [
        ("a map linked to /dev/zero", &|| std::os::unix::fs::symlink("/dev/zero", &colour).unwrap()),
        ("a map that is a FIFO", &|| fifo(&colour)),
        ("a sparse 64 GiB map", &|| std::fs::File::create(&colour).unwrap().set_len(64 << 30).unwrap()),
        ("a manifest that is a FIFO", &|| {
            std::fs::write(&colour, b"x").unwrap();
            std::fs::remove_file(&manifest).unwrap();
            fifo(&manifest);
        }),
    ];
    for (what, plant) in plants {
        let _ = std::fs::remove_file(&colour);
        plant();
        let start = Instant::now();
        let listed = run(&["--list"]);
        // A regular file that is not the set's: the job is to do. A link or a FIFO where the
        // set's file goes: refused as `generate` refuses it (it would be written over).
        if listed.status.success() {
            assert!(stdout(&listed).contains("to do"), "{what}: {}", stdout(&listed));
        } else {
            assert_eq!(listed.status.code(), Some(2), "{what}: {}", stderr(&listed));
            assert!(stderr(&listed).contains("not a regular file"), "{what}: {}", stderr(&listed));
        }
        assert!(start.elapsed() < Duration::from_secs(20), "{what}: --list took {:?}", start.elapsed());
        if std::fs::symlink_metadata(&manifest).is_ok_and(|m| !m.is_file()) {
            std::fs::remove_file(&manifest).unwrap();
            std::fs::write(&manifest, &kept_manifest).unwrap();
        }
    }
    // `generate` over a set whose manifest is a sparse 64 GiB file: the commit's clean-up
    // read the old manifest whole (killed for memory in a 1.5 GB cgroup); now the new set
    // is written and the old "manifest" replaced, at once.
    std::fs::remove_file(&colour).unwrap();
    std::fs::File::create(&manifest).unwrap().set_len(64 << 30).unwrap();
    let start = Instant::now();
    let out = snakeskin(&["generate", "natrix-natrix", "-o", set.to_str().unwrap(), "--size", "16"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(start.elapsed() < Duration::from_secs(20), "generate took {:?}", start.elapsed());
    assert!(std::fs::metadata(&manifest).unwrap().len() < 1 << 20);
}

/// The jobs file named as the batch's own index (`batch out/index.json -o out`): the index
/// replaced the jobs, and the documented way to resume, running it again, failed.
#[test]
fn a_batch_does_not_write_its_index_over_its_jobs_file() {
    let dir = tempfile::tempdir().unwrap();
    let jobs = dir.path().join("index.json");
    std::fs::write(&jobs, "[[job]]\npreset = \"natrix-natrix\"\nsizes = [16]\n").unwrap();
    let run = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", dir.path().to_str().unwrap()]);
    assert_eq!(run.status.code(), Some(2), "{}", stderr(&run));
    assert!(stderr(&run).contains("would be written over this command's input"), "{}", stderr(&run));
    assert!(std::fs::read_to_string(&jobs).unwrap().starts_with("[[job]]"), "the jobs file stays");
    assert!(!dir.path().join("natrix-natrix").exists(), "refused before any job");
}

/// A job's preset saved where the batch writes: as `DIR/index.json` it was replaced by the
/// index (exit 0), and a job's set files could be written over another job's preset.
/// Refused before any job runs; the preset stays.
#[test]
fn a_batch_writes_over_no_job_preset() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    let text = stdout(&snakeskin(&["presets", "show", "natrix-natrix"]));
    let under_index = out.join("index.json");
    std::fs::write(&under_index, &text).unwrap();
    let jobs = dir.path().join("jobs.toml");
    std::fs::write(&jobs, "[[job]]\npreset = \"out/index.json\"\nsizes = [16]\n").unwrap();
    let run = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_eq!(run.status.code(), Some(2), "{}", stderr(&run));
    assert!(stderr(&run).contains("would be written over this command's input"), "{}", stderr(&run));
    assert_eq!(std::fs::read_to_string(&under_index).unwrap(), text, "the preset stays");
    assert_eq!(std::fs::read_dir(&out).unwrap().count(), 1, "refused before any job");

    // Job 2's preset saved where job 1's colour map goes (the first case's preset moved
    // away: a file of another kind where the index goes is refused of itself).
    std::fs::remove_file(&under_index).unwrap();
    let set = out.join("natrix-natrix/tile-16-seed1-png");
    std::fs::create_dir_all(&set).unwrap();
    let in_set = set.join("natrix-natrix_color.png");
    std::fs::write(&in_set, &text).unwrap();
    let jobs_text = "[[job]]\npreset = \"natrix-natrix\"\nseeds = [1]\nsizes = [16]\n\n\
                     [[job]]\npreset = \"out/natrix-natrix/tile-16-seed1-png/natrix-natrix_color.png\"\nsizes = [16]\n";
    std::fs::write(&jobs, jobs_text).unwrap();
    let run = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_eq!(run.status.code(), Some(2), "{}", stderr(&run));
    assert!(stderr(&run).contains("would be written over this command's input"), "{}", stderr(&run));
    assert_eq!(std::fs::read_to_string(&in_set).unwrap(), text, "the preset stays");
    // Negative control: the preset moved out of the way, the same jobs run.
    let moved = dir.path().join("moved.toml");
    std::fs::rename(&in_set, &moved).unwrap();
    std::fs::write(
        &jobs,
        jobs_text.replace("out/natrix-natrix/tile-16-seed1-png/natrix-natrix_color.png", "moved.toml"),
    )
    .unwrap();
    let run = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert!(run.status.success(), "{}", stderr(&run));
}

/// A preset edited while its batch runs: the job that reads the edited preset is not
/// written under the key of the planned one (a later run, the edit undone, took that set as
/// done), and the batch stops with exit 1 and says why; the sets before it stand. The
/// first job pauses at its commit (`SNAKESKIN_TEST_PAUSE_AT`, debug builds) while the
/// preset is edited.
#[test]
fn a_preset_edited_while_its_batch_runs_is_not_written_under_the_old_key() {
    if !test_hooks_exist() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let preset = dir.path().join("snake.toml");
    let original = "species = \"snake\"\n\n[scales]\nrows = 19\n";
    std::fs::write(&preset, original).unwrap();
    let jobs = dir.path().join("jobs.toml");
    std::fs::write(&jobs, "[[job]]\npreset = \"snake.toml\"\nseeds = [1, 2]\nsizes = [32]\n").unwrap();
    let out_dir = dir.path().join("out");
    let args = ["batch", jobs.to_str().unwrap(), "-o", out_dir.to_str().unwrap(), "--concurrent", "1"];
    // The first job's staged maps appear as it reaches its commit, where it pauses.
    let child = spawn_paused_at_commit(&args, &out_dir.join("snake/tile-32-seed1-png"));
    std::fs::write(&preset, original.replace("rows = 19", "rows = 41")).unwrap();
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(
        err.contains("jobs.toml:2: [[job]] 1 (") && err.contains("snake.toml, seed 2, size 32): the preset changed"),
        "{err}"
    );
    snakeskin::export::verify_set(&out_dir.join("snake/tile-32-seed1-png/snake.material.json")).unwrap();
    assert!(!out_dir.join("snake/tile-32-seed2-png/snake.material.json").exists());
    // The edit undone, the second job runs and the first is done.
    std::fs::write(&preset, original).unwrap();
    let out = snakeskin(&args);
    assert_eq!(summary_counts(&out), (1, 1), "{}", stderr(&out));
}

/// A job that fails while it runs (here a rename of its commit, the fault hook of debug
/// builds) is named with its jobs file, line, seed and size; it named only a file. Exit 1:
/// not the input's fault.
#[test]
fn a_job_that_fails_while_it_runs_is_named() {
    if !test_hooks_exist() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let jobs = jobs_file(dir.path(), &["natrix-natrix"], "[5]", 32);
    let out_dir = dir.path().join("out");
    let out = common::snakeskin_env(
        &["batch", jobs.to_str().unwrap(), "-o", out_dir.to_str().unwrap()],
        &[("SNAKESKIN_TEST_FAIL_AT_RENAME", "0")],
    );
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(
        err.contains("jobs.toml:2: [[job]] 1 (natrix-natrix, seed 5, size 32): ") && err.contains("injected"),
        "{err}"
    );
}

/// A batch a job stopped still says what happened, on stdout and in its index: each job done,
/// failed or not run. It wrote no index and printed no summary, and an index left by an
/// earlier run of another jobs file stood, describing sets this run was not about (the QA
/// review). The index of a run as it starts lists this run's jobs.
#[test]
fn a_stopped_batch_writes_its_index_with_what_failed_and_what_never_ran() {
    if !test_hooks_exist() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    let earlier = dir.path().join("earlier.toml");
    std::fs::write(&earlier, "[[job]]\npreset = \"natrix-natrix\"\nseeds = [1]\nsizes = [16]\n").unwrap();
    assert!(snakeskin(&["batch", earlier.to_str().unwrap(), "-o", out_dir.to_str().unwrap()]).status.success());
    // Seed 1 is the earlier run's set (skipped), the last job a duplicate of it: both stay
    // as planned when the run stops (they were `not run`).
    let jobs = jobs_file(dir.path(), &["natrix-natrix"], "[5, 1, 7, 1]", 16);
    let out = common::snakeskin_env(
        &["batch", jobs.to_str().unwrap(), "-o", out_dir.to_str().unwrap(), "--concurrent", "1"],
        &[("SNAKESKIN_TEST_FAIL_AT_RENAME", "0")],
    );
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(stderr(&out).contains("seed 5, size 16): "), "{}", stderr(&out));
    let summary = stdout(&out);
    assert!(
        summary.contains(
            "4 jobs of 4 in shard 0/1, up to 1 at once: 0 run, 1 already done, 1 duplicate of another job, 1 failed, \
             1 not run; index: "
        ),
        "{summary}"
    );
    let index = read_index(&out_dir);
    assert_eq!(index["jobs_file"].as_str(), jobs.to_str(), "{index}");
    assert_eq!(statuses(&index), ["failed", "skipped", "not run", "duplicate"], "{index}");
    // Negative control: run again without the fault, every job is done and said so.
    let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", out_dir.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let index = read_index(&out_dir);
    assert_eq!(statuses(&index), ["done", "skipped", "done", "duplicate"], "{index}");
}

/// `snakeskin verify`: a whole set, a batch's folder of sets and a manifest named alone
/// pass (exit 0, one `ok` line each); a map altered after the run (one byte appended) and a
/// set without its manifest (a run killed while renaming) fail with exit 1 and the file
/// named; a path that is no manifest, a missing one and a folder without sets are the
/// user's mistake (exit 2). Negative control: the altered set passes again once the byte
/// is taken off.
#[test]
fn verify_passes_whole_sets_and_fails_altered_or_incomplete_ones() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let jobs = jobs_file(dir.path(), &["natrix-natrix", "xenopeltis-unicolor"], "[1]", 16);
    let run = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert!(run.status.success(), "{}", stderr(&run));
    let manifests: Vec<PathBuf> = manifests(&out).into_keys().map(|p| out.join(p)).collect();
    assert_eq!(manifests.len(), 2, "{manifests:?}");
    let verify = |paths: &[&Path]| {
        let args: Vec<&str> = ["verify"].into_iter().chain(paths.iter().map(|p| p.to_str().unwrap())).collect();
        snakeskin(&args)
    };
    let whole = verify(&[&out]);
    assert_eq!(whole.status.code(), Some(0), "{}{}", stdout(&whole), stderr(&whole));
    assert_eq!(stdout(&whole).lines().filter(|l| l.starts_with("ok ")).count(), 2, "{}", stdout(&whole));
    let alone = verify(&[&manifests[0]]);
    assert_eq!(alone.status.code(), Some(0), "{}", stderr(&alone));

    // A map entry whose file is empty is no plain file name (it was "a folder, not a
    // regular file": a hostile-input sweep); the control, `../x`, said so already. Names no
    // run writes, as preset file names and `.gltf`s are refused alike
    // (`export::unfit_for_file_names`), with a file of that name and the recorded bytes
    // beside the manifest: such a map verified `ok`.
    let text = std::fs::read(&manifests[0]).unwrap();
    let not_plain = "is not a plain file name";
    let cases = [
        ("", not_plain),
        ("../x", not_plain),
        ("a\\b.png", "has a backslash"),
        ("a\u{1b}b.png", "has control characters"),
    ];
    for (file, what) in cases {
        let mut json: serde_json::Value = serde_json::from_slice(&text).unwrap();
        let folder = manifests[0].parent().unwrap();
        if what != not_plain {
            std::fs::copy(folder.join(json["maps"][0]["file"].as_str().unwrap()), folder.join(file)).unwrap();
        }
        json["maps"][0]["file"] = serde_json::json!(file);
        std::fs::write(&manifests[0], serde_json::to_vec(&json).unwrap()).unwrap();
        let listed = verify(&[&manifests[0]]);
        assert_eq!(listed.status.code(), Some(1), "{file:?}: {}", stdout(&listed));
        let said = format!("map file {file:?} {what}");
        assert!(stdout(&listed).contains(&said), "{file:?}: {}", stdout(&listed));
        if what != not_plain {
            std::fs::remove_file(folder.join(file)).unwrap();
        }
    }
    // A manifest whose size is missing or forged names its key (every map was said to be
    // "more than such a file can be": a hostile-input review); the control, the size as
    // written, verifies.
    for (key, value, said) in [
        ("width", serde_json::json!(1_000_000_000_000u64), "the manifest's width 1000000000000 is outside what a set"),
        (
            "height",
            serde_json::json!(1_000_000_000_000u64),
            "the manifest's height 1000000000000 is outside what a set",
        ),
        ("width", serde_json::json!(0), "the manifest's width 0 is outside what a set can be (16 to"),
        ("height", serde_json::json!(1), "the manifest's height 1 is outside what a set can be (16 to"),
        ("width", serde_json::Value::Null, "the manifest's width and height are not both integers"),
        ("width", serde_json::json!(16.0), "the manifest's width and height are not both integers"),
        // An integer, but below any set (it was "not both integers", a review).
        ("width", serde_json::json!(-1), "the manifest's width -1 is outside what a set can be (16 to"),
    ] {
        let mut json: serde_json::Value = serde_json::from_slice(&text).unwrap();
        json[key] = value;
        std::fs::write(&manifests[0], serde_json::to_vec(&json).unwrap()).unwrap();
        let listed = verify(&[&manifests[0]]);
        assert_eq!(listed.status.code(), Some(1), "{said}: {}", stderr(&listed));
        assert!(
            stdout(&listed).contains(said) && !stdout(&listed).contains("more than such a file"),
            "{}",
            stdout(&listed)
        );
    }
    // A hash no run writes is the manifest's fault, not the map's (an empty or upper-case
    // one was "the set is mixed or altered", a review); the control, the hash as written,
    // verifies below.
    for forged in [String::new(), json_hash(&text, 0).to_uppercase()] {
        let mut json: serde_json::Value = serde_json::from_slice(&text).unwrap();
        json["maps"][0]["sha256"] = serde_json::json!(forged);
        std::fs::write(&manifests[0], serde_json::to_vec(&json).unwrap()).unwrap();
        let listed = stdout(&verify(&[&manifests[0]]));
        assert!(listed.contains(&format!("sha256 {forged:?} is not a SHA-256")), "{listed}");
        assert!(!listed.contains("mixed or altered"), "{listed}");
    }
    // More entries than a set has files: refused before any is checked (80,000 of them took
    // five minutes, the duplicate check's square; a hostile-input sweep).
    let mut json: serde_json::Value = serde_json::from_slice(&text).unwrap();
    let entries: Vec<serde_json::Value> =
        (0..5000).map(|i| serde_json::json!({"map": format!("m{i}"), "file": format!("f{i}"), "sha256": ""})).collect();
    json["maps"] = serde_json::Value::Array(entries);
    std::fs::write(&manifests[0], serde_json::to_vec(&json).unwrap()).unwrap();
    let listed = stdout(&verify(&[&manifests[0]]));
    assert!(listed.contains("the manifest lists 5000 maps; a set has at most"), "{listed}");
    std::fs::write(&manifests[0], &text).unwrap();
    assert_eq!(verify(&[&manifests[0]]).status.code(), Some(0), "the control");

    // One byte appended to one map of the first set.
    let set_folder = manifests[0].parent().unwrap();
    let map = std::fs::read_dir(set_folder)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .find(|p| p.extension().is_some_and(|x| x == "png"))
        .unwrap();
    let bytes = std::fs::read(&map).unwrap();
    std::fs::write(&map, [&bytes[..], &[0]].concat()).unwrap();
    let altered = verify(&[&out]);
    assert_eq!(altered.status.code(), Some(1), "{}", stderr(&altered));
    let lines = stdout(&altered);
    let map_name = map.file_name().unwrap().to_string_lossy().into_owned();
    assert!(
        lines.lines().any(|l| l.starts_with("FAILED ") && l.contains(&map_name) && l.contains("mixed or altered")),
        "{lines}"
    );
    assert_eq!(lines.lines().filter(|l| l.starts_with("ok ")).count(), 1, "{lines}");
    assert!(stderr(&altered).contains("1 of 2 checks failed"), "{}", stderr(&altered));
    // A second map of that set missing as well: one line names both (it named the first
    // problem only, an onboarding review).
    let other = std::fs::read_dir(set_folder)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .find(|p| p.extension().is_some_and(|x| x == "png") && *p != map)
        .unwrap();
    let other_bytes = std::fs::read(&other).unwrap();
    std::fs::remove_file(&other).unwrap();
    let both = stdout(&verify(&[&manifests[0]]));
    let other_name = other.file_name().unwrap().to_string_lossy().into_owned();
    assert!(
        both.lines().any(|l| l.starts_with("FAILED ") && l.contains(&map_name) && l.contains(&other_name)),
        "{both}"
    );
    // An entry that names no plain file besides them: all three on the line (it stopped at
    // such an entry, an independent review).
    let mut json: serde_json::Value = serde_json::from_slice(&text).unwrap();
    let third = json["maps"]
        .as_array()
        .unwrap()
        .iter()
        .position(|m| m["file"] != map_name.as_str() && m["file"] != other_name.as_str())
        .unwrap();
    json["maps"][third]["file"] = serde_json::json!("../evil.png");
    std::fs::write(&manifests[0], serde_json::to_vec(&json).unwrap()).unwrap();
    let three = stdout(&verify(&[&manifests[0]]));
    assert!(
        three.lines().any(|l| l.contains(&map_name) && l.contains(&other_name) && l.contains("\"../evil.png\"")),
        "{three}"
    );
    // An entry without its hash and one listed twice, beside the missing map: all named.
    let mut json: serde_json::Value = serde_json::from_slice(&text).unwrap();
    let twice = json["maps"][third].clone();
    json["maps"][third].as_object_mut().unwrap().remove("sha256");
    json["maps"].as_array_mut().unwrap().push(twice.clone());
    json["maps"].as_array_mut().unwrap().push(twice);
    std::fs::write(&manifests[0], serde_json::to_vec(&json).unwrap()).unwrap();
    let more = stdout(&verify(&[&manifests[0]]));
    assert!(
        more.lines().any(|l| l.contains(&other_name)
            && l.contains(&format!("map entry {}: sha256 is missing or not text", third + 1))
            && l.contains("is listed twice")),
        "{more}"
    );
    std::fs::write(&manifests[0], &text).unwrap();
    std::fs::write(&other, &other_bytes).unwrap();
    std::fs::write(&map, &bytes).unwrap();
    assert_eq!(verify(&[&out]).status.code(), Some(0));

    // A set without its manifest (its maps there): incomplete, named by the manifest's
    // path, by its folder and by the batch's folder (which passed it over before).
    let moved = dir.path().join("aside.json");
    std::fs::rename(&manifests[0], &moved).unwrap();
    for path in [manifests[0].as_path(), set_folder, out.as_path()] {
        let incomplete = verify(&[path]);
        assert_eq!(incomplete.status.code(), Some(1), "{path:?}: {}", stderr(&incomplete));
        let lines = stdout(&incomplete);
        assert!(lines.lines().any(|l| l.starts_with("FAILED ") && l.contains("incomplete")), "{path:?}: {lines}");
    }
    std::fs::rename(&moved, &manifests[0]).unwrap();
    // A set named twice (its manifest, its folder, the batch's folder) is checked once.
    let twice = verify(&[&manifests[0], set_folder, &out]);
    assert_eq!(twice.status.code(), Some(0), "{}", stderr(&twice));
    assert_eq!(stdout(&twice).lines().count(), 2, "{}", stdout(&twice));
    // A linked set folder is followed.
    let linked = dir.path().join("linked");
    std::fs::create_dir(&linked).unwrap();
    std::os::unix::fs::symlink(set_folder, linked.join("set")).unwrap();
    let through_link = verify(&[&linked]);
    assert_eq!(through_link.status.code(), Some(0), "{}", stderr(&through_link));
    assert!(stdout(&through_link).starts_with("ok "), "{}", stdout(&through_link));

    // The user's mistakes: a map file, a missing path, a folder without sets, a manifest's
    // name mistyped (no file of that set beside it: no incomplete set).
    let typo = set_folder.join("natrix-natrx.material.json");
    let empty = dir.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    let glb = dir.path().join("x.glb");
    std::fs::write(&glb, b"glTF").unwrap();
    for (path, says) in [
        (map.as_path(), "is not a set's manifest"),
        (glb.as_path(), "a glTF export carries no manifest"),
        (dir.path().join("missing").as_path(), "missing"),
        (empty.as_path(), "holds no set"),
        (typo.as_path(), "no such manifest, and no file of set \"natrix-natrx\" beside it"),
    ] {
        let refused = verify(&[path]);
        assert_eq!(refused.status.code(), Some(2), "{path:?}: {}", stderr(&refused));
        assert!(stderr(&refused).contains(says), "{path:?}: {}", stderr(&refused));
        // Named between two sets, it does not keep them from being checked (`verify a typo
        // c` checked nothing, a sweep's note): both are reported, the run is still the
        // user's mistake, and says what the others' checks found.
        let among = verify(&[&manifests[0], path, &manifests[1]]);
        assert_eq!(among.status.code(), Some(2), "{path:?}: {}", stderr(&among));
        assert_eq!(stdout(&among).lines().filter(|l| l.starts_with("ok ")).count(), 2, "{}", stdout(&among));
        assert!(
            stderr(&among).contains(says) && stderr(&among).contains("(the other paths' 2 checks: none failed)"),
            "{path:?}: {}",
            stderr(&among)
        );
    }
}

/// The SHA-256 the manifest `text` records for its map entry `index`.
fn json_hash(text: &[u8], index: usize) -> String {
    let json: serde_json::Value = serde_json::from_slice(text).unwrap();
    json["maps"][index]["sha256"].as_str().unwrap().to_string()
}

/// A job can ask for DirectX normals (`normal_convention`, as `generate --normal-convention`):
/// its set goes to a folder of its own (`-directx`), its manifest says so, and its normal
/// map's green channel is the OpenGL one's mirror; left out, OpenGL (the control); without
/// a normal map in the job's maps, no folder of its own (the same bytes). With a
/// pack (which writes its engine's own) and an unknown value, refused with the key's line.
/// A batch could not make DirectX normals but through `pack = "unreal"` (a walkthrough).
#[test]
fn a_job_can_ask_for_directx_normals() {
    let dir = tempfile::tempdir().unwrap();
    let jobs = dir.path().join("jobs.toml");
    let job = |extra: &str| format!("[[job]]\npreset = \"vipera-berus\"\nseeds = [1]\nsizes = [16]\n{extra}\n");
    let colour_only = job("normal_convention = \"directx\"\nmaps = \"color\"");
    std::fs::write(&jobs, job("normal_convention = \"directx\"") + &job("") + &colour_only).unwrap();
    let out = dir.path().join("out");
    let ran = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert!(ran.status.success(), "{}", stderr(&ran));
    let set = |folder: &str| {
        let folder = out.join("vipera-berus").join(folder);
        let manifest: serde_json::Value =
            serde_json::from_slice(&std::fs::read(folder.join("vipera-berus.material.json")).unwrap()).unwrap();
        let normal = image::open(folder.join("vipera-berus_normal.png")).unwrap().into_rgb8();
        (manifest["normal_convention"].as_str().unwrap().to_string(), normal)
    };
    // Without a normal map the convention changes no file, and makes no set of its own.
    assert!(out.join("vipera-berus/tile-16-seed1-png-color/vipera-berus_color.png").exists());
    assert!(!out.join("vipera-berus/tile-16-seed1-png-directx-color").exists());
    let (directx, dx) = set("tile-16-seed1-png-directx");
    let (opengl, gl) = set("tile-16-seed1-png");
    assert_eq!((directx.as_str(), opengl.as_str()), ("directx", "opengl"));
    for (a, b) in dx.pixels().zip(gl.pixels()) {
        assert_eq!((a[0], a[2]), (b[0], b[2]));
        assert!((a[1] as i32 + b[1] as i32 - 255).abs() <= 1, "green {} against {}", a[1], b[1]);
    }
    for (extra, said) in [
        (
            "pack = \"unreal\"\nnormal_convention = \"directx\"",
            "normal_convention: pack \"unreal\" writes its normal map",
        ),
        ("normal_convention = \"dx\"", "normal_convention \"dx\": accepted: opengl, directx"),
    ] {
        std::fs::write(&jobs, job(extra)).unwrap();
        let refused = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", dir.path().join("o").to_str().unwrap()]);
        assert_eq!(refused.status.code(), Some(2), "{}", stderr(&refused));
        assert!(stderr(&refused).contains(said) && stderr(&refused).contains("jobs.toml:"), "{}", stderr(&refused));
    }
}

/// An index file in the output folder that cannot be read as one (a FIFO, a link to
/// /dev/zero, a sparse 64 GiB file, an index cut short), this run's or another shard's, is
/// refused with its name, before any job runs and without reading it whole: the read was
/// unbounded (a FIFO hung `batch` and `--list`, /dev/zero took memory until the read
/// failed) and an unreadable index was skipped unseen, and with it the record of another
/// jobs file's sets (a hostile-input review). Controls: a file of another kind under
/// another shard's index name (a web page) is no record and is passed over; with the
/// planted file gone the run goes on.
#[test]
fn an_index_file_that_is_no_index_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let jobs = jobs_file(dir.path(), &["natrix-natrix"], "[3]", 16);
    let out_dir = dir.path().join("out");
    std::fs::create_dir(&out_dir).unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec!["batch", jobs.to_str().unwrap(), "-o", out_dir.to_str().unwrap()];
        args.extend_from_slice(extra);
        snakeskin(&args)
    };
    let fifo = |path: &Path| {
        let c = std::ffi::CString::new(path.as_os_str().as_encoded_bytes()).unwrap();
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o644) }, 0);
    };
    type Plant<'a> = (&'a str, &'a str, &'a dyn Fn(&Path));
    let plants: [Plant; 4] = [
        ("a FIFO", "not a regular file", &|p| fifo(p)),
        ("a link to /dev/zero", "symbolic link", &|p| std::os::unix::fs::symlink("/dev/zero", p).unwrap()),
        ("a sparse 64 GiB file", "more than such a file can be", &|p| {
            std::fs::File::create(p).unwrap().set_len(64 << 30).unwrap()
        }),
        ("an index cut short", "does not parse", &|p| {
            std::fs::write(p, "{\"generator\": \"snakeskin\", \"jobs_file\": \"j.toml\", \"jobs\": [").unwrap()
        }),
    ];
    for name in ["index.json", "index.shard-1-of-2.json"] {
        let index = out_dir.join(name);
        for (what, said, plant) in plants {
            plant(&index);
            for extra in [&[][..], &["--list"][..]] {
                let start = Instant::now();
                let refused = run(extra);
                let text = stderr(&refused);
                assert_eq!(refused.status.code(), Some(2), "{name} {what} {extra:?}: {text}");
                assert!(text.contains(index.to_str().unwrap()), "{what}: {text}");
                // This run's own index may be refused as a target the run would replace (it
                // was already, where `plan` checks it first); another shard's, which the run
                // only reads, as an index.
                let as_index = text.contains("cannot be read as a batch index");
                if name == "index.json" {
                    assert!(as_index || text.contains("would replace"), "{what}: {text}");
                } else {
                    assert!(as_index && text.contains(said), "{what}: {text}");
                }
                assert!(start.elapsed() < Duration::from_secs(20), "{what}: took {:?}", start.elapsed());
                assert!(!out_dir.join("natrix-natrix").exists(), "{what}: a job ran");
            }
            std::fs::remove_file(&index).unwrap();
        }
    }
    std::fs::write(out_dir.join("index.shard-1-of-2.json"), "<html>site</html>\n").unwrap();
    let control = run(&[]);
    assert_eq!(summary_counts(&control), (1, 0), "{}", stderr(&control));
}

/// Two batch runs into one folder at once keep each other's records: each wrote the whole
/// index at its end from what it read as it began, and the later dropped the other's record
/// of the set it made; a third jobs file's preset of that set's name then replaced it
/// without the refusal the record exists for (a hostile-input review). Here the slow run
/// (each commit paused three seconds, a debug-build hook) ends after the quick one; its index
/// carries the quick run's set, and the third run is refused. Runs into one folder at once
/// stay possible (`a_set_finished_by_another_run_meanwhile_is_not_generated_again`).
#[test]
fn runs_into_one_folder_at_once_keep_each_others_records() {
    if !test_hooks_exist() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let job = |preset: &str| format!("[[job]]\npreset = \"{preset}\"\nseeds = [1]\nsizes = [16]\n");
    let (slow_jobs, quick_jobs, third_jobs) =
        (dir.path().join("a.toml"), dir.path().join("b.toml"), dir.path().join("c.toml"));
    std::fs::write(&slow_jobs, job("natrix-natrix")).unwrap();
    std::fs::write(&quick_jobs, job("boa-constrictor")).unwrap();
    std::fs::create_dir(dir.path().join("c")).unwrap();
    let natrix = stdout(&snakeskin(&["presets", "show", "natrix-natrix"]));
    std::fs::write(dir.path().join("c/boa-constrictor.toml"), natrix).unwrap();
    std::fs::write(&third_jobs, job("c/boa-constrictor.toml")).unwrap();
    // While the slow run's job waits at its commit.
    let args = ["batch", slow_jobs.to_str().unwrap(), "-o", out.to_str().unwrap()];
    let slow = spawn_paused_at_commit(&args, &out.join("natrix-natrix/tile-16-seed1-png"));
    let quick = snakeskin(&["batch", quick_jobs.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_eq!(summary_counts(&quick), (1, 0), "{}", stderr(&quick));
    let slow = slow.wait_with_output().unwrap();
    assert_eq!(summary_counts(&slow), (1, 0), "{}", stderr(&slow));
    let index = read_index(&out);
    assert!(index["jobs_file"].as_str().unwrap().ends_with("a.toml"), "the slow run's index: {index}");
    let carried: Vec<&str> =
        index["other_sets"].as_array().into_iter().flatten().filter_map(|s| s["manifest"].as_str()).collect();
    assert_eq!(carried, ["boa-constrictor/tile-16-seed1-png/boa-constrictor.material.json"], "{index}");
    let boa = out.join("boa-constrictor/tile-16-seed1-png");
    let before = std::fs::read(boa.join("boa-constrictor_color.png")).unwrap();
    let third = snakeskin(&["batch", third_jobs.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_eq!(third.status.code(), Some(2), "{}", stderr(&third));
    assert!(stderr(&third).contains("from another preset of that name"), "{}", stderr(&third));
    assert_eq!(std::fs::read(boa.join("boa-constrictor_color.png")).unwrap(), before);
}

/// A run whose index another holds the lock of (a run stopped while writing it) is refused
/// after a second of tries (exit 1, the lock named) and writes nothing. Shards keep their own
/// indexes and locks. Control: once the lock is let go, the same run goes on.
#[test]
fn an_index_whose_lock_is_held_is_not_written() {
    let dir = tempfile::tempdir().unwrap();
    let jobs = jobs_file(dir.path(), &["natrix-natrix"], "[4]", 16);
    let out_dir = dir.path().join("out");
    std::fs::create_dir(&out_dir).unwrap();
    // The lock a run holds while it writes the index (`SetLock` on the index's name).
    let lock = std::fs::File::create(out_dir.join(".index.json.lock")).unwrap();
    lock.try_lock().unwrap();
    let run = || snakeskin(&["batch", jobs.to_str().unwrap(), "-o", out_dir.to_str().unwrap()]);
    let refused = run();
    assert_eq!(refused.status.code(), Some(1), "{}", stderr(&refused));
    assert!(stderr(&refused).contains("another snakeskin batch is writing the index"), "{}", stderr(&refused));
    assert!(stderr(&refused).contains(".index.json.lock"), "{}", stderr(&refused));
    assert!(!out_dir.join("index.json").exists() && !out_dir.join("natrix-natrix").exists());
    let shard = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", out_dir.to_str().unwrap(), "--shard", "0/2"]);
    assert!(shard.status.success(), "{}", stderr(&shard));
    drop(lock);
    let control = run();
    assert!(control.status.success(), "the control: {}", stderr(&control));
    assert!(out_dir.join("index.json").is_file());
}

/// A job whose set another run is writing (its lock held, past the lock's second of tries)
/// waits for that run, and says so once, instead of failing, and with it the whole queue (of
/// two batches over the same 3K sets started together, the second stopped at its first job,
/// exit 1, having made nothing: a sweep). Where the other run made the set meanwhile, the
/// job is skipped (the set not made again: taking the lock again with its second of tries,
/// it was made again most times, the review); where it let go without making it, the job
/// makes it; where it made another set there (another preset of the name), the job fails
/// rather than replace it.
#[test]
fn a_set_another_run_is_writing_is_waited_for() {
    let dir = tempfile::tempdir().unwrap();
    let jobs = jobs_file(dir.path(), &["natrix-natrix"], "[1, 2]", 16);
    // The first job's set, made apart to be put in place as if another run had made it, and
    // another preset's set of that name.
    let elsewhere = dir.path().join("elsewhere");
    let one = dir.path().join("one.toml");
    std::fs::write(&one, "[[job]]\npreset = \"natrix-natrix\"\nseeds = [1]\nsizes = [16]\n").unwrap();
    let made = snakeskin(&["batch", one.to_str().unwrap(), "-o", elsewhere.to_str().unwrap()]);
    assert!(made.status.success(), "{}", stderr(&made));
    let other_out = set_made_apart(dir.path(), "natrix-natrix.toml", "seed = 9\n");
    let set = Path::new("natrix-natrix/tile-16-seed1-png");
    for meanwhile in ["makes it", "lets go", "makes another"] {
        let out = dir.path().join(format!("out-{}", meanwhile.replace(' ', "-")));
        let folder = out.join(set);
        std::fs::create_dir_all(&folder).unwrap();
        // The lock another run holds while it makes the set (`SetLock`, `.NAME.lock`).
        let lock = std::fs::File::create(folder.join(".natrix-natrix.lock")).unwrap();
        lock.try_lock().unwrap();
        let mut run =
            WatchedRun::start(&["batch", jobs.to_str().unwrap(), "-o", out.to_str().unwrap(), "--concurrent", "1"]);
        // Until the run says it waits (past the lock's second of tries; a run that waits
        // silently, the lock held here, is stopped after a minute).
        run.until_said("waiting for it", 1);
        let said = &run.said;
        assert!(said.contains("another snakeskin run is writing") && said.contains(".natrix-natrix.lock"), "{said}");
        let source = match meanwhile {
            "makes it" => Some(elsewhere.join(set)),
            "makes another" => Some(other_out.join(set)),
            _ => None,
        };
        for file in source.iter().flat_map(|source| std::fs::read_dir(source).unwrap()) {
            let file = file.unwrap().path();
            std::fs::copy(&file, folder.join(file.file_name().unwrap())).unwrap();
        }
        let manifest = folder.join("natrix-natrix.material.json");
        let placed = std::fs::metadata(&manifest).ok().map(|m| m.modified().unwrap());
        drop(lock);
        // Within a minute, or stopped (a wait that never saw the lock free hung the test).
        let (status, rest, stdout) = run.end();
        if meanwhile == "makes another" {
            assert_eq!(status.code(), Some(1), "{rest}");
            assert!(rest.contains("another snakeskin run made") && rest.contains("from other input"), "{rest}");
            // (Refused under the lock, which the run took and let go of, as it removes its own.)
            assert!(!folder.join(".natrix-natrix.lock").exists(), "{rest}");
            assert!(tree(&folder) == tree(&other_out.join(set)), "the other preset's set was replaced");
            continue;
        }
        assert!(status.success(), "{meanwhile}: {rest}");
        assert_eq!(rest.matches("waiting for it").count(), 1, "{rest}");
        let counts = stdout.lines().last().and_then(|l| l.split(": ").nth(1)).unwrap_or_default().to_string();
        let expected = if meanwhile == "makes it" { "1 run, 1 already done" } else { "2 run, 0 already done" };
        assert!(counts.starts_with(expected), "{meanwhile}: {stdout}");
        assert_eq!(statuses(&read_index(&out))[0], if meanwhile == "makes it" { "skipped" } else { "done" });
        if meanwhile == "makes it" {
            assert_eq!(std::fs::metadata(&manifest).unwrap().modified().ok(), placed, "the set was made again");
        }
        let (theirs, made_apart) = (tree(&out.join(set)), tree(&elsewhere.join(set)));
        assert_eq!(theirs.keys().collect::<Vec<_>>(), made_apart.keys().collect::<Vec<_>>(), "{meanwhile}");
        assert!(theirs == made_apart, "{meanwhile}: the set differs");
    }
}

/// Another preset's set committed in the moment a job's lock was taken: the other run let go
/// within the job's second of tries at the lock, before the job called the set busy and
/// waited. The job looks under the lock whether the manifest changed since it started, and
/// refuses; it wrote over the set, taken for the old one, where only a job that waited
/// looked.
#[cfg(target_os = "linux")]
#[test]
fn another_presets_set_made_while_the_lock_is_tried_is_not_written_over() {
    let dir = tempfile::tempdir().unwrap();
    let jobs = jobs_file(dir.path(), &["natrix-natrix"], "[1]", 16);
    let other_out = set_made_apart(dir.path(), "natrix-natrix.toml", "seed = 9\n");
    let set = Path::new("natrix-natrix/tile-16-seed1-png");
    let out = dir.path().join("out");
    let folder = out.join(set);
    std::fs::create_dir_all(&folder).unwrap();
    let lock_path = folder.join(".natrix-natrix.lock");
    let lock = std::fs::File::create(&lock_path).unwrap();
    lock.try_lock().unwrap();
    let run = Command::new(env!("CARGO_BIN_EXE_snakeskin"))
        .args(["batch", jobs.to_str().unwrap(), "-o", out.to_str().unwrap()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // The job tries the lock (it holds the lock file open): the other preset's set is put in
    // place and the lock let go, well within the second of tries.
    common::wait_until_open(run.id(), &lock_path.canonicalize().unwrap());
    for file in std::fs::read_dir(other_out.join(set)).unwrap() {
        let file = file.unwrap().path();
        std::fs::copy(&file, folder.join(file.file_name().unwrap())).unwrap();
    }
    drop(lock);
    let done = run.wait_with_output().unwrap();
    assert_eq!(done.status.code(), Some(1), "{}", stderr(&done));
    assert!(stderr(&done).contains("another snakeskin run made"), "{}", stderr(&done));
    assert!(tree(&folder) == tree(&other_out.join(set)), "the other preset's set was replaced");
}

/// A job waiting for another run's set stops waiting when the queue stops (another job
/// failed): the run ends, the waiting job `not run`. It waited on, and the run with it, until
/// the other run let go.
#[test]
fn a_waiting_job_stops_with_the_queue() {
    let dir = tempfile::tempdir().unwrap();
    let jobs = jobs_file(dir.path(), &["natrix-natrix", "python-regius"], "[1]", 16);
    let out = dir.path().join("out");
    // Both sets' locks held, as another run making them would; then one lock is let go with
    // bytes in its file (not a lock snakeskin made), so that its job fails when it takes it.
    let mut locks = Vec::new();
    for preset in ["natrix-natrix", "python-regius"] {
        let folder = out.join(preset).join("tile-16-seed1-png");
        std::fs::create_dir_all(&folder).unwrap();
        let lock = std::fs::File::create(folder.join(format!(".{preset}.lock"))).unwrap();
        lock.try_lock().unwrap();
        locks.push(lock);
    }
    let mut run =
        WatchedRun::start(&["batch", jobs.to_str().unwrap(), "-o", out.to_str().unwrap(), "--concurrent", "2"]);
    run.until_said("waiting for it", 2);
    let failing = locks.pop().unwrap();
    std::io::Write::write_all(&mut &failing, b"not a lock").unwrap();
    drop(failing);
    // (A waiting job that went on waiting after the queue stopped is stopped after a minute.)
    let (status, rest, _) = run.end();
    // (The failed job's error is of what is in a set's place: exit 2, as `generate` says it.)
    assert_eq!(status.code(), Some(2), "{rest}");
    assert!(rest.contains("python-regius") && rest.contains("not a lock"), "{rest}");
    assert_eq!(statuses(&read_index(&out)), ["not run", "failed"], "{rest}");
    drop(locks);
}

/// Another preset's set made after the run was planned, while the jobs before it ran: the job
/// compares the manifest under the lock with the one there as the run was planned, and
/// refuses. Compared with the one there as the job started, it took the other run's fresh
/// set for the old one and wrote over it, exit 0 (the review: a long queue made the window
/// the whole run).
#[test]
fn another_presets_set_made_after_the_plan_is_not_written_over() {
    let dir = tempfile::tempdir().unwrap();
    let preset = "[scales]\nrows = 20\n";
    std::fs::write(dir.path().join("foo.toml"), preset).unwrap();
    let jobs = dir.path().join("jobs.toml");
    std::fs::write(
        &jobs,
        "[[job]]\npreset = \"natrix-natrix\"\nseeds = [1]\nsizes = [16]\n\n\
         [[job]]\npreset = \"foo.toml\"\nseeds = [1]\nsizes = [16]\n",
    )
    .unwrap();
    // The other preset of that name, and its set, made apart.
    let other_out = set_made_apart(dir.path(), "foo.toml", "[scales]\nrows = 24\n");
    let set = Path::new("foo/tile-16-seed1-png");
    let out = dir.path().join("out");
    // The first job waits for a lock the test holds, so that the second starts after the
    // other preset's set is in place.
    let first = out.join("natrix-natrix/tile-16-seed1-png");
    std::fs::create_dir_all(&first).unwrap();
    let lock = std::fs::File::create(first.join(".natrix-natrix.lock")).unwrap();
    lock.try_lock().unwrap();
    let mut run =
        WatchedRun::start(&["batch", jobs.to_str().unwrap(), "-o", out.to_str().unwrap(), "--concurrent", "1"]);
    run.until_said("waiting for it", 1);
    std::fs::create_dir_all(out.join(set)).unwrap();
    for file in std::fs::read_dir(other_out.join(set)).unwrap() {
        let file = file.unwrap().path();
        std::fs::copy(&file, out.join(set).join(file.file_name().unwrap())).unwrap();
    }
    drop(lock);
    let (status, rest, _) = run.end();
    assert_eq!(status.code(), Some(1), "{rest}");
    assert!(rest.contains("another snakeskin run made") && rest.contains("from other input"), "{rest}");
    assert!(tree(&out.join(set)) == tree(&other_out.join(set)), "the other preset's set was replaced");
    // The control: the first job, which waited and found nothing made meanwhile, made its set.
    assert_eq!(statuses(&read_index(&out)), ["done", "failed"], "{rest}");
}

/// On a terminal a batch's bar is drawn at once, says it is planning, and while a job runs
/// which set it is making, ticking meanwhile: it showed nothing until the first job ended
/// and stood still between jobs (an 8K set: 85 s of a blank screen; a sweep). `script`
/// (util-linux, in every Debian; its `-c` and `-e` are Linux's) gives the run a terminal.
/// Control: redirected, into a folder of its own (a job to make), stderr holds no bar.
#[cfg(target_os = "linux")]
#[test]
fn a_batch_on_a_terminal_says_what_it_is_making_before_the_job_ends() {
    let dir = tempfile::tempdir().unwrap();
    // Big enough that the job lasts several of the bar's ticks (about 1.5 s on two cores).
    let jobs = jobs_file(dir.path(), &["natrix-natrix"], "[1]", 2048);
    let out = dir.path().join("out");
    let line = format!("'{}' batch '{}' -o '{}'", env!("CARGO_BIN_EXE_snakeskin"), jobs.display(), out.display());
    let run = Command::new("script")
        .args(["-qfec", &line, "/dev/null"])
        .stdin(Stdio::null())
        .output()
        .expect("`script` (util-linux) runs the batch on a terminal");
    assert!(run.status.success(), "{}{}", stdout(&run), stderr(&run));
    let screen = stdout(&run);
    let at = |text: &str| screen.find(text).unwrap_or_else(|| panic!("{text:?} not on the screen: {screen:?}"));
    let making = at("making natrix-natrix/tile-2048-seed1-png");
    assert!(at("planning 1 job") < making, "{screen:?}");
    assert!(making < at("1/1 done"), "{screen:?}");
    let elsewhere = dir.path().join("elsewhere");
    let redirected = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", elsewhere.to_str().unwrap()]);
    assert!(redirected.status.success(), "{}", stderr(&redirected));
    assert!(stdout(&redirected).contains("1/1 done"), "the job ran: {}", stdout(&redirected));
    let said = stderr(&redirected);
    assert!(!said.contains("planning") && !said.contains("making"), "{said}");
}
