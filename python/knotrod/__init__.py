"""knotrod: equilibria, continuation, stability and knot diagnostics of
clamped elastic rods (discrete elastic rods), from Python.

The physics is the Rust library's; this package passes scenes in and hands
results back as numpy arrays and plain Python values::

    import knotrod
    scene = knotrod.Scene.from_toml("scenes/appendix_d.toml")
    eq = knotrod.equilibrium(scene)
    print(eq.twist, eq.stable, eq.good_knot, eq.nodes.shape)

A scene is a TOML file, a dict of its sections, or keyword arguments
(``knotrod.Scene(model={...}, clamps={...})``). Long calls (``branch``,
``loading``, ``map``, ``verify``) release the GIL; ``branch`` and ``loading``
take ``progress=callable`` and stop on Ctrl-C after the current equilibrium
with a ``KeyboardInterrupt`` whose ``partial`` attribute is the ``Branch``
computed so far (the recording, if any, is finalised).

Errors: :class:`SceneError` (``field`` names the offending field) and
:class:`SolveError` (``reason``, and ``last``: the last equilibrium computed).
"""

from __future__ import annotations

import json
import os
from enum import Enum
from typing import Any, Callable, Dict, Iterable, List, Mapping, Optional, Sequence, Union

import numpy as np

from . import _knotrod
from ._knotrod import KnotrodError, SceneError, SolveError

__all__ = [
    "Scene",
    "Equilibrium",
    "Event",
    "EventKind",
    "Branch",
    "Recording",
    "KnotrodError",
    "SceneError",
    "SolveError",
    "equilibrium",
    "branch",
    "loading",
    "map",
    "verify",
    "knot_type",
    "read_recording",
]

PathLike = Union[str, "os.PathLike[str]"]


def _merge(base: Dict[str, Any], extra: Mapping[str, Any]) -> Dict[str, Any]:
    """``base`` updated by ``extra``, tables (dicts) merged key by key."""
    out = dict(base)
    for k, v in extra.items():
        if isinstance(v, Mapping) and isinstance(out.get(k), Mapping):
            out[k] = _merge(dict(out[k]), v)
        else:
            out[k] = v
    return out


def _plain(value: Any) -> Any:
    """Numpy scalars and arrays as plain Python values (for the TOML writer)."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    return value


class Scene:
    """A validated scene: the model, clamps, initial shape, solver,
    continuation, loading, map... sections of a knotrod scene file.

    ``Scene(mapping=None, **sections)``: the sections as a dict and/or
    keyword arguments (``model={"K2": 3.0, ...}, clamps={...}``). The dict is
    written as TOML and read by the same parser as a file, so a bad value
    raises :class:`SceneError` whose ``field`` names it (``model.K2``).
    """

    def __init__(self, mapping: Optional[Mapping[str, Any]] = None, **sections: Any) -> None:
        data = _merge(dict(mapping or {}), sections)
        # TOML has no null: keys set to None are left out (defaults)
        self._inner = _knotrod.Scene.from_text(to_toml(_drop_none(_plain(data))))

    @classmethod
    def from_toml(cls, path: PathLike) -> "Scene":
        """Read and validate a scene file (``knotrod::Scene::load``)."""
        return cls._wrap(_knotrod.Scene.from_toml(os.fspath(path)))

    @classmethod
    def from_text(cls, text: str) -> "Scene":
        """Parse and validate scene text (TOML)."""
        return cls._wrap(_knotrod.Scene.from_text(text))

    @classmethod
    def _wrap(cls, inner: Any) -> "Scene":
        scene = cls.__new__(cls)
        scene._inner = inner
        return scene

    def to_dict(self) -> Dict[str, Any]:
        """Every section as a dict (defaults filled in)."""
        return json.loads(self._inner.to_json())

    def with_(self, **sections: Any) -> "Scene":
        """A copy with some sections' keys replaced (tables merged), e.g.
        ``scene.with_(model={"segments": 60}, continuation=None)``; a section
        set to None is removed."""
        data = self.to_dict()
        for k, v in sections.items():
            if v is None:
                data.pop(k, None)
        data = _merge(data, {k: v for k, v in sections.items() if v is not None})
        return Scene(_drop_none(data))

    @property
    def text(self) -> str:
        """The TOML text the scene was read from."""
        return self._inner.text

    @property
    def segments(self) -> int:
        """The scene's number of segments N (``model.segments``)."""
        return self._inner.segments

    def __repr__(self) -> str:
        d = self.to_dict()
        return f"Scene(name={d.get('name')!r}, segments={self.segments})"


