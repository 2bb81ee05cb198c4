//! `knotrod._knotrod`: the Rust half of the Python package `knotrod`.
//!
//! It does no physics: each function parses a scene, calls one library entry
//! point with the GIL released, and turns the result into Python objects
//! (plain dicts, lists and numpy arrays); the pure-Python package
//! (python/knotrod/) wraps those in documented classes. A run's equilibria
//! stay Rust values (`Points`) until Python asks for one: most of a
//! branch's hundreds of points are never read one by one, and converting
//! them all would cost more than the CLI's whole summary. Every library error
//! becomes a `SceneError` or `SolveError`, a panic a `SolveError` (caught
//! here, never unwound into the interpreter), and Ctrl-C during a run a
//! `KeyboardInterrupt` carrying what was computed.

use knotrod::analysis::equilibrium::Equilibrium;
use knotrod::analysis::event::Event;
use knotrod::analysis::profile::Profile;
use knotrod::geometry::closure::{extent, ray_closure};
use knotrod::io::map_files::{LineFolder, trace_cached};
use knotrod::io::recording::{Recorder, parse_recording, parse_state};
use knotrod::io::verify_file::read_solutions;
use knotrod::model::rod::{Parameter, RodModel};
use knotrod::scene::{InitialShape, Job, Scene, SceneError as LibSceneError};
use knotrod::study::boundary::{Traced, trace_island};
use knotrod::study::error::{StudyError, describe};
use knotrod::study::map::{Line, LineStore};
use knotrod::study::verify::{SolutionCheck, VerifyOptions, verify_all};
use knotrod::{knot_type as lib_knot_type, writhe_closed};
use nalgebra::Vector3;
use numpy::{Element, PyArray1, PyArrayMethods};
use pyo3::IntoPyObjectExt;
use pyo3::exceptions::{PyException, PyIndexError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::PathBuf;
use std::sync::Mutex;

pyo3::create_exception!(
    _knotrod,
    KnotrodError,
    PyException,
    "Base class of knotrod's errors."
);
pyo3::create_exception!(
    _knotrod,
    SceneError,
    KnotrodError,
    "A scene that cannot be used; `field` names the offending field (dotted, e.g. `model.segments`) when known."
);
pyo3::create_exception!(
    _knotrod,
    SolveError,
    KnotrodError,
    "A solve or study that failed; `reason` says why, `last` is the last equilibrium computed (a dict) or None."
);

/// The message said when a run is stopped by Ctrl-C (the observer's error).
const INTERRUPTED: &str = "interrupted (Ctrl-C): stopped after this equilibrium";

/// A validated scene and the TOML text it came from (kept for recordings).
#[pyclass(name = "Scene", module = "knotrod._knotrod", frozen)]
struct PyScene {
    /// The scene.
    scene: Scene,
    /// Its TOML text.
    text: String,
}

#[pymethods]
impl PyScene {
    /// Read and validate a scene file (`Scene::load`).
    #[staticmethod]
    fn from_toml(path: PathBuf) -> PyResult<Self> {
        let scene = Scene::load(&path).map_err(|e| scene_error(&e, None))?;
        let text = std::fs::read_to_string(&path).unwrap_or_default();
        Ok(PyScene { scene, text })
    }

    /// Parse and validate scene text (TOML).
    #[staticmethod]
    fn from_text(text: String) -> PyResult<Self> {
        let scene = Scene::parse(&text).map_err(|e| scene_error(&e, Some(&text)))?;
        Ok(PyScene { scene, text })
    }

    /// The scene restarted from a state (an equilibrium's `state_json`):
    /// `[initial] shape = "file"` with that state, at its N. Its text says so
    /// in a comment; the state itself is not in it.
    fn with_start(&self, state_json: &str) -> PyResult<Self> {
        let state: knotrod::RodState = serde_json::from_str(state_json).map_err(|e| {
            let err = SceneError::new_err(format!("start: not a rod state: {e}"));
            Python::attach(|py| {
                let _ = err.value(py).setattr("field", "initial.file");
            });
            err
        })?;
        let mut scene = self.scene.clone();
        scene.model.segments = state.segments() as i64;
        scene.initial.shape = InitialShape::File;
        scene.initial.from_recording = None;
        scene.initial.state = Some(state);
        let text = format!(
            "{}\n# started from a state handed over in Python (N = {}), not in this text\n",
            self.text, scene.model.segments
        );
        Ok(PyScene { scene, text })
    }

    /// The scene as JSON text (every section, defaults filled in).
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.scene).map_err(|e| KnotrodError::new_err(e.to_string()))
    }

    /// The scene's TOML text.
    #[getter]
    fn text(&self) -> &str {
        &self.text
    }

    /// The scene's N (model.segments).
    #[getter]
    fn segments(&self) -> i64 {
        self.scene.model.segments
    }
}

