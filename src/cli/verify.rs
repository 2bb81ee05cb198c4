//! `knotrod verify FILE`: someone's shooting solutions checked by the
//! continuum (adaptive integration, Newton polish) and the discrete rod at
//! three resolutions; a table on the terminal, JSON and a markdown report.

use super::progress::Progress;
use crate::io::auto::{is_auto_input, read_auto_input};
use crate::io::convergence_plot::{Series, convergence_plot};
use crate::io::json::write_pretty;
use crate::io::live::LiveChecks;
use crate::io::output::is_standard_output;
use crate::io::output::{OutputKind, output_kind};
use crate::io::verify_file::read_solutions;
use crate::linalg::counters::{Work, within};
use crate::model::rod::Parameter;
use crate::report::auto_events::{self, compare_with_continuation};
use crate::report::verify::{details, markdown, summary};
use crate::scene::{InitialShape, Job, Scene, human_time};
use crate::study::verify::{Quantity, SolutionCheck, VerifyOptions, verify_all};
use anyhow::{Context, Result, bail, ensure};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The command's arguments.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The solutions (TOML `[[solution]]`, JSON `{"solution": [...]}` or
    /// CSV, one row each), or AUTO-07p's: a TOML file with an `[auto]`
    /// mapping, or its `s.NAME` / `fort.8` itself with `--map`.
    pub file: PathBuf,
    /// For AUTO-07p files: which AUTO unknowns and parameters are knotrod's,
    /// e.g. `--map n0=13,14,15 --map m0=16,17,18 --map phi=1:turns` (φ's
    /// unit: radians or turns, φ/2π), `--map branch=b.NAME`,
    /// `--map continuation=scene.toml` (its events beside AUTO's LP and BP).
    #[arg(long)]
    pub map: Vec<String>,
    /// The base scene (model and clamps); overrides the file's `scene`.
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// Also find the value of this scene parameter (e.g. phi_over_2pi)
    /// whose solution lies closest to the given unknowns.
    #[arg(long)]
    pub fit: Option<String>,
    /// The three resolutions N, 2N, 4N of the discrete rod.
    #[arg(long, value_delimiter = ',', default_value = "100,200,400")]
    pub segments: Vec<usize>,
    /// Stretching stiffness S of the discrete rod (the continuum is
    /// inextensible; the model error is O(1/S), estimated from S/10).
    #[arg(long, default_value_t = 1e7)]
    pub stiffness: f64,
    /// Write the results as JSON here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write a markdown report here (with a convergence plot beside it).
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Threads (default: all cores; at most the machine's cores); results
    /// are the same for any count.
    #[arg(long)]
    pub threads: Option<usize>,
    /// Verify even when the predicted memory or CPU time exceeds the base
    /// scene's `[budget]`.
    #[arg(long)]
    pub allow_large: bool,
    /// Serve each solution's check live to the Foxglove app (WebSocket,
    /// `/verify/checks`) at HOST:PORT (default 127.0.0.1:8765; port 0: any
    /// free port, printed).
    #[arg(long, num_args = 0..=1, default_missing_value = crate::io::live::DEFAULT_ADDRESS)]
    pub live: Option<String>,
}