def _toml_value(v: Any) -> str:
    """One TOML value (inline: lists, and dicts as inline tables)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if v != v:
            return "nan"
        if v in (float("inf"), float("-inf")):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)
    if isinstance(v, Mapping):
        return "{" + ", ".join(f"{_toml_key(k)} = {_toml_value(x)}" for k, x in v.items()) + "}"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise TypeError(f"a scene holds numbers, strings, booleans, lists and dicts, not {type(v).__name__}")


def _toml_key(k: str) -> str:
    bare = k.replace("_", "").replace("-", "").isalnum() and k.isascii()
    return k if bare else json.dumps(k)


def to_toml(scene: Mapping[str, Any]) -> str:
    """A scene's dict of sections as TOML text: top-level values, then one
    ``[table]`` per dict and one ``[[table]]`` per dict of a list of dicts
    (a loading path's legs), one ``key = value`` line each, so that a parse
    error's line names its field."""
    head, tables = [], []
    for k, v in scene.items():
        key = _toml_key(str(k))
        if isinstance(v, Mapping):
            tables.append(f"[{key}]")
            tables += [f"{_toml_key(str(a))} = {_toml_value(b)}" for a, b in v.items()]
        elif isinstance(v, (list, tuple)) and v and all(isinstance(x, Mapping) for x in v):
            for x in v:
                tables.append(f"[[{key}]]")
                tables += [f"{_toml_key(str(a))} = {_toml_value(b)}" for a, b in x.items()]
        else:
            head.append(f"{key} = {_toml_value(v)}")
    return "\n".join(head + tables) + "\n"


def _drop_none(value: Any) -> Any:
    """TOML has no null: keys whose value is None are left out."""
    if isinstance(value, dict):
        return {k: _drop_none(v) for k, v in value.items() if v is not None}
    if isinstance(value, list):
        return [_drop_none(v) for v in value]
    return value


SceneLike = Union[Scene, Mapping[str, Any], PathLike]


def _scene(scene: SceneLike) -> Any:
    """The Rust scene of a Scene, a dict of sections or a TOML file's path."""
    if isinstance(scene, Scene):
        return scene._inner
    if isinstance(scene, _knotrod.Scene):
        return scene
    if isinstance(scene, Mapping):
        return Scene(scene)._inner
    return _knotrod.Scene.from_toml(os.fspath(scene))


# the state and its model as JSON text: for restarts and exports, not fields
_TEXTS = ("state_json", "model_json")

_ARRAYS = (
    "nodes",
    "theta",
    "directors",
    "strains",
    "force",
    "moment",
    "s_nodes",
    "s_edges",
    "s_vertices",
)


class Equilibrium:
    """One equilibrium and its measurements.

    Arrays along the rod (N segments, h = 1/N):

    - ``nodes`` (N+2, 3): node positions x_0..x_{N+1} at arc lengths
      ``s_nodes`` = (i - 1/2) h (the clamp nodes half a segment outside
      [0, 1]);
    - ``directors`` (N+1, 3, 3): the material frame (d1, d2, d3) of each
      edge (``d1``, ``d2``, ``d3``: (N+1, 3) each), edges centred at
      ``s_edges`` = j h;
    - ``strains`` (N, 3): u1, u2, u3 at the interior vertices ``s_vertices``;
    - ``force``, ``moment`` (N+1, 3): internal force n(s) and moment m(s) at
      each edge's centre, in its material frame (``force[0]`` is n(0));
    - ``theta`` (N+1,): material angles.

    Scalars: ``energy``, ``n0``, ``m0``, ``twist`` (Tw), ``writhe``, ``link``,
    ``knot_determinant``, ``knot_name``, ``alexander``, ``knotted``,
    ``walled``, ``stable``, ``lowest_eigenvalues``, ``omega_squared``,
    ``good_knot``, ``z_star``, ``delta``, ``phi_over_2pi``, ``branch``... —
    every field of the JSON summary's equilibria (see ``to_dict()``).

    An equilibrium of a :class:`Branch` is converted from the Rust result
    when first read (its scalars on the first scalar read, its arrays on the
    first array read) and kept: a branch of hundreds of points costs only
    what is read of it.
    """

    def __init__(self, data: Dict[str, Any]) -> None:
        self._data = data
        self._source: Any = None
        self._index = 0
        self._scalars_read = self._arrays_read = True

    @classmethod
    def _lazy(cls, source: Any, index: int) -> "Equilibrium":
        """Point ``index`` of a run's ``_knotrod.Points``, read on access."""
        eq = cls.__new__(cls)
        eq._data = {}
        eq._source = source
        eq._index = index
        eq._scalars_read = eq._arrays_read = False
        return eq

    def _scalars_loaded(self) -> Dict[str, Any]:
        if not self._scalars_read:
            self._data.update(self._source.scalars(self._index))
            self._scalars_read = True
        return self._data

    def _all_loaded(self) -> Dict[str, Any]:
        self._scalars_loaded()
        if not self._arrays_read:
            self._data.update(self._source.arrays(self._index))
            self._arrays_read = True
        return self._data

    def __getattr__(self, name: str) -> Any:
        # only names not found the usual way; private and dunder probes
        # (copy, numpy, pandas) must not convert anything
        if name.startswith("_") or "_data" not in self.__dict__:
            raise AttributeError(name)
        if name == "state_json":
            if name not in self._data and self._source is not None:
                self._data[name] = self._source.state_json(self._index)
            data = self._data
        elif name == "model_json":
            if name not in self._data and self._source is not None:
                self._data[name] = self._source.model_json()
            data = self._data
        elif name in _ARRAYS:
            data = self._all_loaded()
        else:
            data = self._scalars_loaded()
        try:
            return data[name]
        except KeyError:
            raise AttributeError(name) from None

    def __reduce__(self) -> Any:
        # pickled and copied whole: the Rust result it reads from is not
        # picklable
        data = dict(self._all_loaded())
        if "state_json" not in data and self._source is not None:
            data["state_json"] = self._source.state_json(self._index)
        if "model_json" not in data and self._source is not None:
            data["model_json"] = self._source.model_json()
        return (type(self), (data,))

    def __dir__(self) -> List[str]:
        return sorted(set(super().__dir__()) | set(self._scalars_loaded()) | set(_ARRAYS) | {"d1", "d2", "d3"})

    @property
    def d1(self) -> np.ndarray:
        """d1 of each edge, (N+1, 3)."""
        return self.directors[:, 0, :]

    @property
    def d2(self) -> np.ndarray:
        """d2 of each edge, (N+1, 3)."""
        return self.directors[:, 1, :]

    @property
    def d3(self) -> np.ndarray:
        """d3 (the tangent) of each edge, (N+1, 3)."""
        return self.directors[:, 2, :]

    @property
    def segments(self) -> int:
        """N."""
        if not self._arrays_read:
            return self._source.segments(self._index)
        return len(self._data["s_vertices"])

    def to_vtp(self, path: Optional[PathLike] = None) -> bytes:
        """The state as VTK PolyData, the bytes of a ``.vtp`` file (written to
        ``path`` if given), as ``knotrod export --format vtp`` writes it: the
        centreline r(0), x_1..x_N, r(1) as one line, with point data ``s``,
        ``tube_radius``, ``d1``, ``d2``, ``d3``, ``strains`` (u1, u2, u3),
        ``n``, ``m`` (lab frame) and ``n_material``, ``m_material``."""
        data = _knotrod.vtp(self.model_json, self.state_json)
        if path is not None:
            with open(os.fspath(path), "wb") as f:
                f.write(data)
        return data

    def to_pyvista(self) -> Any:
        """The state as a ``pyvista.PolyData`` (needs pyvista): the fields of
        :meth:`to_vtp` as its point data; ``.tube(scalars="tube_radius",
        absolute=True)`` draws the rod at its diameter."""
        try:
            import pyvista
        except ImportError as e:
            raise ImportError("Equilibrium.to_pyvista() needs pyvista: pip install pyvista") from e
        import tempfile

        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "state.vtp")
            self.to_vtp(path)
            return pyvista.read(path)

    def scalars(self) -> Dict[str, Any]:
        """The measurements without the arrays."""
        return {k: v for k, v in self._scalars_loaded().items() if k not in _ARRAYS and k not in _TEXTS}

    def to_dict(self) -> Dict[str, Any]:
        """Everything as a plain dict (arrays as numpy arrays)."""
        return {k: v for k, v in self._all_loaded().items() if k not in _TEXTS}

    def __repr__(self) -> str:
        d = self._scalars_loaded()
        return (
            f"Equilibrium(z_star={d.get('z_star')}, delta={d.get('delta')}, "
            f"phi_over_2pi={d.get('phi_over_2pi')}, twist={d.get('twist')}, "
            f"stable={d.get('stable')}, good_knot={d.get('good_knot')}, N={self.segments})"
        )