/// A `SceneError` from the library's, with `field` set: the dotted field of
/// an invalid value, or (for a parse error of `text`) the key on the line
/// the parser points at, under its table.
fn scene_error(e: &LibSceneError, text: Option<&str>) -> PyErr {
    let field = match e {
        LibSceneError::Invalid { field, .. } => Some(field.to_string()),
        LibSceneError::TooLarge { key, .. } => Some(key.to_string()),
        LibSceneError::Parse { message, .. } => parse_field(message, text),
        LibSceneError::Io { .. } => None,
    };
    let err = SceneError::new_err(e.to_string());
    Python::attach(|py| {
        let _ = err.value(py).setattr("field", field);
    });
    err
}

/// The field a TOML parse error is about: `missing field `x``, `unknown
/// field `x`` or the key of the line ("line L, column C: …"), prefixed with
/// the table the line is in.
fn parse_field(message: &str, text: Option<&str>) -> Option<String> {
    let quoted = message
        .split('`')
        .nth(1)
        .filter(|_| message.contains("field `"))
        .map(str::to_string);
    let line: Option<usize> = message
        .strip_prefix("line ")
        .and_then(|r| r.split(',').next())
        .and_then(|n| n.trim().parse().ok());
    let (Some(text), Some(line)) = (text, line) else {
        return quoted;
    };
    // the scene's own required sections: the parser points at the first
    // table, which is not where they are missing from
    if message.contains("missing field `model`") || message.contains("missing field `clamps`") {
        return quoted;
    }
    let lines: Vec<&str> = text.lines().collect();
    let here = lines.get(line.checked_sub(1)?)?.trim();
    let table = lines[..line.min(lines.len())]
        .iter()
        .rev()
        .map(|l| l.trim())
        .find(|l| l.starts_with('[') && l.ends_with(']'))
        .map(|l| l.trim_matches(|c| c == '[' || c == ']').trim().to_string());
    let key = if here.starts_with('[') {
        // an unknown table is its own field
        if quoted.as_deref() == table.as_deref() {
            return quoted;
        }
        quoted
    } else {
        here.split('=')
            .next()
            .map(|k| k.trim().trim_matches('"').to_string())
            .filter(|k| !k.is_empty())
            .or(quoted)
    };
    match (table, key) {
        (Some(t), Some(k)) => Some(format!("{t}.{k}")),
        (None, k) => k,
        (t, None) => t,
    }
}

/// A `SolveError` with the reason (the error and its chain of steps) and
/// the last equilibrium computed; a scene error inside a study stays a
/// `SceneError`.
fn study_error(
    py: Python<'_>,
    e: &StudyError,
    last: Option<&Equilibrium>,
    model: &RodModel,
) -> PyErr {
    let mut inner = e;
    while let StudyError::At { source, .. } = inner {
        inner = source;
    }
    if let StudyError::Scene(se) = inner {
        return scene_error(se, None);
    }
    let mut reason = e.to_string();
    let mut source = std::error::Error::source(e);
    while let Some(s) = source {
        reason.push_str(": ");
        reason.push_str(&s.to_string());
        source = s.source();
    }
    let err = SolveError::new_err(reason.clone());
    let value = err.value(py);
    let _ = value.setattr("reason", reason);
    let last = last.and_then(|eq| equilibrium_dict(py, eq, model).ok());
    let _ = value.setattr("last", last);
    err
}

/// Run `f` with the GIL released, a panic turned into a `SolveError`.
fn detached<T: Send>(py: Python<'_>, f: impl FnOnce() -> T + Send) -> PyResult<T> {
    py.detach(|| catch_unwind(AssertUnwindSafe(f)))
        .map_err(|p| {
            let what = p
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "unknown".into());
            SolveError::new_err(format!("internal error (a bug in knotrod): {what}"))
        })
}

/// Check `segments` as the CLI does.
fn check_segments(segments: Option<usize>) -> PyResult<()> {
    match segments {
        Some(n) if !(4..=1_000_000).contains(&n) => Err(PyValueError::new_err(format!(
            "segments must be in 4..=1000000, got {n}"
        ))),
        _ => Ok(()),
    }
}

/// Python objects from serde (through the json module: plain dicts, lists,
/// floats, ints, strings, None).
fn to_py<'py>(py: Python<'py>, value: &impl serde::Serialize) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value).map_err(|e| KnotrodError::new_err(e.to_string()))?;
    py.import("json")?.call_method1("loads", (text,))
}

