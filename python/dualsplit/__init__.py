"""dualsplit: dual-split trees, BVHs and a TRaX-style ray-tracing hardware simulator
(Lin et al. 2020, "Hardware-Accelerated Dual-Split Trees"), from Python.

>>> import dualsplit, numpy as np
>>> scene = dualsplit.load_scene("builtin:cornell")
>>> tree = dualsplit.build(scene, "dst")
>>> t, prim, u, v = tree.intersect(np.zeros((1, 3), np.float32), np.array([[0, 0, 1]], np.float32))

* ``load_scene(spec)``: a file (.obj, .ply, .gltf, .glb, optionally .gz) or
  ``builtin:NAME?params``; ``Scene.triangles`` is a read-only ``(N, 3, 3)`` float32 array
  holding the loader's memory.
* ``build(scene, kind)``: one of ``STRUCTURES``, as ``dualsplit build``; ``TRAVERSALS`` and
  ``CONFIGURATIONS`` name the traversals and simulated configurations (the Rust registries).
* ``Tree.save(path)`` / ``Tree.load(path, scene)``: the saved-tree format of the command line.
* ``Tree.intersect`` / ``Tree.occluded``: batched ray queries on the Rust thread pool, without
  the GIL.
* ``simulate(scene, ...)``: the dict ``dualsplit simulate --json`` prints.

Rust errors are raised as ``DualsplitError`` with the Rust message; bad argument types and
values as ``TypeError`` / ``ValueError``.
"""

from ._dualsplit import (
    CONFIGURATIONS,
    STRUCTURES,
    TRAVERSALS,
    DualsplitError,
    Scene,
    Tree,
    __version__,
    build,
    builtins,
    load_scene,
    simulate,
)

__all__ = [
    "CONFIGURATIONS",
    "STRUCTURES",
    "TRAVERSALS",
    "DualsplitError",
    "Scene",
    "Tree",
    "__version__",
    "build",
    "builtins",
    "load_scene",
    "simulate",
]