class EventKind(str, Enum):
    """What happens at an event. A ``str``: each kind equals its name
    (``EventKind.WALL == "wall"``), prints and formats as it, and is written
    as it to JSON."""

    WALL = "wall"
    """The rod touches a wall (enters or leaves the walled region)."""
    CROSSING = "crossing"
    """The centreline passes through itself or a ray (the link jumps by ±2)."""
    RIBBON_CONTACT = "ribbon_contact"
    """A strip's ribbon comes to touch itself, or comes clear of itself."""
    STABILITY = "stability"
    """The count of negative eigenvalues changes."""
    FOLD = "fold"
    """The parameter turns back along the branch."""
    BRANCH_POINT = "branch_point"
    """A branch point: another branch crosses this one."""
    JUMP = "jump"
    """The rod jumps off its branch (loading paths)."""
    KNOT_CHANGE = "knot_change"
    """The knot type of the ray closure changes."""
    END = "end"
    """The branch ends (lost, or a switch failed)."""
    CONTACT_LOST = "contact_lost"
    """The last contact opens (loading with contact)."""

    # the plain string everywhere a string is expected (Python 3.12 prints
    # a mixed-in Enum as "EventKind.WALL")
    def __str__(self) -> str:
        return str.__str__(self)

    def __format__(self, spec: str) -> str:
        return str.__format__(self.value, spec)

    def __hash__(self) -> int:
        return str.__hash__(self)