/// Python objects from a JSON value, directly (no text in between).
fn value_to_py<'py>(py: Python<'py>, value: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    use serde_json::Value;
    match value {
        Value::Null => Ok(py.None().into_bound(py)),
        Value::Bool(b) => b.into_bound_py_any(py),
        Value::Number(n) => match (n.as_i64(), n.as_u64()) {
            (Some(i), _) => i.into_bound_py_any(py),
            (None, Some(u)) => u.into_bound_py_any(py),
            _ => n.as_f64().unwrap_or(f64::NAN).into_bound_py_any(py),
        },
        Value::String(s) => s.into_bound_py_any(py),
        Value::Array(items) => {
            let list = PyList::empty(py);
            for item in items {
                list.append(value_to_py(py, item)?)?;
            }
            Ok(list.into_any())
        }
        Value::Object(map) => {
            let d = PyDict::new(py);
            for (k, v) in map {
                d.set_item(k, value_to_py(py, v)?)?;
            }
            Ok(d.into_any())
        }
    }
}

/// An (n, 3) array.
fn rows<'py>(py: Python<'py>, v: &[[f64; 3]]) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<f64> = v.iter().flatten().copied().collect();
    Ok(PyArray1::from_vec(py, flat)
        .reshape([v.len(), 3])?
        .into_any())
}

/// The arrays of a state along s (nodes, directors, strains, n(s), m(s) and
/// their arc lengths) into `d`.
fn add_arrays(
    py: Python<'_>,
    d: &Bound<'_, PyDict>,
    model: &RodModel,
    state: &knotrod::RodState,
) -> PyResult<()> {
    let p = Profile::of(model, state);
    let nodes: Vec<[f64; 3]> = state.nodes.iter().map(|x| [x[0], x[1], x[2]]).collect();
    d.set_item("nodes", rows(py, &nodes)?)?;
    d.set_item("theta", PyArray1::from_slice(py, &state.theta))?;
    let directors: Vec<f64> = p.directors.iter().flatten().flatten().copied().collect();
    let directors = PyArray1::from_vec(py, directors).reshape([p.directors.len(), 3, 3])?;
    d.set_item("directors", directors)?;
    d.set_item("strains", rows(py, &p.strains)?)?;
    d.set_item("force", rows(py, &p.force)?)?;
    d.set_item("moment", rows(py, &p.moment)?)?;
    d.set_item("s_nodes", PyArray1::from_slice(py, &p.s_nodes))?;
    d.set_item("s_edges", PyArray1::from_slice(py, &p.s_edges))?;
    d.set_item("s_vertices", PyArray1::from_slice(py, &p.s_vertices))?;
    Ok(())
}

/// The rod model as JSON text (what `vtp` reads with a state).
fn model_json(model: &RodModel) -> String {
    serde_json::to_string(model).unwrap_or_default()
}

/// The state as JSON text (what `[initial] shape = "file"` reads).
fn state_json(state: &knotrod::RodState) -> String {
    serde_json::to_string(state).unwrap_or_default()
}

/// An equilibrium's scalars (the JSON summary's fields, without its state).
fn scalars_dict<'py>(py: Python<'py>, eq: &Equilibrium) -> PyResult<Bound<'py, PyDict>> {
    let mut value = serde_json::to_value(eq).map_err(|e| KnotrodError::new_err(e.to_string()))?;
    if let Some(o) = value.as_object_mut() {
        o.remove("state");
    }
    Ok(value_to_py(py, &value)?.cast_into::<PyDict>()?)
}

/// An equilibrium as a dict: its scalars (the JSON summary's fields) and
/// the arrays of its state.
fn equilibrium_dict<'py>(
    py: Python<'py>,
    eq: &Equilibrium,
    model: &RodModel,
) -> PyResult<Bound<'py, PyDict>> {
    let d = scalars_dict(py, eq)?;
    add_arrays(py, &d, model, &eq.state)?;
    d.set_item("state_json", state_json(&eq.state))?;
    d.set_item("model_json", model_json(model))?;
    Ok(d)
}

/// One value per equilibrium as a numpy array.
fn column<'py, T: Element>(
    py: Python<'py>,
    eqs: &[Equilibrium],
    f: impl Fn(&Equilibrium) -> T,
) -> Bound<'py, PyArray1<T>> {
    PyArray1::from_iter(py, eqs.iter().map(f))
}

/// The equilibria of a run, kept as the library's values: each becomes
/// Python objects (a dict of scalars, a dict of arrays) only when asked for,
/// so that a branch costs no more through Python than through the CLI.
#[pyclass(name = "Points", module = "knotrod._knotrod", frozen)]
struct PyPoints {
    /// The equilibria, in the order computed.
    equilibria: Vec<Equilibrium>,
    /// The rod model they are states of (the scene's, at the run's N).
    model: RodModel,
}

impl PyPoints {
    /// The equilibrium at `index` (negative: from the end, as Python's).
    fn at(&self, index: isize) -> PyResult<&Equilibrium> {
        let n = self.equilibria.len() as isize;
        let k = if index < 0 { index + n } else { index };
        if (0..n).contains(&k) {
            Ok(&self.equilibria[k as usize])
        } else {
            Err(PyIndexError::new_err(format!(
                "point {index} of {n} is out of range"
            )))
        }
    }
}

