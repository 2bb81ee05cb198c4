"""Type stubs of the extension module knotrod._knotrod (the Rust half of the
package; use the documented wrappers in ``knotrod`` instead)."""

from typing import Any, Callable, Dict, List, Optional, Tuple

INTERRUPTED: str

class KnotrodError(Exception):
    """Base class of knotrod's errors."""

class SceneError(KnotrodError):
    """A scene that cannot be used."""

    field: Optional[str]

class SolveError(KnotrodError):
    """A solve or study that failed."""

    reason: str
    last: Optional[Dict[str, Any]]

class Scene:
    """A validated scene and its TOML text."""

    @staticmethod
    def from_toml(path: str) -> "Scene": ...
    @staticmethod
    def from_text(text: str) -> "Scene": ...
    def with_start(self, state_json: str) -> "Scene": ...
    def to_json(self) -> str: ...
    @property
    def text(self) -> str: ...
    @property
    def segments(self) -> int: ...

class Points:
    """The equilibria of a run, kept as Rust values and converted on request."""

    def __len__(self) -> int: ...
    def scalars(self, index: int) -> Dict[str, Any]: ...
    def arrays(self, index: int) -> Dict[str, Any]: ...
    def state_json(self, index: int) -> str: ...
    def model_json(self) -> str: ...
    def segments(self, index: int) -> int: ...
    def columns(self) -> Dict[str, Any]: ...

def solve(scene: Scene, segments: Optional[int] = None, allow_large: bool = False) -> Dict[str, Any]: ...
def run(
    scene: Scene,
    segments: Optional[int] = None,
    progress: Optional[Callable[[Dict[str, Any]], Any]] = None,
    record: Optional[str] = None,
    allow_large: bool = False,
) -> Tuple[Points, List[Dict[str, Any]]]: ...
def map_scene(
    scene: Scene,
    segments: Optional[int] = None,
    progress: Optional[Callable[[Dict[str, Any]], Any]] = None,
    cache: Optional[str] = None,
    allow_large: bool = False,
) -> Dict[str, Any]: ...
def verify(
    path: str,
    scene: Optional[str] = None,
    segments: Tuple[int, int, int] = (100, 200, 400),
    stiffness: float = 1e7,
    fit: Optional[str] = None,
    progress: Optional[Callable[[Dict[str, Any]], Any]] = None,
) -> List[Dict[str, Any]]: ...
def knot_type(points: List[List[float]], closed: bool = True) -> Dict[str, Any]: ...
def read_recording(
    path: str,
) -> Tuple[List[Dict[str, Any]], List[Dict[str, Any]], Dict[str, str], List[Dict[str, Any]]]: ...
def vtp(model_json: str, state_json: str) -> bytes: ...