class Event:
    """An event along a branch or loading path: ``kind`` (an
    :class:`EventKind`, equal to its name: ``"wall"``, ``"crossing"``,
    ``"branch_point"``, ``"fold"``, ``"jump"``, ...), ``label`` as in the
    paper's figures (W1, W2, X, S, F1...), where (``phi_over_2pi``,
    ``z_star``, ``delta``), ``twist``, ``branch`` and ``detail``;
    ``continuum`` when polished; ``located_within``, the width of the
    parameter interval (φ as φ/2π) a bisected event lies in (None for
    events not bisected)."""

    kind: Union["EventKind", str]
    label: str
    phi_over_2pi: float
    z_star: float
    delta: float
    twist: float
    branch: int
    detail: str
    located_within: Optional[float]

    def __init__(self, data: Dict[str, Any]) -> None:
        self._data = data
        for k, v in data.items():
            setattr(self, k, v)
        if "continuum" not in data:
            self.continuum = None
        if "located_within" not in data:
            self.located_within = None
        try:
            self.kind = EventKind(data.get("kind"))
        except ValueError:
            # a kind this version does not know (a newer recording): its name
            pass

    def to_dict(self) -> Dict[str, Any]:
        """The event as a plain dict."""
        return dict(self._data)

    def __repr__(self) -> str:
        return f"Event({self.label!r}, {str(self.kind)!r}, phi_over_2pi={self.phi_over_2pi:.6f}, branch={self.branch})"