#[pymethods]
impl PyPoints {
    /// The number of equilibria.
    fn __len__(&self) -> usize {
        self.equilibria.len()
    }

    /// The scalars of equilibrium `index` (the JSON summary's fields).
    fn scalars<'py>(&self, py: Python<'py>, index: isize) -> PyResult<Bound<'py, PyDict>> {
        scalars_dict(py, self.at(index)?)
    }

    /// The arrays along s of equilibrium `index` (nodes, theta, directors,
    /// strains, force, moment, s_nodes, s_edges, s_vertices).
    fn arrays<'py>(&self, py: Python<'py>, index: isize) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        add_arrays(py, &d, &self.model, &self.at(index)?.state)?;
        Ok(d)
    }

    /// The state of equilibrium `index` as JSON text.
    fn state_json(&self, index: isize) -> PyResult<String> {
        Ok(state_json(&self.at(index)?.state))
    }

    /// The rod model of the equilibria as JSON text.
    fn model_json(&self) -> String {
        model_json(&self.model)
    }

    /// The N of equilibrium `index`.
    fn segments(&self, index: isize) -> PyResult<usize> {
        Ok(self.at(index)?.state.segments())
    }

    /// The scalars as numpy arrays, one entry per equilibrium: the columns
    /// of `knotrod.Branch.columns()`, in its order.
    fn columns<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let e = &self.equilibria[..];
        let d = PyDict::new(py);
        d.set_item("branch", column(py, e, |q| q.branch as i64))?;
        d.set_item("leg", column(py, e, |q| q.leg as i64))?;
        d.set_item("z_star", column(py, e, |q| q.z_star))?;
        d.set_item("delta", column(py, e, |q| q.delta))?;
        d.set_item("phi_over_2pi", column(py, e, |q| q.phi_over_2pi))?;
        d.set_item("energy", column(py, e, |q| q.energy))?;
        d.set_item("twist", column(py, e, |q| q.twist))?;
        d.set_item("writhe", column(py, e, |q| q.writhe))?;
        d.set_item("link", column(py, e, |q| q.link))?;
        d.set_item(
            "knot_determinant",
            column(py, e, |q| q.knot_determinant as i64),
        )?;
        d.set_item("knotted", column(py, e, |q| q.knotted))?;
        d.set_item("walled", column(py, e, |q| q.walled))?;
        d.set_item("stable", column(py, e, |q| q.stable))?;
        d.set_item(
            "negative_eigenvalues",
            column(py, e, |q| q.negative_eigenvalues as i64),
        )?;
        d.set_item("good_knot", column(py, e, |q| q.good_knot))?;
        d.set_item("min_z", column(py, e, |q| q.min_z))?;
        d.set_item("max_z", column(py, e, |q| q.max_z))?;
        d.set_item("wall_distance", column(py, e, |q| q.wall_distance))?;
        d.set_item("min_self_distance", column(py, e, |q| q.min_self_distance))?;
        d.set_item("contact_force", column(py, e, |q| q.contact_force))?;
        d.set_item("iterations", column(py, e, |q| q.iterations as i64))?;
        d.set_item("converged", column(py, e, |q| q.converged))?;
        for c in 0..3 {
            d.set_item(format!("n0_{}", c + 1), column(py, e, |q| q.n0[c]))?;
        }
        for c in 0..3 {
            d.set_item(format!("m0_{}", c + 1), column(py, e, |q| q.m0[c]))?;
        }
        let first = |v: &[f64]| v.first().copied().unwrap_or(f64::NAN);
        d.set_item(
            "lowest_eigenvalue",
            column(py, e, |q| first(&q.lowest_eigenvalues)),
        )?;
        d.set_item(
            "lowest_omega_squared",
            column(py, e, |q| first(&q.omega_squared)),
        )?;
        Ok(d)
    }
}

/// Solve a scene's equilibrium (its start, solved and measured).
#[pyfunction]
#[pyo3(signature = (scene, segments=None, allow_large=false))]
fn solve<'py>(
    py: Python<'py>,
    scene: &PyScene,
    segments: Option<usize>,
    allow_large: bool,
) -> PyResult<Bound<'py, PyDict>> {
    check_segments(segments)?;
    let s = &scene.scene;
    s.check_budget(Job::Run, segments, allow_large)
        .map_err(|e| scene_error(&e, None))?;
    let model = s.rod_model(segments);
    match detached(py, || knotrod::solve_scene(s, segments))? {
        Ok(eq) => equilibrium_dict(py, &eq, &model),
        Err(e) => Err(study_error(py, &e, None, &model)),
    }
}

