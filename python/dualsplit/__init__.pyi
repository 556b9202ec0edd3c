"""Type stubs of the dualsplit package (the ``dualsplit._dualsplit`` extension module)."""

import os
from collections.abc import Mapping, Sequence
from typing import Any, Literal, Union

import numpy as np
import numpy.typing as npt

__version__: str

# The registries' names (the Rust side checks these literals against them).
STRUCTURES: list[StructureKind]
TRAVERSALS: list[Traversal]
CONFIGURATIONS: list[str]

StructureKind = Literal["dst", "bvh2", "bvh4", "bvh8", "cwbvh", "dst-q"]
Traversal = Literal["bvh2", "bvh4", "bvh8", "dst-sw", "dst", "cwbvh", "dst-q"]
SimConfigName = Literal[
    "bvh2", "bvh2+", "bvh4", "bvh4+", "bvh8", "bvh8+", "dst-sw", "dst", "cwbvh", "cwbvh+", "dst-q", "all"
]
ConfigValue = Union[bool, int, float, str]
PerRay = Union[float, npt.NDArray[np.float32]]

class DualsplitError(Exception):
    """An error of dualsplit's Rust code; the message is the Rust error's, with its causes."""

class Scene:
    """A loaded scene (triangle soup, bounds, default camera and light)."""

    @property
    def name(self) -> str:
        """Short name: the file stem or the builtin's name."""
    @property
    def spec(self) -> str:
        """The spec the scene was loaded from."""
    @property
    def triangles(self) -> npt.NDArray[np.float32]:
        """The triangles, a read-only ``(N, 3, 3)`` float32 array (triangle, vertex, xyz)
        owning the loader's memory; a triangle's id (``prim``) is its row."""
    @property
    def bounds(self) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]:
        """``(min, max)``, two float32 arrays of 3."""
    @property
    def camera(self) -> dict[str, Any]:
        """The default camera, as in ``simulate``'s result."""
    @property
    def light(self) -> dict[str, Any]:
        """The default light, as in ``simulate``'s result."""
    def __len__(self) -> int:
        """The number of triangles."""

class Tree:
    """One structure: a BVH2, BVH4, BVH8 or DST."""

    @property
    def kind(self) -> StructureKind:
        """The structure."""
    @property
    def traversals(self) -> list[Traversal]:
        """Its traversals: ``["dst-sw", "dst"]`` for a DST, its own kind for a BVH."""
    @property
    def scene(self) -> Scene:
        """The scene it was built from or checked against."""
    @property
    def stats(self) -> dict[str, Any]:
        """Sizes, node counts and build time (``dualsplit build --json``'s ``stats``)."""
    def save(self, path: Union[str, os.PathLike[str]]) -> None:
        """Saves the structure in the saved-tree format (``dualsplit build -o``)."""
    @staticmethod
    def load(path: Union[str, os.PathLike[str]], scene: Union[Scene, str, os.PathLike[str]]) -> Tree:
        """Loads a tree file; it must come from ``scene`` (triangles checked bit for bit)."""
    def intersect(
        self,
        origins: npt.NDArray[np.float32],
        directions: npt.NDArray[np.float32],
        tmin: PerRay = 0.0,
        tmax: PerRay = float("inf"),
        *,
        traversal: Union[Traversal, None] = None,
    ) -> tuple[
        npt.NDArray[np.float32], npt.NDArray[np.int64], npt.NDArray[np.float32], npt.NDArray[np.float32]
    ]:
        """Closest hits of the ``(N, 3)`` float32 rays: ``(t, prim, u, v)``; a miss is
        ``t = inf``, ``prim = -1``, ``u = v = 0``. A ray with a non-finite origin or direction, or
        a NaN ``tmin`` or ``tmax``, raises ``DualsplitError`` naming the ray and the field. Runs
        on the Rust thread pool without the GIL."""
    def occluded(
        self,
        origins: npt.NDArray[np.float32],
        directions: npt.NDArray[np.float32],
        tmin: PerRay = 0.0,
        tmax: PerRay = float("inf"),
        *,
        traversal: Union[Traversal, None] = None,
    ) -> npt.NDArray[np.bool_]:
        """True where a ray hits any triangle within ``[tmin, tmax]``; rays are checked as in
        ``intersect``."""

def load_scene(
    spec: Union[str, os.PathLike[str]],
    *,
    max_triangles: Union[int, None] = None,
    max_bytes: Union[int, None] = None,
) -> Scene:
    """Loads a file (.obj, .ply, .gltf, .glb, optionally .gz) or ``builtin:NAME?params``."""

def build(scene: Union[Scene, str, os.PathLike[str]], kind: StructureKind | None = None) -> Tree:
    """Builds one structure as ``dualsplit build`` does (default build settings)."""

def builtins() -> list[str]:
    """The generated scenes' names, for ``builtin:NAME``."""

def simulate(
    scene: Union[Scene, str, os.PathLike[str]],
    *,
    accel: Union[SimConfigName, Sequence[SimConfigName], None] = None,
    workload: Literal["cast", "path"] = "path",
    res: Union[int, tuple[int, int], None] = None,
    tms: Union[int, None] = None,
    model: Literal["rv32", "fast", "simt"] = "rv32",
    config: Union[Mapping[str, Union[ConfigValue, Mapping[str, ConfigValue]]], None] = None,
    config_file: Union[str, os.PathLike[str], None] = None,
    tree: Union[Tree, None] = None,
    threads: Union[int, None] = None,
) -> dict[str, Any]:
    """One frame per configuration on the TRaX-style model: the dict ``dualsplit simulate
    --json`` prints. ``config`` sets keys of the hardware TOML (``{"l2.size_bytes": 1 << 20}``
    or ``{"l2": {"size_bytes": 1 << 20}}``) over ``config_file`` (default lin2020), with the
    same checks and messages as a file; ``res`` defaults to 512. ``threads`` host threads
    (default: the host's cores) run the frames side by side, splitting a frame's TMs when
    there are fewer frames; the result is the same for any number. ``model="simt"`` runs the
    RTX-style GPU model instead and needs a ``[simt]`` chip (``config_file`` =
    ``configs/rtx2060.toml``); each result then has a ``simt`` dict."""