_COLUMNS = (
    "branch",
    "leg",
    "z_star",
    "delta",
    "phi_over_2pi",
    "energy",
    "twist",
    "writhe",
    "link",
    "knot_determinant",
    "knotted",
    "walled",
    "stable",
    "negative_eigenvalues",
    "good_knot",
    "min_z",
    "max_z",
    "wall_distance",
    "min_self_distance",
    "contact_force",
    "iterations",
    "converged",
)


class Branch:
    """The equilibria of a run (branches, a sweep or a loading path) in the
    order computed, and its events.

    ``points`` is a list of :class:`Equilibrium`; ``events`` a list of
    :class:`Event`; ``columns()`` (also ``to_dict()["points"]``) the points'
    scalars as numpy arrays by name, which ``pandas.DataFrame(...)`` takes as
    it is; ``event_columns()`` the same for the events. ``interrupted`` is
    True for the partial result of a run stopped by Ctrl-C.

    The points of a run stay Rust values until read: ``columns()`` is built
    from them directly, and a point's scalars and arrays are converted when
    it is first read (see :class:`Equilibrium`).
    """

    def __init__(self, points: Union["_knotrod.Points", Sequence[Union[Dict[str, Any], Equilibrium]]], events: List[Dict[str, Any]], interrupted: bool = False) -> None:
        if isinstance(points, _knotrod.Points):
            # a run's result: each point converted when first read
            self._source: Any = points
            self.points = [Equilibrium._lazy(points, k) for k in range(len(points))]
        else:
            self._source = None
            self.points = [p if isinstance(p, Equilibrium) else Equilibrium(p) for p in points]
        self.events = [Event(e) for e in events]
        self.interrupted = interrupted

    def __getstate__(self) -> Dict[str, Any]:
        # the Rust result is not picklable; the points pickle whole
        state = dict(self.__dict__)
        state["_source"] = None
        return state

    def _unchanged(self) -> bool:
        """The points are still the run's, in its order (the columns can
        then be taken from the Rust result)."""
        src = self._source
        if src is None or len(self.points) != len(src):
            return False
        return all(getattr(p, "_source", None) is src and p._index == k for k, p in enumerate(self.points))

    def __len__(self) -> int:
        return len(self.points)

    def columns(self) -> Dict[str, np.ndarray]:
        """One numpy array per scalar, one entry per point; n0 and m0 as
        n0_1..n0_3, m0_1..m0_3, and the lowest eigenvalue and ω²."""
        if self._unchanged():
            # built in Rust, no point converted
            return self._source.columns()
        pts = [p._scalars_loaded() for p in self.points]
        cols: Dict[str, np.ndarray] = {k: np.array([p.get(k) for p in pts]) for k in _COLUMNS}
        for name in ("n0", "m0"):
            for c in range(3):
                cols[f"{name}_{c + 1}"] = np.array([p[name][c] for p in pts], dtype=float)
        for name, key in (("lowest_eigenvalue", "lowest_eigenvalues"), ("lowest_omega_squared", "omega_squared")):
            cols[name] = np.array([p[key][0] if p[key] else np.nan for p in pts], dtype=float)
        return cols

    def event_columns(self) -> Dict[str, np.ndarray]:
        """The events' fields as arrays (kind, label, phi_over_2pi, z_star,
        delta, twist, branch)."""
        keys = ("label", "phi_over_2pi", "z_star", "delta", "twist", "branch")
        cols = {"kind": np.array([str(e.kind) for e in self.events])}
        cols.update({k: np.array([getattr(e, k) for e in self.events]) for k in keys})
        return cols

    def event(self, label: str) -> Event:
        """The first event with this label (W1, W2, X, S, F1, ...)."""
        for e in self.events:
            if e.label == label:
                return e
        raise KeyError(f"no event {label!r}; events: {[e.label for e in self.events]}")

    def to_dict(self) -> Dict[str, Any]:
        """{"points": columns(), "events": event_columns(), "interrupted": ...}."""
        return {"points": self.columns(), "events": self.event_columns(), "interrupted": self.interrupted}

    def __repr__(self) -> str:
        labels = ", ".join(e.label for e in self.events)
        return f"Branch({len(self.points)} points, events [{labels}]{', interrupted' if self.interrupted else ''})"