/// What `run` hands back: equilibria, events, and the error that stopped it.
struct RunOutcome {
    /// The equilibria, in order.
    equilibria: Vec<Equilibrium>,
    /// The labelled events (empty when the run stopped early).
    events: Vec<Event>,
    /// Why it stopped early.
    error: Option<StudyError>,
}

/// Run a scene (a branch, a sweep of branches or a loading path): every
/// equilibrium is kept, handed to `progress` (a dict of its scalars) and
/// recorded (MCAP) when `record` names a file. Returns (points, events), the
/// equilibria as `Points`; Ctrl-C stops it after the current equilibrium
/// with a KeyboardInterrupt whose `partial` is (points, events) and the
/// recording finalised.
#[pyfunction]
#[pyo3(signature = (scene, segments=None, progress=None, record=None, allow_large=false))]
fn run<'py>(
    py: Python<'py>,
    scene: &PyScene,
    segments: Option<usize>,
    progress: Option<Py<PyAny>>,
    record: Option<PathBuf>,
    allow_large: bool,
) -> PyResult<(Bound<'py, PyPoints>, Bound<'py, PyList>)> {
    check_segments(segments)?;
    let s = &scene.scene;
    s.check_budget(Job::Run, segments, allow_large)
        .map_err(|e| scene_error(&e, None))?;
    let model = s.rod_model(segments);
    let mut recorder = match &record {
        Some(file) => Some(
            Recorder::create(file, &scene.text, &model, s.model.rod_diameter)
                .map_err(|e| KnotrodError::new_err(e.to_string()))?,
        ),
        None => None,
    };
    let window = Window::new(progress.as_ref());
    let outcome = detached(py, || {
        let mut out = RunOutcome {
            equilibria: Vec::new(),
            events: Vec::new(),
            error: None,
        };
        let mut record_error = None;
        // the events as located: an interrupted run keeps those it passed
        let mut located: Vec<Event> = Vec::new();
        let on_event = |e: &Event| {
            located.push(e.clone());
            Ok(())
        };
        let on_equilibrium = |eq: Equilibrium| {
            if let Some(r) = recorder.as_mut()
                && let Err(e) = r.record(&eq)
            {
                record_error = Some(e.to_string());
            }
            let index = out.equilibria.len();
            let told = window.tell(|py| {
                item(py, |d| {
                    d.set_item("index", index)?;
                    d.set_item("branch", eq.branch)?;
                    d.set_item("z_star", eq.z_star)?;
                    d.set_item("delta", eq.delta)?;
                    d.set_item("phi_over_2pi", eq.phi_over_2pi)?;
                    d.set_item("twist", eq.twist)?;
                    d.set_item("stable", eq.stable)?;
                    d.set_item("good_knot", eq.good_knot)
                })
            });
            out.equilibria.push(eq);
            if let Some(e) = record_error.take() {
                return Err(StudyError::Observer(format!("recording: {e}").into()));
            }
            told
        };
        let result = knotrod::run_scene(
            s,
            segments,
            &mut knotrod::study::observer::both(on_equilibrium, on_event),
        );
        match result {
            Ok(events) => out.events = events,
            Err(e) => {
                knotrod::analysis::event::label_events(&mut located);
                out.events = located;
                out.error = Some(e);
            }
        }
        out
    })?;
    // the recording is finalised whatever happened, with what was computed
    let finished = match recorder {
        Some(mut r) => r
            .events(&outcome.events)
            .and_then(|()| r.finish())
            .map_err(|e| KnotrodError::new_err(e.to_string())),
        None => Ok(()),
    };
    let RunOutcome {
        equilibria,
        events,
        error,
    } = outcome;
    // the Python exception raised in the observer (Ctrl-C, or the progress
    // callback's own)
    let python = window.raised();
    // the equilibria stay Rust values; Python converts those it reads
    let error = match (&python, &error) {
        (None, Some(e)) => Some(study_error(py, e, equilibria.last(), &model)),
        _ => None,
    };
    let points = Bound::new(py, PyPoints { equilibria, model })?;
    let events = to_py(py, &events)?.cast_into::<PyList>()?;
    if let Some(err) = python {
        let value = err.value(py);
        let _ = value.setattr("partial", (points.clone(), events.clone()));
        let _ = value.setattr("recording", record.clone());
        return Err(err);
    }
    if let Some(err) = error {
        return Err(err);
    }
    finished?;
    Ok((points, events))
}

/// The value in a mutex, also after a panic elsewhere poisoned it.
fn locked<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|p| p.into_inner())
}

/// Python's window on a long call made without the GIL: each report takes
/// the GIL for a moment, runs Python's signal handlers (Ctrl-C raises
/// KeyboardInterrupt there) and the progress callback; the first exception
/// is kept and the call told to stop.
struct Window<'a> {
    progress: Option<&'a Py<PyAny>>,
    raised: Mutex<Option<PyErr>>,
}