/// The machine's cores.
fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// Refuse (unless `allow_large`) a verify run whose predicted CPU time or
/// memory exceeds the base scene's `[budget]`, the limits `run` uses: each
/// solution is one equilibrium at each of the three N, its memory held by
/// each of `threads` solves at once. The error names the option to change.
fn check_budget(
    base: &Scene,
    solutions: usize,
    segments: [usize; 3],
    threads: usize,
    allow_large: bool,
) -> Result<()> {
    if allow_large {
        return Ok(());
    }
    // one shooting start per N: the base scene's path of equilibria is not followed
    let mut one = base.clone();
    one.continuation = None;
    one.sweep = None;
    one.loading.clear();
    one.initial.shape = InitialShape::Shooting;
    let seconds: f64 = segments
        .iter()
        .map(|&n| one.estimate(Job::Run, Some(n)).seconds)
        .sum::<f64>()
        * solutions as f64;
    // no more solves at once than solutions
    let at_once = threads.min(solutions).max(1);
    let memory = one.estimate(Job::Run, Some(segments[2])).memory_bytes * at_once as f64;
    let [n1, n2, n3] = segments;
    let b = &base.budget;
    ensure!(
        seconds <= b.hours * 3600.0,
        "predicted CPU time {} ({solutions} solutions × N = {n1}, {n2}, {n3} of --segments) \
         exceeds the budget of {}: give fewer solutions or smaller --segments, raise \
         `budget.hours` in the base scene, or pass --allow-large",
        human_time(seconds),
        human_time(b.hours * 3600.0)
    );
    ensure!(
        memory <= b.memory_gb * 1e9,
        "predicted memory {:.3} GB ({at_once} solves at once, of --threads, each at \
         N = {n3} of --segments) exceeds the budget of {} GB: use fewer --threads or smaller \
         --segments, raise `budget.memory_gb` in the base scene, or pass --allow-large",
        memory / 1e9,
        b.memory_gb
    );
    Ok(())
}

fn parameter(name: &str) -> Result<Parameter> {
    Parameter::named(name).with_context(|| {
        let names: Vec<&str> = Parameter::ALL
            .iter()
            .chain(Parameter::MODEL.iter())
            .map(|p| p.name())
            .collect();
        format!(
            "--fit {name}: not a scene parameter (one of {})",
            names.join(", ")
        )
    })
}

/// Run `knotrod verify`.
pub fn verify(a: Args) -> Result<()> {
    let dash = |p: &Option<PathBuf>| p.as_deref().is_some_and(is_standard_output);
    ensure!(
        !(dash(&a.json) && dash(&a.report)),
        "--json - and --report -: only one of them can go to standard output"
    );
    let [n1, n2, n3] = a.segments[..] else {
        bail!("--segments: give three resolutions N, 2N, 4N (e.g. 100,200,400)");
    };
    ensure!(
        n1 >= 4 && n2 == 2 * n1 && n3 == 2 * n2 && n3 <= 100_000,
        "--segments: give N, 2N, 4N with 4 ≤ N and 4N ≤ 100000 (got {n1},{n2},{n3})"
    );
    ensure!(
        a.stiffness.is_finite() && a.stiffness >= 1e3,
        "--stiffness: a finite stretching stiffness of at least 1e3 (got {})",
        a.stiffness
    );
    let options = VerifyOptions {
        segments: [n1, n2, n3],
        fit: a.fit.as_deref().map(parameter).transpose()?,
        stretching_stiffness: a.stiffness,
        ..VerifyOptions::default()
    };
    let auto = if is_auto_input(&a.file) {
        Some(read_auto_input(&a.file, a.scene.as_deref(), &a.map)?)
    } else {
        ensure!(
            a.map.is_empty(),
            "--map: only for AUTO-07p files (s.NAME, fort.8, or TOML with [auto])"
        );
        None
    };
    let (base, solutions) = match &auto {
        Some(x) => (x.scene.clone(), x.solutions.clone()),
        None => read_solutions(&a.file, a.scene.as_deref())?,
    };
    // more threads than cores only cost memory (and 10⁵ threads cost the machine)
    let threads = a.threads.map_or(cores(), |t| t.clamp(1, cores()));
    if let Some(t) = a.threads.filter(|t| *t > threads) {
        eprintln!("--threads {t}: capped at the machine's {threads} cores");
    }
    check_budget(
        &base,
        solutions.len(),
        options.segments,
        threads,
        a.allow_large,
    )?;
    let live = match &a.live {
        Some(address) => {
            let l = LiveChecks::start(address)?;
            let host = address
                .rsplit_once(':')
                .map_or(address.as_str(), |(h, _)| h);
            eprintln!(
                "live view at ws://{host}:{} (Foxglove: Open connection, Foxglove WebSocket; \
                 /verify/checks)",
                l.port()
            );
            Some(l)
        }
        None => None,
    };
    let work = Work::new();
    let progress = Progress::bar(solutions.len() as u64, "solutions", &work);
    let run = || {
        within(Some(&work), || {
            verify_all(&base, &solutions, &options, &|c: &SolutionCheck| {
                if let Some(l) = &live
                    && let Err(e) = l.check(c)
                {
                    // the checks go on: the live view is a view
                    eprintln!("live view: {e}");
                }
                progress.item(format!("{}: {:?}", c.given.name, c.verdict));
                Ok(())
            })
        })
    };
    let checks = match a.threads {
        Some(_) => rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .context("--threads: the thread pool")?
            .install(run)?,
        None => run()?,
    };
    progress.finish();
    if let Some(l) = live {
        // what was published reaches the clients before the server goes
        l.stop();
    }
    // a JSON or report on standard output keeps it for itself: the table for
    // people goes to standard error
    let mut out: Box<dyn Write> = if dash(&a.json) || dash(&a.report) {
        Box::new(std::io::stderr().lock())
    } else {
        Box::new(std::io::stdout().lock())
    };
    write!(out, "{}", summary(&checks))?;
    if checks.len() <= 10 {
        for c in &checks {
            writeln!(out)?;
            write!(out, "{}", details(c, &checks))?;
        }
    }
    // AUTO's folds and branch points beside knotrod's events on its branch
    let labelled = match &auto {
        Some(x) => Some(auto_events::markdown(&compare_with_continuation(x)?)),
        None => None,
    };
    if let Some(section) = &labelled {
        writeln!(out)?;
        write!(out, "{section}")?;
    }
    if let Some(p) = &a.json {
        write_pretty(p, &checks)?;
        if !dash(&a.json) {
            eprintln!("wrote {}", p.display());
        }
    }
    if let Some(p) = &a.report {
        write_report(p, &a.file, &checks, options.segments, labelled.as_deref())?;
        if !dash(&a.report) {
            eprintln!("wrote {}", p.display());
        }
    }
    Ok(())
}

