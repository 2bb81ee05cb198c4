//! Progress of long commands: an indicatif bar on a terminal, plain lines on
//! stderr otherwise (a Slurm log, a pipe), and in both a heartbeat from the
//! run's work counters (`linalg::counters::Work`) so that one long solve shows it is moving: the first
//! report comes within a second, whatever the computation.

use crate::linalg::counters::Work;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// What the reporting thread shares with the command.
struct Shared {
    /// Set when the command is done.
    done: AtomicBool,
    /// Items finished (equilibria, lines, boundary points).
    count: AtomicUsize,
    /// The last item's description.
    last: Mutex<String>,
    /// When the last item finished.
    since: Mutex<Instant>,
    /// The run's work, counted by its solvers.
    work: Arc<Work>,
}

/// A progress display with a heartbeat; finish it (or drop it) when done.
pub struct Progress {
    bar: ProgressBar,
    shared: Arc<Shared>,
    thread: Option<JoinHandle<()>>,
}

/// When plain-text reports are printed (seconds from the start): soon at
/// first, then every minute.
fn next_report(t: f64) -> f64 {
    [1.0, 5.0, 15.0, 30.0, 60.0]
        .into_iter()
        .find(|&s| s > t)
        .unwrap_or(60.0 * ((t / 60.0).floor() + 1.0))
}

impl Progress {
    /// A spinner counting `unit` (e.g. "equilibria") of the run doing `work`.
    pub fn spinner(unit: &'static str, work: &Arc<Work>) -> Self {
        let bar = ProgressBar::new_spinner();
        bar.set_style(
            ProgressStyle::with_template(&format!(
                "{{spinner}} {{elapsed}} {{pos}} {unit} — {{msg}}"
            ))
            .expect("a valid template"),
        );
        Self::start(bar, unit, None, work)
    }

    /// A bar of `len` `unit` (e.g. "lines") of the run doing `work`.
    pub fn bar(len: u64, unit: &'static str, work: &Arc<Work>) -> Self {
        let bar = ProgressBar::new(len);
        bar.set_style(
            ProgressStyle::with_template(&format!(
                "{{bar:30}} {{pos}}/{{len}} {unit}, ETA {{eta}} — {{msg}}"
            ))
            .expect("a valid template"),
        );
        Self::start(bar, unit, Some(len), work)
    }

    fn start(bar: ProgressBar, unit: &'static str, len: Option<u64>, work: &Arc<Work>) -> Self {
        let shared = Arc::new(Shared {
            done: AtomicBool::new(false),
            count: AtomicUsize::new(0),
            last: Mutex::new(String::new()),
            since: Mutex::new(Instant::now()),
            work: work.clone(),
        });
        let terminal = std::io::stderr().is_terminal();
        if terminal {
            bar.enable_steady_tick(Duration::from_millis(200));
        }
        let (b, s) = (bar.clone(), shared.clone());
        let thread = std::thread::spawn(move || heartbeat(&b, &s, unit, len, terminal));
        Progress {
            bar,
            shared,
            thread: Some(thread),
        }
    }

    /// One more item done, described by `message`.
    pub fn item(&self, message: String) {
        self.bar.inc(1);
        self.bar.set_message(message.clone());
        self.shared.count.fetch_add(1, Ordering::Relaxed);
        *self.shared.last.lock().unwrap_or_else(|e| e.into_inner()) = message;
        *self.shared.since.lock().unwrap_or_else(|e| e.into_inner()) = Instant::now();
    }

    /// Stop the heartbeat and clear the bar.
    pub fn finish(mut self) {
        self.stop();
    }

    fn stop(&mut self) {
        self.shared.done.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
        self.bar.finish_and_clear();
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.stop();
    }
}

/// The reporting thread: on a terminal it adds the solver's heartbeat to the
/// bar's message while an item takes long; elsewhere it prints a line at
/// 1 s, 5 s, 15 s, 30 s and then every minute.
fn heartbeat(bar: &ProgressBar, shared: &Shared, unit: &str, len: Option<u64>, terminal: bool) {
    let begin = Instant::now();
    let first = shared.work.iterations();
    let mut due = next_report(0.0);
    while !shared.done.load(Ordering::Relaxed) {
        std::thread::sleep(Duration::from_millis(50));
        let t = begin.elapsed().as_secs_f64();
        let iterations = shared.work.iterations() - first;
        let solving = format!(
            "{iterations} Newton iterations, relative gradient {:.2e}",
            shared.work.residual()
        );
        let last = shared
            .last
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone();
        let quiet = shared
            .since
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .elapsed();
        if terminal {
            if quiet > Duration::from_secs(1) {
                bar.set_message(if last.is_empty() {
                    format!("solving: {solving}")
                } else {
                    format!("{last} — solving: {solving}")
                });
            }
        } else if t >= due {
            due = next_report(t);
            let count = shared.count.load(Ordering::Relaxed);
            let of = len.map_or(String::new(), |l| format!("/{l}"));
            let last = if last.is_empty() {
                String::new()
            } else {
                format!("; last: {last}")
            };
            eprintln!("[{t:.0} s] {count}{of} {unit}, {solving}{last}");
        }
    }
}