impl<'a> Window<'a> {
    fn new(progress: Option<&'a Py<PyAny>>) -> Self {
        Window {
            progress,
            raised: Mutex::new(None),
        }
    }

    /// Report: the callback gets `item`'s object (built only when there is a
    /// callback); an error once Python raised.
    fn tell(
        &self,
        item: impl FnOnce(Python<'_>) -> PyResult<Bound<'_, PyAny>>,
    ) -> Result<(), StudyError> {
        Python::attach(|py| -> PyResult<()> {
            py.check_signals()?;
            if let Some(cb) = self.progress {
                cb.call1(py, (item(py)?,))?;
            }
            Ok(())
        })
        .map_err(|e| {
            locked(&self.raised).get_or_insert(e);
            StudyError::Observer(INTERRUPTED.into())
        })
    }

    /// Whether Python raised.
    fn has_raised(&self) -> bool {
        locked(&self.raised).is_some()
    }

    /// The exception Python raised, if it did.
    fn raised(self) -> Option<PyErr> {
        self.raised.into_inner().unwrap_or_else(|p| p.into_inner())
    }
}

/// A dict built by `fill`, as a progress item.
fn item<'py>(
    py: Python<'py>,
    fill: impl FnOnce(&Bound<'py, PyDict>) -> PyResult<()>,
) -> PyResult<Bound<'py, PyAny>> {
    let d = PyDict::new(py);
    fill(&d)?;
    Ok(d.into_any())
}

/// Where a map from Python keeps its lines (a folder, to resume, or memory
/// only): every line computed is reported through the window, whose
/// exception (Ctrl-C) stops the map after the lines in progress.
struct PyLines<'a> {
    folder: Option<LineFolder>,
    window: &'a Window<'a>,
    parameter: &'a str,
    done: Mutex<Vec<Line>>,
}

impl LineStore for PyLines<'_> {
    fn get(&self, index: usize, value: f64) -> Option<Line> {
        let line = self.folder.as_ref()?.get(index, value)?;
        locked(&self.done).push(line.clone());
        Some(line)
    }
    fn put(&self, line: &Line) -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
        if let Some(f) = &self.folder {
            f.put(line)?;
        }
        locked(&self.done).push(line.clone());
        self.window.tell(|py| {
            item(py, |d| {
                d.set_item("stage", "line")?;
                d.set_item("index", line.index)?;
                d.set_item(self.parameter, line.value)?;
                d.set_item("good_intervals", line.intervals.len())
            })
        })?;
        Ok(())
    }
}

/// Map a scene's good-knot region (its `[map]` and `[continuation]`), as
/// `knotrod map` does: the boundary walk from the scene's good knot (its
/// boundary polished on the continuum when `[map] polish = true`), then one
/// branch per line in parallel; the assembled map as a dict. `progress` gets
/// a dict per boundary point and per line; `cache` names a folder keeping
/// the lines and the walk, from which a rerun resumes. Ctrl-C stops it
/// (after the walk or the lines in progress) with a KeyboardInterrupt whose
/// `partial` holds the walk and the lines computed.
#[pyfunction]
#[pyo3(signature = (scene, segments=None, progress=None, cache=None, allow_large=false))]
fn map_scene<'py>(
    py: Python<'py>,
    scene: &PyScene,
    segments: Option<usize>,
    progress: Option<Py<PyAny>>,
    cache: Option<PathBuf>,
    allow_large: bool,
) -> PyResult<Bound<'py, PyAny>> {
    check_segments(segments)?;
    let raw = &scene.scene;
    raw.check_budget(Job::Map, segments, allow_large)
        .map_err(|e| scene_error(&e, None))?;
    // gravity fixed in the lab once (`[load] major_loop`), as the CLI does:
    // the walk and every line then start from the same resolved scene
    let lab = detached(py, || {
        knotrod::study::start::in_the_lab(raw, segments).map(|c| c.into_owned())
    })?
    .map_err(|e| study_error(py, &e, None, &raw.rod_model(segments)))?;
    let s = &lab;
    let (Some(spec), Some(cont)) = (s.map.clone(), s.continuation.clone()) else {
        let err = SceneError::new_err("the scene needs [map] and [continuation] sections");
        err.value(py).setattr("field", "map")?;
        return Err(err);
    };
    let name = s.file_stem("map");
    let indices: Vec<usize> = (0..spec.lines).collect();
    let model = s.rod_model(segments);
    let folder = match &cache {
        Some(c) => Some(
            LineFolder::create(c, s, &spec, segments)
                .map_err(|e| KnotrodError::new_err(e.to_string()))?,
        ),
        None => None,
    };
    let window = Window::new(progress.as_ref());
    let store = PyLines {
        folder,
        window: &window,
        parameter: spec.parameter.name(),
        done: Mutex::new(Vec::new()),
    };
    // the walk first (sequential), as the CLI: its points reported, an
    // interruption honoured when it ends
    let on_point = |k: usize, on: &str| {
        let _ = window.tell(|py| {
            item(py, |d| {
                d.set_item("stage", "boundary")?;
                d.set_item("point", k)?;
                d.set_item("on", on)
            })
        });
    };
    // a walk that cannot start or fails says why in the map (`stopped`),
    // as the CLI's
    let traced = detached(py, || match &cache {
        Some(c) => trace_cached(s, &spec, segments, c, &on_point).map_err(|e| e.to_string()),
        None => Ok(trace_island(s, &spec, segments, &on_point)
            .unwrap_or_else(|e| Traced::failed(describe(&e)))),
    })?
    .map_err(|e| KnotrodError::new_err(format!("the boundary walk's cache: {e}")))?;
    let lines = if window.has_raised() {
        None
    } else {
        Some(detached(py, || {
            knotrod::study::map::compute_lines(s, &spec, &indices, segments, &store, &|_| {})
        })?)
    };
    // an exception in Python (Ctrl-C): the walk and the lines done kept
    let done = store.done.into_inner().unwrap_or_else(|p| p.into_inner());
    if let Some(err) = window.raised() {
        let partial = PyDict::new(py);
        let _ = to_py(py, &traced).and_then(|t| partial.set_item("traced", t));
        let _ = to_py(py, &done).and_then(|l| partial.set_item("lines", l));
        let _ = err.value(py).setattr("partial", partial);
        return Err(err);
    }
    let lines = lines
        .expect("the lines ran: Python raised nothing")
        .map_err(|e| study_error(py, &e, None, &model))?;
    let map = knotrod::study::map::assemble(
        &name,
        &spec,
        cont.parameter,
        cont.range,
        lines,
        Some(traced),
    );
    to_py(py, &map)
}