/// The markdown report at `p` of `checks` of `file` (AUTO's labelled
/// events after it), with its convergence plot beside it where `p` is a
/// file.
fn write_report(
    p: &Path,
    file: &Path,
    checks: &[SolutionCheck],
    segments: [usize; 3],
    labelled: Option<&str>,
) -> Result<()> {
    let plot = p.with_extension("svg");
    // drawn beside a report file only (not beside a FIFO, device or `-`)
    let beside = output_kind(p) == OutputKind::File;
    let drawn = beside
        && match convergence_plot(&plot, &series(checks)) {
            Ok(()) => true,
            Err(e) => {
                eprintln!("no convergence plot: {e}");
                false
            }
        };
    let name = plot
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    let command: Vec<String> = std::env::args()
        .enumerate()
        .map(|(k, a)| if k == 0 { "knotrod".into() } else { a })
        .collect();
    let mut text = markdown(
        &command.join(" "),
        &file.display().to_string(),
        checks,
        segments,
        drawn.then_some(name.as_str()),
    );
    if let Some(section) = labelled {
        text.push('\n');
        text.push_str(section);
    }
    crate::io::output::write_file(p, text.as_bytes())?;
    Ok(())
}

/// Relative distances of n(0) of each solution's discrete rod from its
/// continuum solution, against N.
fn series(checks: &[SolutionCheck]) -> Vec<Series> {
    checks
        .iter()
        .filter_map(|c| {
            let e = c.estimate(Quantity::Force)?;
            let reference = e.continuum.as_ref()?;
            let scale = reference.iter().map(|x| x * x).sum::<f64>().sqrt();
            let points = c
                .der
                .iter()
                .zip(&e.values)
                .map(|(d, v)| {
                    let dist = v
                        .iter()
                        .zip(reference)
                        .map(|(a, b)| (a - b).powi(2))
                        .sum::<f64>()
                        .sqrt();
                    (d.segments as f64, dist / scale)
                })
                .collect();
            Some((format!("{}: n(0)", c.given.name), points))
        })
        .collect()
}
