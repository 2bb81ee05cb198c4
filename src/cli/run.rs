//! `knotrod run`: solve a scene, streaming every equilibrium to the JSONL file
//! and the MCAP recording as it is computed, then print and plot the result
//! and write the summary.

use super::progress::Progress;
use crate::analysis::equilibrium::Equilibrium;
use crate::analysis::event::Event;
use crate::io::live::Live;
use crate::io::output::{Output, OutputKind, is_standard_output, output_kind};
use crate::io::plot::{PlotPoint, bifurcation_diagram};
use crate::io::recording::Recorder;
use crate::io::summary::{Summary, print_equilibrium, print_events};
use crate::linalg::counters::{Work, within};
use crate::model::rod::RodModel;
use crate::scene::{Job, Scene};
use crate::study::error::StudyError;
use crate::study::observer::Observer;
use crate::study::run::run_scene;
use anyhow::Result;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

/// Set by Ctrl-C / SIGTERM: the run stops at the next equilibrium and still
/// finalises its recording and summary.
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Solve the scene at `path`. `record`: `None` for no recording, `Some(None)`
/// for the default file recordings/<scene>.mcap.
pub fn run(
    path: &Path,
    json: Option<PathBuf>,
    segments: Option<usize>,
    record: Option<Option<PathBuf>>,
    live: Option<&str>,
    allow_large: bool,
) -> Result<()> {
    let scene = Scene::load(path)?;
    let _ = ctrlc::set_handler(|| INTERRUPTED.store(true, Ordering::SeqCst));
    if let Some(n) = segments {
        anyhow::ensure!(
            (4..=1_000_000).contains(&n),
            "--segments must be in 4..=1000000, got {n}"
        );
    }
    scene.check_budget(Job::Run, segments, allow_large)?;
    let scene = lab_scene(scene, segments)?;
    let model = scene.rod_model(segments);
    let start = std::time::Instant::now();
    let json = json.or(scene.output.json.clone());
    // a summary or recording on standard output (`-`) keeps it for itself:
    // what is printed for people goes to standard error instead
    let dash = is_standard_output;
    let on_stdout =
        json.as_deref().is_some_and(dash) || matches!(&record, Some(Some(p)) if dash(p));
    let mut summary = Summary::new(&scene, &model);
    let mut outputs = Outputs::open(path, &scene, &model, json.as_deref(), record)?;
    let mut live = match live {
        Some(address) => {
            let l = Live::start(address, &model, scene.model.rod_diameter)?;
            let host = address.rsplit_once(':').map_or(address, |(h, _)| h);
            eprintln!(
                "live view at ws://{host}:{} (Foxglove: Open connection, Foxglove WebSocket)",
                l.port()
            );
            Some(l)
        }
        None => None,
    };
    let work = Work::new();
    let progress = Progress::spinner("equilibria", &work);
    let mut watch = Watch {
        outputs: &mut outputs,
        progress: &progress,
        summary: &mut summary,
        events: Vec::new(),
        live: live.as_mut(),
    };
    let result = within(Some(&work), || run_scene(&scene, segments, &mut watch));
    let mut located = watch.events;
    progress.finish();
    let mut out: Box<dyn Write> = if on_stdout {
        Box::new(std::io::stderr().lock())
    } else {
        Box::new(std::io::stdout().lock())
    };
    writeln!(
        out,
        "scene {} — {}, N = {} ({:.2} s, {} equilibria)",
        summary.scene,
        model.describe(),
        model.segments,
        start.elapsed().as_secs_f64(),
        summary.equilibria.len()
    )?;
    let failed = match result {
        Ok(events) => {
            summary.events = events;
            None
        }
        Err(e) => {
            // stopped early: the events it passed, labelled among themselves
            crate::analysis::event::label_events(&mut located);
            summary.events = located;
            Some(e)
        }
    };
    // the recording, the stream and the summary are finalised whatever
    // happened, with what was computed
    let summary_out = outputs.finish(&summary.events, &mut out)?;
    if let Some(l) = live {
        l.final_events(&summary.events)?;
        // what was published reaches the clients before the server goes
        l.stop();
    }
    report(&scene, &summary, json.as_deref(), &mut out)?;
    if let Some(file) = summary_out {
        let path = file.path().to_path_buf();
        summary.write(file)?;
        if !is_standard_output(&path) {
            writeln!(out, "summary written to {}", path.display())?;
        }
    }
    failed.map_or(Ok(()), |e| Err(e.into()))
}