/// Verify shooting solutions (a TOML, JSON or CSV file as `knotrod verify`
/// reads) by the continuum and the discrete rod at N, 2N, 4N: one dict per
/// solution. `progress` gets each solution's dict as it is done (in the
/// order they finish); Ctrl-C stops the run once the solutions in progress
/// are done, with a KeyboardInterrupt whose `partial` lists those done.
#[pyfunction]
#[pyo3(signature = (path, scene=None, segments=(100, 200, 400), stiffness=1e7, fit=None, progress=None))]
fn verify<'py>(
    py: Python<'py>,
    path: PathBuf,
    scene: Option<PathBuf>,
    segments: (usize, usize, usize),
    stiffness: f64,
    fit: Option<&str>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let (n1, n2, n3) = segments;
    if !(n1 >= 4 && n2 == 2 * n1 && n3 == 2 * n2 && n3 <= 100_000) {
        return Err(PyValueError::new_err(format!(
            "segments: give N, 2N, 4N with 4 ≤ N and 4N ≤ 100000 (got {n1}, {n2}, {n3})"
        )));
    }
    if !(stiffness.is_finite() && stiffness >= 1e3) {
        return Err(PyValueError::new_err(format!(
            "stiffness: a finite stretching stiffness of at least 1e3 (got {stiffness})"
        )));
    }
    let fit = match fit {
        Some(name) => Some(Parameter::named(name).ok_or_else(|| {
            PyValueError::new_err(format!("fit: {name} is not a scene parameter"))
        })?),
        None => None,
    };
    let options = VerifyOptions {
        segments: [n1, n2, n3],
        fit,
        stretching_stiffness: stiffness,
        ..VerifyOptions::default()
    };
    let (base, solutions) = read_solutions(&path, scene.as_deref()).map_err(|e| {
        let err = SceneError::new_err(e.to_string());
        Python::attach(|py| {
            let _ = err.value(py).setattr("field", None::<String>);
        });
        err
    })?;
    let model = base.rod_model(None);
    let done: Mutex<Vec<SolutionCheck>> = Mutex::new(Vec::new());
    let window = Window::new(progress.as_ref());
    let on_done = |c: &SolutionCheck| -> Result<(), StudyError> {
        locked(&done).push(c.clone());
        window.tell(|py| to_py(py, c))
    };
    let checks = detached(py, || verify_all(&base, &solutions, &options, &on_done))?;
    if let Some(err) = window.raised() {
        let done = done.into_inner().unwrap_or_else(|p| p.into_inner());
        let _ = to_py(py, &done).and_then(|d| err.value(py).setattr("partial", d));
        return Err(err);
    }
    let checks = checks.map_err(|e| study_error(py, &e, None, &model))?;
    to_py(py, &checks)
}