class Recording:
    """A recording (MCAP) read back: ``states`` (a list of
    :class:`Equilibrium` with the recorded scalars and the state's arrays),
    ``scalars`` (the per-state scalar messages), ``events`` and
    ``metadata``."""

    def __init__(self, scalars: List[Dict[str, Any]], events: List[Dict[str, Any]], metadata: Dict[str, str], states: List[Dict[str, Any]]) -> None:
        self.scalars = scalars
        self.events = [Event(e) for e in events]
        self.metadata = metadata
        self.states = [Equilibrium(s) for s in states]

    def __len__(self) -> int:
        return len(self.states)

    def to_dict(self) -> Dict[str, Any]:
        """{"scalars": columns by name, "events": [...], "metadata": {...}}."""
        keys = sorted({k for s in self.scalars for k in s})
        return {
            "scalars": {k: np.array([s.get(k) for s in self.scalars]) for k in keys},
            "events": [e.to_dict() for e in self.events],
            "metadata": dict(self.metadata),
        }

    def __repr__(self) -> str:
        return f"Recording({len(self.states)} states, {len(self.events)} events)"


StartLike = Union["Equilibrium", str]


def _started(scene: SceneLike, start: Optional[StartLike]) -> Any:
    """The scene, restarted from ``start`` (an :class:`Equilibrium` or its
    ``state_json``) when given: at the state's N, from its shape."""
    s = _scene(scene)
    if start is None:
        return s
    return s.with_start(start if isinstance(start, str) else start.state_json)


def equilibrium(
    scene: SceneLike, segments: Optional[int] = None, allow_large: bool = False, start: Optional[StartLike] = None
) -> Equilibrium:
    """Solve the scene's equilibrium at its clamps (``knotrod run`` of a
    scene without continuation): its start solved by Newton and measured.

    ``segments`` overrides N; ``allow_large`` runs a scene over its budget;
    ``start`` (an equilibrium handed back earlier, or its ``state_json``)
    replaces the scene's initial shape, at the state's N.
    """
    return Equilibrium(_knotrod.solve(_started(scene, start), segments, allow_large))


def _run(
    scene: Any,
    segments: Optional[int],
    progress: Optional[Callable[[Dict[str, Any]], Any]],
    record: Optional[PathLike],
    allow_large: bool,
) -> Branch:
    rec = None if record is None else os.fspath(record)
    try:
        points, events = _knotrod.run(scene, segments, progress, rec, allow_large)
    except BaseException as e:
        # Ctrl-C, or the progress callback's own exception: what was computed
        partial = getattr(e, "partial", None)
        if partial is not None:
            e.partial = Branch(partial[0], partial[1], interrupted=True)
        raise
    return Branch(points, events)


def branch(
    scene: SceneLike,
    segments: Optional[int] = None,
    progress: Optional[Callable[[Dict[str, Any]], Any]] = None,
    record: Optional[PathLike] = None,
    allow_large: bool = False,
    start: Optional[StartLike] = None,
) -> Branch:
    """Follow the scene's branch(es) (its ``[continuation]``, swept over
    ``[sweep]``): every equilibrium and the labelled events, from the
    scene's start or from ``start`` (as for :func:`equilibrium`).

    ``progress(point)`` is called with a dict (index, branch, z_star, delta,
    phi_over_2pi, twist, stable, good_knot) after each equilibrium; an
    exception it raises stops the run. ``record`` writes an MCAP recording
    (finalised also when the run stops early). Ctrl-C stops the run after
    the current equilibrium: the ``KeyboardInterrupt`` has ``partial`` (the
    :class:`Branch` so far) and ``recording``.
    """
    return _run(_started(scene, start), segments, progress, record, allow_large)