/// The run's observer: each equilibrium to the outputs, the progress
/// display and the summary; a Ctrl-C stops the run after the equilibrium.
struct Watch<'a> {
    outputs: &'a mut Outputs,
    progress: &'a Progress,
    summary: &'a mut Summary,
    /// The events as located: a run stopped early keeps those it passed.
    events: Vec<Event>,
    /// The live view, if serving.
    live: Option<&'a mut Live>,
}

impl Observer for Watch<'_> {
    fn equilibrium(&mut self, eq: Equilibrium) -> Result<(), StudyError> {
        self.outputs
            .equilibrium(&eq)
            .map_err(|e| StudyError::Observer(e.into()))?;
        if let Some(live) = self.live.as_mut() {
            live.equilibrium(&eq)
                .map_err(|e| StudyError::Observer(e.into()))?;
        }
        self.progress.item(describe(&eq));
        self.summary.equilibria.push(eq);
        if INTERRUPTED.load(Ordering::SeqCst) {
            return Err(StudyError::Observer(
                "interrupted (Ctrl-C): stopped after this equilibrium".into(),
            ));
        }
        Ok(())
    }

    fn event(&mut self, e: &Event) -> Result<(), StudyError> {
        if let Some(live) = self.live.as_mut() {
            live.event(e).map_err(|e| StudyError::Observer(e.into()))?;
        }
        self.events.push(e.clone());
        Ok(())
    }
}

/// Where a run's equilibria go as they are computed: one JSON line each to
/// `<json>.jsonl`, and the MCAP recording; and the summary, written at the
/// end. All are opened (and so held against a second run) before the work.
struct Outputs {
    /// The JSON lines stream.
    stream: Option<BufWriter<Output>>,
    /// The recording.
    recorder: Option<Recorder>,
    /// The summary's file.
    summary: Option<Output>,
}

impl Outputs {
    /// Create the JSONL file beside `json` (if any) and the recording (if
    /// asked for; `Some(None)` is recordings/<scene>.mcap).
    fn open(
        scene_path: &Path,
        scene: &Scene,
        model: &RodModel,
        json: Option<&Path>,
        record: Option<Option<PathBuf>>,
    ) -> Result<Self> {
        // the stream of equilibria goes beside a summary file; beside a FIFO,
        // device or standard output there is nowhere to put it
        let stream = match json.filter(|p| output_kind(p) == OutputKind::File) {
            Some(p) => {
                // checked before the work, not after it
                anyhow::ensure!(
                    !p.is_dir(),
                    "--json {}: is a folder; name the summary's file",
                    p.display()
                );
                let lines = p.with_extension("jsonl");
                anyhow::ensure!(
                    lines != p,
                    "--json {}: the summary would overwrite its own stream of \
                     equilibria ({}); name it with .json",
                    p.display(),
                    lines.display()
                );
                Some(BufWriter::new(Output::create(&lines)?))
            }
            None => None,
        };
        let summary = json.map(Output::create).transpose()?;
        let recorder = match record {
            Some(file) => {
                let file = file.unwrap_or_else(|| {
                    PathBuf::from("recordings").join(format!("{}.mcap", scene.file_stem("run")))
                });
                anyhow::ensure!(
                    !file.is_dir(),
                    "--record {}: is a folder; name the recording's file",
                    file.display()
                );
                anyhow::ensure!(
                    json.is_none_or(|j| j != file && j.with_extension("jsonl") != file),
                    "--record {}: the same file as the JSON summary or its stream",
                    file.display()
                );
                anyhow::ensure!(
                    !(is_standard_output(&file) && json.is_some_and(is_standard_output)),
                    "--record - and --json -: only one of them can go to standard output"
                );
                let text = std::fs::read_to_string(scene_path).unwrap_or_default();
                Some(Recorder::create(
                    &file,
                    &text,
                    model,
                    scene.model.rod_diameter,
                )?)
            }
            None => None,
        };
        Ok(Outputs {
            stream,
            recorder,
            summary,
        })
    }