/// Writhe and knot type of a curve ((n, 3) points): closed as given, or
/// (closed=False) closed by rays along −z from the first point and +z from
/// the last. A dict: writhe, knot_determinant, alexander, knot_name,
/// knot_names, crossings.
#[pyfunction]
#[pyo3(signature = (points, closed=true))]
fn knot_type<'py>(
    py: Python<'py>,
    points: Vec<[f64; 3]>,
    closed: bool,
) -> PyResult<Bound<'py, PyDict>> {
    if points.len() < 3 || points.iter().flatten().any(|v| !v.is_finite()) {
        return Err(PyValueError::new_err(
            "points: at least 3 finite points (an (n, 3) array)",
        ));
    }
    let pts: Vec<Vector3<f64>> = points.iter().map(|p| Vector3::from(*p)).collect();
    let (writhe, kt) = detached(py, || {
        if closed {
            (writhe_closed(&pts), lib_knot_type(&pts))
        } else {
            let size = extent(&pts).max(1e-300);
            let (down, up) = (-Vector3::z(), Vector3::z());
            // the writhe's closure error decays as 1/(ray length)
            let w = writhe_closed(&ray_closure(&pts, down, up, 1e6 * size));
            (w, lib_knot_type(&ray_closure(&pts, down, up, 4.0 * size)))
        }
    })?;
    let kt = kt.map_err(|e| PyValueError::new_err(format!("no knot type: {e}")))?;
    let d = PyDict::new(py);
    d.set_item("writhe", writhe)?;
    d.set_item("knot_determinant", kt.determinant)?;
    d.set_item("alexander", kt.alexander.clone())?;
    d.set_item("knot_name", kt.name.clone())?;
    d.set_item("knot_names", kt.names.clone())?;
    d.set_item("crossings", kt.crossings)?;
    Ok(d)
}

/// A recording as Python values: (scalars, events, metadata, states).
type RecordingParts<'py> = (
    Bound<'py, PyAny>,
    Bound<'py, PyAny>,
    Bound<'py, PyAny>,
    Bound<'py, PyList>,
);

/// Read a recording (MCAP): (scalars, events, metadata, states), the states
/// as dicts of arrays with the recorded scalars.
#[pyfunction]
fn read_recording<'py>(py: Python<'py>, path: PathBuf) -> PyResult<RecordingParts<'py>> {
    let bytes = std::fs::read(&path).map_err(|e| {
        pyo3::exceptions::PyOSError::new_err(format!("cannot read {}: {e}", path.display()))
    })?;
    let io = |e: knotrod::io::error::IoError| KnotrodError::new_err(e.to_string());
    let rec = detached(py, || parse_recording(&path, &bytes))?.map_err(io)?;
    let states = PyList::empty(py);
    for (k, scalars) in rec.scalars.iter().enumerate() {
        let msg = detached(py, || parse_state(&path, &bytes, k as u64))?.map_err(io)?;
        let d = to_py(py, scalars)?.cast_into::<PyDict>()?;
        add_arrays(py, &d, &msg.model, &msg.state)?;
        d.set_item("state_json", state_json(&msg.state))?;
        d.set_item("model_json", model_json(&msg.model))?;
        states.append(d)?;
    }
    Ok((
        to_py(py, &rec.scalars)?,
        to_py(py, &rec.events)?,
        to_py(py, &rec.metadata)?,
        states,
    ))
}

/// A state of a rod model (both as JSON text) as VTK PolyData, the bytes of
/// a `.vtp` file (`knotrod export --format vtp`).
#[pyfunction]
fn vtp<'py>(py: Python<'py>, model_json: &str, state_json: &str) -> PyResult<Bound<'py, PyBytes>> {
    let bad = |what: &str, e: serde_json::Error| KnotrodError::new_err(format!("{what}: {e}"));
    let model: RodModel = serde_json::from_str(model_json).map_err(|e| bad("model_json", e))?;
    let state: knotrod::RodState =
        serde_json::from_str(state_json).map_err(|e| bad("state_json", e))?;
    let bytes = knotrod::io::vtk::vtp(
        &model,
        &state,
        "knotrod state",
        std::path::Path::new("<state>"),
    )
    .map_err(|e| KnotrodError::new_err(e.to_string()))?;
    Ok(PyBytes::new(py, &bytes))
}

/// The extension module.
#[pymodule]
fn _knotrod(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("KnotrodError", py.get_type::<KnotrodError>())?;
    m.add("SceneError", py.get_type::<SceneError>())?;
    m.add("SolveError", py.get_type::<SolveError>())?;
    m.add("INTERRUPTED", INTERRUPTED)?;
    m.add_class::<PyScene>()?;
    m.add_class::<PyPoints>()?;
    m.add_function(wrap_pyfunction!(solve, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(map_scene, m)?)?;
    m.add_function(wrap_pyfunction!(verify, m)?)?;
    m.add_function(wrap_pyfunction!(knot_type, m)?)?;
    m.add_function(wrap_pyfunction!(read_recording, m)?)?;
    m.add_function(wrap_pyfunction!(vtp, m)?)?;
    Ok(())
}