def loading(
    scene: SceneLike,
    segments: Optional[int] = None,
    progress: Optional[Callable[[Dict[str, Any]], Any]] = None,
    record: Optional[PathLike] = None,
    allow_large: bool = False,
    start: Optional[StartLike] = None,
) -> Branch:
    """Follow the scene's quasi-static loading path (its ``[[loading]]``
    legs): each step minimised from the previous equilibrium, jumps and
    other events located. Arguments as for :func:`branch`."""
    s = _started(scene, start)
    if not json.loads(s.to_json()).get("loading"):
        err = SceneError("the scene has no [[loading]] legs")
        err.field = "loading"
        raise err
    return _run(s, segments, progress, record, allow_large)


def map(  # noqa: A001 - mirrors `knotrod map`
    scene: SceneLike,
    segments: Optional[int] = None,
    progress: Optional[Callable[[Dict[str, Any]], Any]] = None,
    cache: Optional[PathLike] = None,
    allow_large: bool = False,
) -> Dict[str, Any]:
    """Map the good-knot region as ``knotrod map`` does: the boundary walk
    from the scene's good knot (``traced``: its pieces, corners, area, and
    ``polished`` on the continuum when the scene's ``[map] polish = true``),
    then one branch per line of the ``[map]``, in parallel. The map as a dict
    (``lines`` with their good intervals, ``grid``, ``area``, ``traced``...).

    ``progress`` is called with a dict per boundary point (``stage``
    "boundary") and per line (``stage`` "line"). ``cache`` names a folder
    keeping the walk and the lines: a rerun resumes from it. Ctrl-C stops the
    map (once the walk, or the lines in progress, finish) with a
    KeyboardInterrupt whose ``partial`` holds ``traced`` and the ``lines``
    computed."""
    return _knotrod.map_scene(
        _scene(scene), segments, progress, None if cache is None else os.fspath(cache), allow_large
    )


def verify(
    path: PathLike,
    scene: Optional[PathLike] = None,
    segments: Sequence[int] = (100, 200, 400),
    stiffness: float = 1e7,
    fit: Optional[str] = None,
    progress: Optional[Callable[[Dict[str, Any]], Any]] = None,
) -> List[Dict[str, Any]]:
    """Verify a table of shooting solutions (TOML ``[[solution]]``, JSON or
    CSV, as ``knotrod verify`` reads) by two independent methods: the
    continuum equations integrated adaptively and polished, and the discrete
    rod at N, 2N, 4N extrapolated. One dict per solution (``verdict``,
    ``estimates``, ``claims``...). ``progress`` is called with each
    solution's dict as it is done; Ctrl-C stops the run once the solutions in
    progress are done, with a KeyboardInterrupt whose ``partial`` lists
    those done."""
    n = tuple(int(k) for k in segments)
    if len(n) != 3:
        raise ValueError("segments: three resolutions N, 2N, 4N")
    return _knotrod.verify(
        os.fspath(path), None if scene is None else os.fspath(scene), n, float(stiffness), fit, progress
    )


def knot_type(points: Union[np.ndarray, Iterable[Sequence[float]]], closed: bool = True) -> Dict[str, Any]:
    """Writhe and knot type of a polygon ((n, 3) points): ``closed`` as
    given, else closed by rays along -z from the first point and +z from the
    last. A dict: writhe, knot_determinant (3: trefoil), alexander (lowest
    degree first), knot_name, knot_names, crossings. Raises ValueError when
    the curve passes through itself."""
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise ValueError(f"points: an (n, 3) array, got shape {pts.shape}")
    return _knotrod.knot_type(pts.tolist(), closed)


def read_recording(path: PathLike) -> Recording:
    """Read a recording (MCAP, from ``knotrod run --record`` or
    ``branch(..., record=path)``): its states back as :class:`Equilibrium`."""
    return Recording(*_knotrod.read_recording(os.fspath(path)))