    /// Stream one equilibrium (the line is flushed at once).
    fn equilibrium(&mut self, eq: &Equilibrium) -> Result<()> {
        if let Some(w) = self.stream.as_mut() {
            let write = |w: &mut BufWriter<Output>| -> std::io::Result<()> {
                serde_json::to_writer(&mut *w, eq)?;
                w.write_all(b"\n")?;
                w.flush()
            };
            write(w).map_err(|e| w.get_ref().error("writing", e))?;
        }
        if let Some(r) = self.recorder.as_mut() {
            r.record(eq)?;
        }
        Ok(())
    }

    /// Finalise the stream, record the events, finalise the recording and
    /// say where it is; hand back the summary's file.
    fn finish(self, events: &[Event], out: &mut impl Write) -> Result<Option<Output>> {
        if let Some(w) = self.stream {
            w.into_inner()
                .map_err(|e| {
                    let (error, w) = e.into_parts();
                    w.get_ref().error("writing", error)
                })?
                .commit()?;
        }
        if let Some(mut r) = self.recorder {
            let recorded = r.events(events);
            let (file, states) = (r.path().to_path_buf(), r.len());
            // finished even when the events failed: a failure is finish's to tell
            r.finish()?;
            recorded?;
            writeln!(
                out,
                "recording written to {} ({states} states)",
                file.display()
            )?;
        }
        Ok(self.summary)
    }
}

/// One line for the progress display.
fn describe(eq: &Equilibrium) -> String {
    format!(
        "branch {}: z* = {:.4}, δ = {:.4}, φ/2π = {:.4}, Tw = {:.4}{}",
        eq.branch,
        eq.z_star,
        eq.delta,
        eq.phi_over_2pi,
        eq.twist,
        if eq.stable { "" } else { " (unstable)" }
    )
}

/// The result: a single equilibrium in full, or the events of a branch and
/// its bifurcation diagram (beside the summary, or in recordings/).
fn report(
    scene: &Scene,
    summary: &Summary,
    json: Option<&Path>,
    out: &mut impl Write,
) -> Result<()> {
    if scene.continuation.is_none() && scene.loading.is_empty() {
        if let Some(eq) = summary.equilibria.first() {
            print_equilibrium(eq, scene, out)?;
        }
        return Ok(());
    }
    print_events(&summary.events, out)?;
    // beside the summary, unless that is no file (then where they go without it)
    let stem = json
        .filter(|p| output_kind(p) == OutputKind::File)
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("recordings").join(scene.file_stem("run")));
    let title = format!("{} (N = {})", summary.scene, summary.segments);
    let points: Vec<PlotPoint> = summary.equilibria.iter().map(PlotPoint::from).collect();
    for f in bifurcation_diagram(&stem, &title, &points, &summary.events)? {
        writeln!(out, "plot written to {}", f.display())?;
    }
    Ok(())
}

/// The scene with gravity fixed in the lab (`[load] major_loop`), the
/// direction found printed.
pub(crate) fn lab_scene(scene: Scene, segments: Option<usize>) -> Result<Scene> {
    let Some(facing) = scene.load.major_loop else {
        return Ok(scene);
    };
    let lab = crate::study::start::in_the_lab(&scene, segments)?.into_owned();
    let g = lab.load.direction;
    eprintln!(
        "gravity across the clamps' axis, the major loop facing {}: along ({:.4}, {:.4}, {:.4})",
        facing.name(),
        g[0],
        g[1],
        g[2]
    );
    Ok(lab)
}
